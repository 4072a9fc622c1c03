"""MP-DQN and P-DQN on Platform, tuned preset, 5 seeds x 300k samples: curves, greedy returns, wall time.

    python benchmarks/bench_pdqn_platform.py [--workers 2] [--scale 1.0] [--seeds 0,1,2,3,4] [--out DIR]

Writes benchmarks/pdqn_platform.md and benchmarks/results/pdqn_platform.png; the runs themselves go to
results/bench (not committed) and resume if interrupted. ``--scale`` multiplies pdqn_platform.toml's budget.
"""

from _record import main

if __name__ == "__main__":
    main("pdqn_platform.toml", __doc__, workers=2)
