"""PADDPG on Platform with Hausknecht & Stone's preset, 1 seed x 300k samples (issue 5's fairness check).

    python benchmarks/bench_paddpg_hausknecht_stone.py [--workers 1] [--scale 1.0] [--out DIR]

Writes benchmarks/paddpg_hausknecht_stone.md with its learning curve and greedy evaluations during training;
the run goes to DIR/paddpg_hausknecht_stone (not committed) and resumes if interrupted.
"""

from _record import main

if __name__ == "__main__":
    main("paddpg_hausknecht_stone.toml", __doc__, workers=1)
