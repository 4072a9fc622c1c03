"""The README's main job (``pamdp train patrpo``) over 10 seeds, beside candidate changes (main_job.toml): how many
seeds reach a greedy return of 0.99 (issue 45 asks for 9 of 10).

    nice python benchmarks/bench_main_job.py [--workers 1] [--runs default] [--seeds 0,1,...] [--out DIR]
        [--record-only]

Runs the arms seed by seed across the arms (a cut-short invocation still compares them), each resuming from its
checkpoint, and rewrites benchmarks/main_job.md after every seed.
"""

from __future__ import annotations

import numpy as np
from _record import (
    HERE,
    arm_runs,
    median_minutes,
    per_seed,
    record_head,
    seed_by_seed_main,
    write_record,
)

from pamdp.experiments import load_experiment

RECORD = HERE / "main_job.md"
SOLVED = 0.99  # the bar: Platform's greedy return, 1.0 for crossing every gap


def arm_row(label: str, jobs) -> str:
    runs, partial = arm_runs(jobs, "eval/mean_return")
    done = [(seed, evaluation["mean_return"]) for seed, evaluation, _ in runs]
    returns = [r for _, r in done]
    solved = sum(r >= SOLVED for r in returns)
    return (
        f"| {label} | {jobs[0][0].total_steps:,} | {len(done)} of {len(jobs)} "
        f"| {per_seed(done)} | {f'{solved} of {len(done)}' if done else '-'} "
        f"| {f'{np.median(returns):.3f}' if returns else '-'} | {f'{min(returns):.3f}' if returns else '-'} "
        f"| {median_minutes(runs, jobs[0][0].total_steps)} | {'; '.join(partial) or '-'} |"
    )


def write(exp, arms: dict, command: str) -> None:
    lines = record_head(exp.description, command, rewritten=True) + [
        f"- the arms of [{exp.name}.toml]({exp.name}.toml); greedy return: 1000 greedy episodes of each seed's "
        "final model",
        "",
        f"| arm | samples | seeds done | greedy return per seed | seeds at {SOLVED} or more | median | worst "
        "| CPU minutes a run (median) | unfinished |",
        "|---|---|---|---|---|---|---|---|---|",
        *(arm_row(label, jobs) for label, jobs in arms.items()),
        "",
        "CPU minutes: the run's CPU time in training (its greedy evaluations left out), median over the finished "
        "seeds; another run shared the 2 cores with it.",
    ]
    write_record(lines, RECORD)


if __name__ == "__main__":
    exp = load_experiment(HERE / "main_job.toml")
    seed_by_seed_main(__doc__, exp, lambda arms, out, command: write(exp, arms, command))
