"""PATRPO on Platform, paper and tuned presets, 5 seeds x 1M samples: curves, greedy returns, wall time.

    python benchmarks/bench_patrpo_platform.py [--workers 2] [--scale 1.0] [--seeds 0,1,2,3,4] [--out DIR]

Writes benchmarks/patrpo_platform.md and benchmarks/results/patrpo_platform.png; the runs themselves go to
results/bench (not committed) and resume if interrupted.
"""

from _record import main

if __name__ == "__main__":
    main("patrpo_platform.toml", __doc__)
