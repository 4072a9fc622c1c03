"""PASVG(0) on Platform, tuned preset, 5 seeds x 1M samples: curves, greedy returns, wall time.

    python benchmarks/bench_pasvg_platform.py [--workers 1] [--scale 1.0] [--seeds 0,1,2,3,4] [--out DIR]

Writes benchmarks/pasvg_platform.md and benchmarks/results/pasvg_platform.png; the runs themselves go to
results/bench (not committed) and resume if interrupted.
"""

from _record import main

if __name__ == "__main__":
    main("pasvg_platform.toml", __doc__, workers=1)
