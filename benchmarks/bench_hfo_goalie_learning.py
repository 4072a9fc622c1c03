"""Half Field Offense against the real server's goalie (issue 43): greedy goal rate, steps to goal and capture rate
of each arm's seeds, in benchmarks/hfo_goalie_learning.md: the packaged recipe (``pamdp reproduce hfo-goalie``)
first, then every arm of hfo_goalie_learning.toml (what was tried on the way).

    nice pamdp reproduce hfo-goalie --out DIR --workers 2      # the recipe's runs
    nice python benchmarks/bench_hfo_goalie_learning.py [--runs "PATRPO from 1v0"] [--seeds 0,1,2] [--workers 2]
        [--out DIR] [--record-only]

Runs the chosen arms of hfo_goalie_learning.toml seed by seed, each resuming from its checkpoint (an arm started
from another's model waits for that run of the same seed, listed before it), and rewrites the record after every
finished run, with the recipe's runs found under the same ``--out``.
"""

from __future__ import annotations

from pathlib import Path

from _record import HERE, seed_by_seed_main
from bench_hfo_learning import write

from pamdp.experiments import load_experiment

RECORD = HERE / "hfo_goalie_learning.md"


def with_recipe(arms: dict, out_root: str) -> dict:
    """The packaged recipe's arms (``hfo-goalie``, each with its own seeds) before ``arms``."""
    recipe = load_experiment("hfo-goalie")
    jobs = recipe.jobs(out_root, recipe.specs())
    found = {
        run["label"]: [(spec, Path(out)) for spec, out in jobs if spec.label == run["label"]] for run in recipe.runs
    }
    return {**{f"recipe: {label}": pairs for label, pairs in found.items()}, **arms}


if __name__ == "__main__":
    exp = load_experiment(HERE / "hfo_goalie_learning.toml")
    seed_by_seed_main(
        __doc__,
        exp,
        lambda arms, out, command: write(exp, with_recipe(arms, out), out, command, RECORD, captures=True),
    )
