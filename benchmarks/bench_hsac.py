"""Hybrid SAC on Platform, flat and hierarchical forms (hsac_platform.toml): 5 seeds x 300k samples each.

    taskset -c 0 python benchmarks/bench_hsac.py [--seeds 0,1,2,3,4] [--runs flat,hierarchical] [--out DIR]
        [--record-only]

Runs one at a time, seed by seed, the two forms alternating (so that a cut-short invocation still compares the
forms), and rewrites benchmarks/hsac_platform.md after each seed's runs: the greedy return of each finished seed (1000
episodes) with the median and mean per form, and the cost per sample (CPU seconds from each run's progress.csv).
The runs go to DIR/hsac_platform/FORM/seedN (default results/bench) and resume where they stopped, so a rerun
continues the benchmark; the record keeps its hand-written notes.
"""

from __future__ import annotations

import numpy as np
from _record import (
    HERE,
    arm_runs,
    record_head,
    seed_by_seed_main,
    write_record,
)

from pamdp.experiments import load_experiment

RECORD = HERE / "hsac_platform.md"


def _arm_lines(label: str, jobs) -> list[str]:
    """One row of the table: the finished seeds' greedy returns, their median and mean, the cost per sample."""
    runs, partial = arm_runs(jobs, "eval/mean_return", 3, " samples")
    returns = [(seed, evaluation["mean_return"]) for seed, evaluation, _ in runs]
    costs = [cost for _, _, cost in runs]
    values = np.array([r for _, r in returns])
    per_seed = ", ".join(f"{s}: {r:.3f}" for s, r in returns) or "-"
    median = f"{np.median(values):.3f}" if len(values) else "-"
    mean = f"{values.mean():.3f} +- {values.std():.3f}" if len(values) else "-"
    cost = f"{np.median(costs):.2f}" if costs else "-"
    row = f"| {label} | {len(returns)} of {len(jobs)} | {per_seed} | {median} | {mean} | {cost} |"
    return [row] + ([f"| {label} (unfinished) | | {'; '.join(partial)} | | | |"] if partial else [])


def write(exp, arms: dict, command: str) -> None:
    lines = record_head(exp.description, command, rewritten=True) + [
        f"- {exp.total_steps:,} samples per run, one run at a time; greedy return: 1000 episodes of the final model",
        "",
        "| form | seeds done | greedy return per seed | median | mean +- std | CPU ms per sample |",
        "|---|---|---|---|---|---|",
    ]
    for label, jobs in arms.items():
        lines += _arm_lines(label, jobs)
    lines += [
        "",
        "CPU ms per sample: the run's CPU time in training (its greedy evaluations left out) over its samples, "
        "median over the finished seeds.",
    ]
    write_record(lines, RECORD)


if __name__ == "__main__":
    exp = load_experiment(HERE / "hsac_platform.toml")
    seed_by_seed_main(__doc__, exp, lambda arms, out, command: write(exp, arms, command))
