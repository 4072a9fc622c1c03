"""Regenerate the tables of the docs that restate code: the commands (from the parser of ``pamdp``), each
algorithm's command-line name, default budget and presets (from :data:`pamdp.algos.ALGORITHMS` and
:mod:`pamdp.presets`: the configs' own, then the envs'), the experiments of ``pamdp reproduce`` (from their files)
in ``docs/cli.md``, the registered env ids in ``docs/environments.md``, and the search space of each algorithm
(from :data:`pamdp.experiments.tune.SEARCH_SPACES`) in ``docs/tune.md``.

Each table sits between ``<!-- cli:NAME start -->`` and ``<!-- cli:NAME end -->``; everything between the
markers is replaced.

    python docs/gen_cli_tables.py            # rewrite the docs in place
    python docs/gen_cli_tables.py --check    # exit 1 if a table is out of date (for CI and the tests)
"""

from __future__ import annotations

import argparse
import re
import sys
import warnings
from pathlib import Path

from pamdp.algos import ALGORITHMS, algorithm_class
from pamdp.presets import default_preset, preset_names

DOCS = [Path(__file__).with_name(name) for name in ("cli.md", "environments.md", "tune.md")]
BLOCK = re.compile(r"(<!-- cli:([\w-]+) start -->\n)(.*?)(<!-- cli:\2 end -->)", re.DOTALL)


def commands_block() -> str:
    """Each command of ``pamdp``, its arguments and its ``--help`` line."""
    from pamdp.cli import build_parser

    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    helps = {action.dest: action.help for action in sub._choices_actions}
    lines = []
    for name, parser in sub.choices.items():
        args = []
        for action in parser._actions:
            if action.option_strings or action.dest == "help":
                continue
            word = (action.metavar or action.dest).upper()
            args.append(word + "..." if action.nargs == "+" else word)
        lines.append((f"pamdp {name} {' '.join(args)}", helps[name]))
    width = max(len(usage) for usage, _ in lines) + 2
    return "```\n" + "".join(f"{usage:<{width}}{text}\n" for usage, text in lines) + "```\n"


def algorithms_table() -> str:
    rows = [
        "| `ALGO` | algorithm | `--total-steps` default | `--preset` choices (the default in bold) |",
        "|---|---|---|---|",
    ]
    for name, entry in ALGORITHMS.items():
        config_class = algorithm_class(name).config_class
        default = default_preset(config_class)
        presets = ", ".join(f"**`{p}`**" if p == default else f"`{p}`" for p in preset_names(config_class))
        rows.append(f"| `{name}` | {entry.help} | {entry.total_steps:,} | {presets} |")
    return "\n".join(rows) + "\n"


def experiments_table() -> str:
    """The experiments ``pamdp reproduce NAME`` knows: their description, runs, seeds and budgets."""
    from pamdp.experiments import available_experiments, load_experiment

    rows = ["| `NAME` | experiment | runs | seeds | steps a run |", "|---|---|---|---|---|"]
    for name in available_experiments():
        exp = load_experiment(name)
        budgets = sorted({run.get("total_steps", exp.total_steps) for run in exp.runs})
        steps = " to ".join(f"{b:,}" for b in (budgets[0], budgets[-1])[: 1 + (len(budgets) > 1)])
        seeds = ", ".join(map(str, exp.seeds))
        rows.append(f"| `{name}` | {exp.description} | {len(exp.runs)} | {seeds} | {steps} |")
    return "\n".join(rows) + "\n"


def _space(space) -> str:
    """A parameterized action space in short: ``Tuple(Discrete(3), Tuple(Box(1), Box(1), Box(1)))``, with runs of
    equal boxes counted (``Box(4) x 16``)."""
    from pamdp.spaces import HybridActionSpace

    sizes = HybridActionSpace.from_gym(space).param_sizes
    runs: list[list[int]] = []
    for size in sizes:
        if runs and runs[-1][0] == size:
            runs[-1][1] += 1
        else:
            runs.append([size, 1])
    boxes = ", ".join(f"Box({size})" + (f" x {count}" if count > 1 else "") for size, count in runs)
    return f"Tuple(Discrete({len(sizes)}), Tuple({boxes}))"


def envs_table() -> str:
    """Every env ``import pamdp`` registers: its classes, its action space (default arguments) and GIF frame rate."""
    import gymnasium

    import pamdp  # noqa: F401  (registers the envs)

    rows = [
        "| id | scalar | batched (`vector_entry_point`) | action space (default arguments) | GIF frames a second |",
        "|---|---|---|---|---|",
    ]
    for env_id, spec in gymnasium.registry.items():
        if not env_id.startswith("pamdp/"):
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            env = gymnasium.make(env_id)
        scalar, batched = (str(e).replace(":", ".") for e in (spec.entry_point, spec.vector_entry_point))
        fps = env.metadata.get("render_fps", "-")
        rows.append(f"| `{env_id}` | `{scalar}` | `{batched}` | `{_space(env.action_space)}` | {fps} |")
        env.close()
    return "\n".join(rows) + "\n"


def search_spaces_table() -> str:
    """What ``pamdp tune ALGO`` searches: each algorithm's settings, their ranges and why."""
    from pamdp.experiments.tune import SEARCH_SPACES

    rows = ["| `ALGO` | setting | range | why |", "|---|---|---|---|"]
    for algo, space in SEARCH_SPACES.items():
        rows += [f"| `{algo}` | `{name}` | {dim.describe()} | {dim.note} |" for name, dim in space.items()]
    return "\n".join(rows) + "\n"


TABLES = {
    "commands": commands_block,
    "algorithms": algorithms_table,
    "experiments": experiments_table,
    "envs": envs_table,
    "search-spaces": search_spaces_table,
}


def render(text: str, doc: Path = DOCS[0]) -> str:
    def fill(match: re.Match) -> str:
        name = match.group(2)
        if name not in TABLES:
            raise SystemExit(f"{doc}: no generator for table {name!r}; expected one of {', '.join(TABLES)}")
        return match.group(1) + TABLES[name]() + match.group(4)

    return BLOCK.sub(fill, text)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="exit 1 if a doc is out of date")
    args = parser.parse_args()
    stale = []
    for doc in DOCS:
        text = doc.read_text()
        new = render(text, doc)
        if new != text and args.check:
            stale.append(doc)
            print(f"{doc} is out of date: run python docs/gen_cli_tables.py", file=sys.stderr)
        elif new != text:
            doc.write_text(new)
    return int(bool(stale))


if __name__ == "__main__":
    sys.exit(main())
