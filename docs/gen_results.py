"""Regenerate the tables and figures of ``docs/results.md`` that come from runs, from the committed run summaries.

Each experiment's summaries lie in ``docs/results/summaries/EXPERIMENT/ARM/seedN.json`` (``pamdp summarize RUN_DIR
--out docs/results/summaries/EXPERIMENT``; :mod:`pamdp.experiments.summary`). Each table sits between
``<!-- results:NAME start -->`` and ``<!-- results:NAME end -->`` in ``docs/results.md`` (and the README's line of
the suite's aggregates); everything between the markers is replaced. The benchmark suite's ``suite.md`` and
``suite-finals.json`` (the archive that ``pamdp plot --suite-archive`` reads) are rewritten from the same
summaries, and its performance profiles, sample-efficiency figure and a figure per domain are drawn.

    python docs/gen_results.py            # rewrite the tables, suite.md, suite-finals.json and the figures
    python docs/gen_results.py --check    # exit 1 if a table or file is out of date (for CI and the tests)
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path

from pamdp.experiments import load_experiment, results
from pamdp.experiments.suite import suite_table
from pamdp.experiments.summary import load

DOCS = Path(__file__).parent
PAGE = DOCS / "results.md"
README = DOCS.parent / "README.md"
SUMMARIES = DOCS / "results" / "summaries"
SUITE = DOCS / "results" / "benchmark-suite"
BLOCK = re.compile(r"(<!-- results:([\w-]+) start -->\n)(.*?)(<!-- results:\2 end -->)", re.DOTALL)


def summaries(experiment: str) -> list[dict]:
    """The committed summaries of an experiment, in path order."""
    return [load(path) for path in sorted((SUMMARIES / experiment).rglob("*.json"))]


def tables() -> dict[str, str]:
    """Each generated table of the page by its marker's name."""
    suite = summaries("benchmark-suite")
    planned = results.planned_cells(load_experiment("benchmark-suite").specs())  # its cells not run yet owe runs too
    return {
        "suite": suite_table(results.finals(suite)) + "\n",
        "suite-stats": results.stats_table(suite, planned) + "\n",
        "suite-aggregate": results.aggregate_table(suite) + "\n",
        "suite-improvement": results.improvement_table(suite) + "\n",
        "suite-efficiency": results.efficiency_table(suite) + "\n",
        "suite-standing": results.standing_table(suite) + "\n",
        "one-preset": results.one_preset_table(summaries("one-preset"), suite) + "\n",
        "readme-suite": "Benchmark suite, generated from the committed summaries ([how](docs/results.md"
        "#intervals-profiles-and-sample-efficiency-issue-44)): " + results.aggregate_line(suite) + " "
        + results.runs_line(suite, planned) + "\n",
        "readme-standing": results.standing_line(suite) + "\n",
    }


def files() -> dict[Path, str]:
    """The suite's table and archive beside its figures, as the summaries give them."""
    suite = summaries("benchmark-suite")
    return {
        SUITE / "suite.md": suite_table(results.finals(suite)) + "\n",
        SUITE / "suite-finals.json": json.dumps(results.finals(suite), indent=1) + "\n",
    }


def render(text: str, page: Path = PAGE) -> str:
    generated = tables()

    def fill(match: re.Match) -> str:
        name = match.group(2)
        if name not in generated:
            raise SystemExit(f"{page}: no generator for table {name!r}; expected one of {', '.join(generated)}")
        return match.group(1) + generated[name] + match.group(4)

    return BLOCK.sub(fill, text)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="exit 1 if a table or file is out of date")
    args = parser.parse_args()
    wanted = {page: render(page.read_text(), page) for page in (PAGE, README)} | files()
    stale = [path for path, text in wanted.items() if not path.exists() or path.read_text() != text]
    if args.check:
        for path in stale:
            print(f"{path} is out of date: run python docs/gen_results.py", file=sys.stderr)
        return int(bool(stale))
    for path in stale:
        path.write_text(wanted[path])
    results.plot_profiles(summaries("benchmark-suite"), SUITE / "profiles")
    results.plot_efficiency(summaries("benchmark-suite"), SUITE / "efficiency")
    results.plot_domains(summaries("benchmark-suite"), SUITE)
    return 0


if __name__ == "__main__":
    sys.exit(main())
