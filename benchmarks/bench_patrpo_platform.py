"""PATRPO on Platform, paper and tuned presets, 5 seeds x 1M samples: curves, greedy returns, wall time.

    python benchmarks/bench_patrpo_platform.py [--workers 2] [--scale 1.0] [--seeds 0,1,2,3,4]

Writes benchmarks/patrpo_platform.md and benchmarks/results/patrpo_platform.png; the runs themselves go to
results/bench (not committed) and resume if interrupted.
"""

import argparse

from _record import run_and_record

if __name__ == "__main__":
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--scale", type=float, default=1.0)
    p.add_argument("--seeds", default=None)
    p.add_argument("--out", default="results/bench")
    a = p.parse_args()
    seeds = [int(s) for s in a.seeds.split(",")] if a.seeds else None
    run_and_record("patrpo_platform.toml", a.out, "patrpo_platform.md", a.workers, a.scale, seeds)
