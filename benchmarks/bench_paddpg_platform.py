"""PADDPG on Platform, the seed paper's preset, 5 seeds x 1M samples (issue 5): curves, greedy returns, times.

    python benchmarks/bench_paddpg_platform.py [--workers 2] [--scale 1.0] [--seeds 0,1,2,3,4] [--out DIR]

These are the PADDPG arm of the paper's ``platform`` experiment: with ``--out DIR`` the runs go to
``DIR/platform/PADDPG/seedN``, where ``pamdp reproduce platform --out DIR`` finds them finished (and the other
way round). One update per sample with {400, 300} networks is 3 to 5 hours of one core per run here, so the
runs resume across sessions (``save_replay`` keeps the replay buffer in each checkpoint).

Writes benchmarks/paddpg_platform.md, benchmarks/results/paddpg_platform.png and, from the greedy evaluations
every 5 epochs, benchmarks/results/paddpg_platform_greedy.png.
"""

from _record import main

if __name__ == "__main__":
    main(
        "platform",
        __doc__,
        workers=2,
        runs=["PADDPG"],
        record="paddpg_platform.md",
        title="PADDPG on Platform: the seed paper's preset, 5 seeds x 1M samples",
    )
