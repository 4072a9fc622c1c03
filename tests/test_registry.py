"""The package's structure: one registry of algorithms behind the command line, algorithms that import family
modules and never each other, and module-level imports without a circle."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import pamdp
from pamdp.algos import ALGORITHMS, AlgoEntry, algorithm_class
from pamdp.cli import build_parser

SRC = Path(pamdp.__file__).parent


def module_imports(path: Path) -> set[str]:
    """The pamdp modules a file imports, at its top or inside its functions; not those only a type checker
    reads (under ``if TYPE_CHECKING:``)."""
    name = "pamdp." + ".".join(path.relative_to(SRC).with_suffix("").parts)
    package = name.removesuffix(".__init__") if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()

    def walk(node):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            return
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            parts = package.split(".")[: len(package.split(".")) - max(node.level - 1, 0)] if node.level else []
            base = ".".join([*parts, *([node.module] if node.module else [])])
            for alias in node.names:
                # `from pamdp.algos import onpolicy` imports a module; `from pamdp.algos import ALGORITHMS` a name
                child = f"{base}.{alias.name}"
                found.add(child if module_path(child) is not None else base)
        for child in ast.iter_child_nodes(node):
            walk(child)

    walk(ast.parse(path.read_text()))
    return {m for m in found if m == "pamdp" or m.startswith("pamdp.")}


def module_path(name: str) -> Path | None:
    parts = name.split(".")[1:]
    for candidate in (SRC.joinpath(*parts).with_suffix(".py"), SRC.joinpath(*parts, "__init__.py")):
        if parts and candidate.is_file():
            return candidate
    return SRC / "__init__.py" if not parts else None


def test_the_command_line_offers_each_registered_algorithm_with_its_help_and_budget(monkeypatch, capsys):
    monkeypatch.setitem(ALGORITHMS, "patrpo-copy", AlgoEntry("pamdp.algos.patrpo:PATRPO", "a registered copy", 1234))
    parser = build_parser()
    with pytest.raises(SystemExit):
        parser.parse_args(["train", "--help"])
    listing = capsys.readouterr().out
    for name, entry in ALGORITHMS.items():
        assert name in listing and entry.help.split()[0] in listing
    with pytest.raises(SystemExit):
        parser.parse_args(["train", "patrpo-copy", "--help"])
    assert "(default: 1,234)" in " ".join(capsys.readouterr().out.split())


@pytest.mark.parametrize("name", list(ALGORITHMS))
def test_each_entry_names_its_class(name):
    cls = algorithm_class(name)
    assert cls.__name__ == ALGORITHMS[name].class_name and cls.__module__ == ALGORITHMS[name].module


@pytest.mark.parametrize("name", list(ALGORITHMS))
def test_an_algorithm_imports_no_other_algorithm(name):
    own = ALGORITHMS[name].module
    others = {entry.module for entry in ALGORITHMS.values()} - {own}
    assert module_imports(module_path(own)) & others == set()


def test_no_import_circle_in_the_package():
    graph = {}
    for path in SRC.rglob("*.py"):
        name = "pamdp." + ".".join(path.relative_to(SRC).with_suffix("").parts)
        graph[name.removesuffix(".__init__")] = module_imports(path)
    state: dict[str, str] = {}

    def visit(node, trail):
        if state.get(node) == "done":
            return
        assert state.get(node) != "open", "import circle: " + " -> ".join([*trail[trail.index(node) :], node])
        state[node] = "open"
        for child in sorted(graph.get(node, ())):
            visit(child, [*trail, node])
        state[node] = "done"

    for node in sorted(graph):
        visit(node, [])
