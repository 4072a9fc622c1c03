"""Regenerate the tables of ``docs/cli.md`` that restate code: each algorithm's command-line name, default budget
and presets (from :data:`pamdp.algos.ALGORITHMS` and :mod:`pamdp.presets`: the configs' own, then the envs').

Each table sits between ``<!-- cli:NAME start -->`` and ``<!-- cli:NAME end -->``; everything between the
markers is replaced.

    python docs/gen_cli_tables.py            # rewrite docs/cli.md in place
    python docs/gen_cli_tables.py --check    # exit 1 if a table is out of date (for CI and the tests)
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

from pamdp.algos import ALGORITHMS, algorithm_class
from pamdp.presets import default_preset, preset_names

DOC = Path(__file__).with_name("cli.md")
BLOCK = re.compile(r"(<!-- cli:([\w-]+) start -->\n)(.*?)(<!-- cli:\2 end -->)", re.DOTALL)


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


TABLES = {"algorithms": algorithms_table}


def render(text: str) -> str:
    def fill(match: re.Match) -> str:
        name = match.group(2)
        if name not in TABLES:
            raise SystemExit(f"{DOC}: no generator for table {name!r}; expected one of {', '.join(TABLES)}")
        return match.group(1) + TABLES[name]() + match.group(4)

    return BLOCK.sub(fill, text)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="exit 1 if docs/cli.md is out of date")
    args = parser.parse_args()
    text = DOC.read_text()
    new = render(text)
    if new != text and args.check:
        print(f"{DOC} is out of date: run python docs/gen_cli_tables.py", file=sys.stderr)
    elif new != text:
        DOC.write_text(new)
    return int(new != text and args.check)


if __name__ == "__main__":
    sys.exit(main())
