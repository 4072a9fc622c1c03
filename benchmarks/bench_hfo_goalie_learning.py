"""Half Field Offense against the real server's goalie (hfo_goalie_learning.toml, issue 43): greedy goal rate, steps
to goal and capture rate of each arm's seeds, in benchmarks/hfo_goalie_learning.md.

    nice python benchmarks/bench_hfo_goalie_learning.py [--runs "PATRPO from 1v0"] [--seeds 0,1,2] [--workers 2]
        [--out DIR] [--record-only]

Runs the chosen arms seed by seed, each resuming from its checkpoint (an arm started from another's model waits
for that run of the same seed, listed before it), and rewrites the record after every finished run;
``pamdp reproduce benchmarks/hfo_goalie_learning.toml --out DIR`` makes the same runs.
"""

from __future__ import annotations

from _record import HERE, seed_by_seed_main
from bench_hfo_learning import write

from pamdp.experiments import load_experiment

RECORD = HERE / "hfo_goalie_learning.md"

if __name__ == "__main__":
    exp = load_experiment(HERE / "hfo_goalie_learning.toml")
    seed_by_seed_main(__doc__, exp, lambda arms, out, command: write(exp, arms, out, command, RECORD, captures=True))
