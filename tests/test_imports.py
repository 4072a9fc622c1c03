"""The package's layers, read from its source: imports without a circle, algorithms that import family modules and
never each other, an algorithms' package that knows no env (the env presets live above it, in presets/) but makes
and steps its envs through envs/' backends and stepping, and the layers below the algorithms (the envs, the
networks and the updates' building blocks, the evaluation, the logger) that import nothing above them."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

import pamdp
from pamdp.algos import ALGORITHMS

SRC = Path(pamdp.__file__).parent


def module_name(path: Path) -> str:
    return ("pamdp." + ".".join(path.relative_to(SRC).with_suffix("").parts)).removesuffix(".__init__")


def module_path(name: str) -> Path | None:
    parts = name.split(".")[1:]
    for candidate in (SRC.joinpath(*parts).with_suffix(".py"), SRC.joinpath(*parts, "__init__.py")):
        if parts and candidate.is_file():
            return candidate
    return SRC / "__init__.py" if not parts else None


def module_imports(path: Path) -> set[str]:
    """The pamdp modules a file imports: at its top, inside its functions and for a type checker only (under
    ``if TYPE_CHECKING:``) alike, since a circle through any of them is one a reader has to untangle."""
    name = module_name(path)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            parts = package.split(".")[: len(package.split(".")) - max(node.level - 1, 0)] if node.level else []
            base = ".".join([*parts, *([node.module] if node.module else [])])
            for alias in node.names:
                # `from pamdp.algos import onpolicy` imports a module; `from pamdp.algos import ALGORITHMS` a name
                child = f"{base}.{alias.name}"
                found.add(child if module_path(child) is not None else base)
    return {m for m in found if m == "pamdp" or m.startswith("pamdp.")}


GRAPH = {module_name(path): module_imports(path) for path in sorted(SRC.rglob("*.py"))}
ALGOS = sorted(m for m in GRAPH if m == "pamdp.algos" or m.startswith("pamdp.algos."))


def test_no_import_circle_in_the_package():
    state: dict[str, str] = {}

    def visit(node, trail):
        if state.get(node) == "done":
            return
        assert state.get(node) != "open", "import circle: " + " -> ".join([*trail[trail.index(node) :], node])
        state[node] = "open"
        for child in sorted(GRAPH.get(node, ())):
            visit(child, [*trail, node])
        state[node] = "done"

    for node in sorted(GRAPH):
        visit(node, [])


def test_the_circle_finder_finds_a_circle(monkeypatch):
    monkeypatch.setitem(GRAPH, "pamdp.evaluation", GRAPH["pamdp.evaluation"] | {"pamdp.algos.base"})
    circle = r"import circle: pamdp\.algos\.base -> (pamdp\.callbacks -> )?pamdp\.evaluation -> pamdp\.algos\.base"
    with pytest.raises(AssertionError, match=circle):
        test_no_import_circle_in_the_package()


@pytest.mark.parametrize("name", list(ALGORITHMS))
def test_an_algorithm_imports_no_other_algorithm(name):
    own = ALGORITHMS[name].module
    others = {entry.module for entry in ALGORITHMS.values()} - {own}
    assert GRAPH[own] & others == set()


ENV_SERVICES = ("pamdp.envs.backends", "pamdp.envs.stepping")
"""What the algorithms use of envs/: how an env is made, and how its copies are stepped and their episodes counted."""


@pytest.mark.parametrize("module", ALGOS)
def test_the_algorithms_know_no_env(module):
    # The envs' domains, their presets and the experiments sit above the algorithms: an algorithm trains on whatever
    # env it is given (made and stepped by ENV_SERVICES, which know no domain), and a preset that needs an env's
    # layout (Masson's start on Goal) gives it as data.
    above = ("pamdp.presets", "pamdp.envs", "pamdp.experiments", "pamdp.cli")
    assert sorted(m for m in GRAPH[module] if (m == "pamdp" or m.startswith(above)) and m not in ENV_SERVICES) == []
    env_ids = re.findall(r"pamdp/\w+-v\d+", module_path(module).read_text())
    assert env_ids == []


BELOW_THE_ALGORITHMS = {
    "pamdp.envs": ("pamdp.envs", "pamdp.spaces", "pamdp.hints"),  # a domain, and the envs' backends, know no learner
    "pamdp.evaluation": ENV_SERVICES,
    "pamdp.policies": ("pamdp.distributions", "pamdp.spaces", "pamdp.nn"),
    "pamdp.nn": ("pamdp.nn",),
    "pamdp.distributions": (),
    "pamdp.spaces": (),
    "pamdp.hints": (),
    "pamdp.logger": (),
    "pamdp.atomic": (),
}
"""Each layer below the algorithms (a module, or a package with its modules) and the pamdp modules it may import
(with theirs)."""


@pytest.mark.parametrize("layer", BELOW_THE_ALGORITHMS)
def test_a_layer_below_the_algorithms_imports_nothing_above_it(layer):
    allowed = BELOW_THE_ALGORITHMS[layer]
    modules = [m for m in GRAPH if m == layer or m.startswith(layer + ".")]
    assert modules, f"no module {layer}"
    outside = sorted(
        f"{m} -> {i}" for m in modules for i in GRAPH[m] if not any(i == a or i.startswith(a + ".") for a in allowed)
    )
    assert outside == []


def test_the_layer_rule_finds_an_env_module_that_imports_the_algorithms(monkeypatch):
    monkeypatch.setitem(GRAPH, "pamdp.envs.backends", GRAPH["pamdp.envs.backends"] | {"pamdp.algos.settings"})
    with pytest.raises(AssertionError, match=r"pamdp\.envs\.backends -> pamdp\.algos\.settings"):
        test_a_layer_below_the_algorithms_imports_nothing_above_it("pamdp.envs")
