"""Regenerate the settings tables of ``docs/algorithms.md`` from the config dataclasses.

Each table sits between two marker comments, ``<!-- settings:NAME start -->`` and
``<!-- settings:NAME end -->``, where ``NAME`` is a config class below; everything between the markers is
replaced. A row per ``dataclasses.fields(Config)``: the name, the type, the default, the value in each
preset that differs from the default (blank where it does not), the field's ``metadata["help"]`` and the values
its check accepts (``Config.check_of(name)``). Between ``<!-- domain-presets start -->`` and
``<!-- domain-presets end -->``: the presets chosen by the env (``pamdp.presets.domains.DOMAIN_PRESETS``),
each with the env arguments it asks for and each override with its source.

    python docs/gen_settings.py            # rewrite docs/algorithms.md in place
    python docs/gen_settings.py --check    # exit 1 if the tables are out of date (for CI)
"""

from __future__ import annotations

import argparse
import dataclasses
import re
import sys
import typing
from pathlib import Path

from pamdp.algos import ALGORITHMS, algorithm_class
from pamdp.presets.domains import DOMAIN_PRESETS

UNCONSTRAINED = {bool: "True or False", int: "any integer", float: "any finite number"}
# every registered algorithm's config, so that a new algorithm's table is asked for (its markers) and written
CONFIGS = {c.__name__: c for c in (algorithm_class(name).config_class for name in ALGORITHMS)}
DOC = Path(__file__).with_name("algorithms.md")
BLOCK = re.compile(r"(<!-- settings:(\w+) start -->\n)(.*?)(<!-- settings:\2 end -->)", re.DOTALL)
DOMAIN_BLOCK = re.compile(r"(<!-- domain-presets start -->\n)(.*?)(<!-- domain-presets end -->)", re.DOTALL)


def _value(v) -> str:
    if isinstance(v, tuple):
        return "(" + ", ".join(_value(x) for x in v) + ("," if len(v) == 1 else "") + ")"
    if isinstance(v, int) and not isinstance(v, bool) and abs(v) >= 10_000:
        return f"{v:_}"
    return repr(v)


def _type(hint) -> str:
    if typing.get_origin(hint) is tuple:
        return "tuple[" + ", ".join(getattr(a, "__name__", "...") for a in typing.get_args(hint)) + "]"
    return getattr(hint, "__name__", str(hint))


def table(config_class) -> str:
    """The markdown table of one config class, with a line naming presets identical to the defaults."""
    default = config_class()
    presets = config_class.presets()
    differing = {n: p for n, p in presets.items() if p != default}
    same = [n for n in presets if n not in differing]
    hints = typing.get_type_hints(config_class)
    head = ["setting", "type", "default", *(f"`{n}`" for n in differing), "meaning", "valid"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for f in dataclasses.fields(config_class):
        base = getattr(default, f.name)
        type_cell = _type(hints[f.name]).replace("|", "\\|")  # float | None: not a cell boundary
        cells = [f"`{f.name}`", f"`{type_cell}`", f"`{_value(base)}`"]
        for p in differing.values():
            v = getattr(p, f.name)
            cells.append(f"`{_value(v)}`" if v != base else "")
        cells.append(f.metadata.get("help", "").replace("|", "\\|"))
        check = config_class.check_of(f.name)
        cells.append(check.expected if check else UNCONSTRAINED.get(hints[f.name], "any"))
        lines.append("| " + " | ".join(cells) + " |")
    if same:
        names = ", ".join(f"`{n}`" for n in same)
        verb = "is" if len(same) == 1 else "are"
        lines += ["", f"Preset {names} {verb} the defaults."]
    return "\n".join(lines) + "\n"


def domain_table() -> str:
    """The markdown table of the presets chosen by the env."""
    lines = [
        "| algorithm | env | preset | over | settings (source) | note |",
        "|---|---|---|---|---|---|",
    ]
    for (algo, env_id, match), p in DOMAIN_PRESETS.items():
        over = "" if p.base == p.name else f"`{p.base}`"
        settings = "; ".join(f"`{n} = {_value(v)}` ({src})" for n, v, src in p.overrides) or "the preset as it is"
        note = p.note.replace("|", "\\|")
        env = f"`{env_id}`" + "".join(f", {n} in {{{', '.join(map(str, vs))}}}" for n, vs in match)
        lines.append(f"| `{algo}` | {env} | `{p.name}` | {over} | {settings} | {note} |")
    return "\n".join(lines) + "\n"


def render(text: str) -> str:
    def replace(m: re.Match) -> str:
        name = m.group(2)
        if name not in CONFIGS:
            raise SystemExit(f"unknown config {name!r} in a settings marker; expected one of {', '.join(CONFIGS)}")
        return m.group(1) + table(CONFIGS[name]) + m.group(4)

    text = BLOCK.sub(replace, text)
    return DOMAIN_BLOCK.sub(lambda m: m.group(1) + domain_table() + m.group(3), text)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="report out-of-date tables instead of writing")
    args = parser.parse_args(argv)
    text = DOC.read_text()
    found = {m.group(2) for m in BLOCK.finditer(text)}
    missing = sorted(set(CONFIGS) - found) + ([] if DOMAIN_BLOCK.search(text) else ["domain-presets"])
    if missing:
        print(f"{DOC}: no settings markers for {', '.join(missing)}", file=sys.stderr)
        return 1
    new = render(text)
    if args.check:
        if new != text:
            print(f"{DOC}: settings tables are out of date; run python docs/gen_settings.py", file=sys.stderr)
            return 1
        return 0
    if new != text:
        DOC.write_text(new)
        print(f"rewrote the settings tables in {DOC}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
