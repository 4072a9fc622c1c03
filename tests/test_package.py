"""The package as published (issue 47): its metadata says what the source says, and the documentation site has
an API entry for every public class and a page with a picture for every domain."""

import importlib
import importlib.metadata
import importlib.util
import re
import sys
from pathlib import Path

import gymnasium

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

import pamdp
from pamdp.algos import ALGORITHMS, algorithm_class
from pamdp.algos.base import Algorithm
from pamdp.algos.settings import AlgoConfig
from pamdp.envs.scalar import DomainEnv
from pamdp.envs.vector import Domain, DomainVectorEnv

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]


def test_installed_metadata_matches_the_source():
    """What pip installed (the version, the licence) is what the source declares; a mismatch means metadata
    from an older install: reinstall with `pip install -e .`."""
    dist = importlib.metadata.distribution("pamdp")
    stale = f"metadata of an older install at {dist.locate_file('')}: run `pip install -e .`"
    assert dist.version == pamdp.__version__, stale
    assert dist.metadata["License-Expression"] == PYPROJECT["license"] == "MIT", stale


def test_licence_file_is_the_declared_licence():
    assert PYPROJECT["license-files"] == ["LICENSE"]
    text = (ROOT / "LICENSE").read_text()
    assert text.startswith("MIT License\n")
    assert "Copyright (c)" in text and "the pamdp authors" in text


def test_changelog_has_a_section_for_this_version():
    changelog = (ROOT / "CHANGELOG.md").read_text()
    assert "## [Unreleased]" in changelog
    assert f"## [{pamdp.__version__}]" in changelog, f"CHANGELOG.md has no section for {pamdp.__version__}"


def _resolve(path: str):
    """The object a ``::: dotted.path`` block documents: the longest importable module, then attributes."""
    parts = path.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ModuleNotFoundError as error:
            if error.name and not error.name.startswith("pamdp"):
                raise  # the module exists but needs a package that is not installed
            continue
        for name in parts[i:]:
            obj = getattr(obj, name)
        return obj
    raise ImportError(path)


def _entry_point(target: str):
    module, _, name = target.partition(":")
    return getattr(importlib.import_module(module), name)


def _public_objects() -> dict[str, object]:
    """Every public class and function: pamdp's exports, each algorithm and its config with their bases, the
    wrappers, the evaluation, the env shell and each registered env's domain."""
    names = [n for n in pamdp.__all__ if n != "__version__"]  # a string, checked against the metadata above
    objects = {f"pamdp.{n}": getattr(pamdp, n) for n in names}
    objects |= {"Algorithm": Algorithm, "AlgoConfig": AlgoConfig}
    for key in ALGORITHMS:
        cls = algorithm_class(key)
        objects |= {cls.__name__: cls, cls.config_class.__name__: cls.config_class}
    for module in ("pamdp.wrappers", "pamdp.evaluation"):
        mod = importlib.import_module(module)
        objects |= {f"{module}.{n}": getattr(mod, n) for n in mod.__all__}
    for env_id, spec in gymnasium.registry.items():
        if env_id.startswith("pamdp/"):
            # a registered env's classes are made from its domain by the one shell: the domain and the shell carry
            # what there is to read (the classes themselves exist only at run time, where the site's reader of
            # source text cannot see them)
            domain = _entry_point(spec.entry_point).domain_class
            objects[f"{domain.__module__}.{domain.__qualname__}"] = domain
    objects |= {"DomainEnv": DomainEnv, "DomainVectorEnv": DomainVectorEnv, "Domain": Domain}
    if importlib.util.find_spec("pettingzoo") is not None:  # the optional multi-agent interface (issue 47)
        multiagent = importlib.import_module("pamdp.envs.hfo.multiagent")
        objects |= {f"pamdp.envs.hfo.multiagent.{n}": getattr(multiagent, n) for n in multiagent.__all__}
    return objects


def test_every_public_class_has_an_api_entry():
    """A new public class, algorithm, config or env without a ``:::`` block in docs/api/ fails here."""
    targets = [
        t for page in (ROOT / "docs" / "api").glob("*.md") for t in re.findall(r"^::: (\S+)", page.read_text(), re.M)
    ]
    documented = set()
    for target in targets:
        try:
            documented.add(id(_resolve(target)))
        except ModuleNotFoundError:  # an optional extra's class (PettingZoo's env), not installed: not public here
            continue
    missing = sorted(name for name, obj in _public_objects().items() if id(obj) not in documented)
    assert not missing, f"no ::: block in docs/api/*.md for {missing}"


def _domain_pictures():
    spec = importlib.util.spec_from_file_location("gen_domain_pictures", ROOT / "docs" / "gen_domain_pictures.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.DOMAINS


def test_every_domain_has_a_page_with_its_picture():
    domains = _domain_pictures()
    registered = {env_id for env_id in gymnasium.registry if env_id.startswith("pamdp/")}
    assert {env_id for env_id, *_ in domains.values()} == registered
    mkdocs = (ROOT / "mkdocs.yml").read_text()
    for name in domains:
        page = ROOT / "docs" / "domains" / f"{name}.md"
        picture = page.parent / "img" / f"{name}.png"
        assert f"](img/{name}.png)" in page.read_text(), f"{page} does not show {picture.name}"
        assert picture.stat().st_size < 200_000, f"{picture} is over 200 KB"
        assert f" domains/{name}.md\n" in mkdocs, f"mkdocs.yml's nav has no domains/{name}.md"


def test_mkdocs_nav_lists_every_page():
    """MkDocs only notes a page left out of the nav; here it fails."""
    nav = set(re.findall(r"^\s+- (?:[^:\n]+: )?(\S+\.md)$", (ROOT / "mkdocs.yml").read_text(), re.M))
    pages = {p.relative_to(ROOT / "docs").as_posix() for p in (ROOT / "docs").rglob("*.md")}
    assert pages - nav == set(), f"pages missing from mkdocs.yml's nav: {sorted(pages - nav)}"
    assert nav - pages == set(), f"nav entries without a page: {sorted(nav - pages)}"
