"""PADDPG on Platform, the seed paper's preset, 3 seeds x 150k samples: curves, greedy returns, wall time.

    python benchmarks/bench_paddpg_platform.py [--workers 1] [--scale 1.0] [--seeds 0,1,2] [--out DIR]

Writes benchmarks/paddpg_platform.md and benchmarks/results/paddpg_platform.png; the runs themselves go to
results/bench (not committed) and resume if interrupted. ``--scale`` multiplies paddpg_platform.toml's budget.
"""

from _record import main

if __name__ == "__main__":
    main("paddpg_platform.toml", __doc__, workers=1)
