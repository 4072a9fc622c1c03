"""Later methods on Platform (MP-DQN, P-DQN, H-PPO as PAPPO), tuned presets, 5 seeds x 300k samples.

    python benchmarks/bench_later_platform.py [--workers 2] [--scale 1.0] [--seeds 0,1,2,3,4] [--out DIR]

Writes benchmarks/later_platform.md and benchmarks/results/later_platform.png; the runs themselves go to
results/bench (not committed) and resume if interrupted. ``--scale`` multiplies later_platform.toml's budget.
"""

from _record import main

if __name__ == "__main__":
    main("later_platform.toml", __doc__, workers=2)
