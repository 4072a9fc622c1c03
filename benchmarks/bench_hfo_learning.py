"""Every algorithm on Half Field Offense 1v0 (hfo_learning.toml, issue 27): greedy goal rate and steps to goal.

    nice python benchmarks/bench_hfo_learning.py [--runs "PATRPO tuned,MP-DQN"] [--seeds 0,1,2] [--workers 2]
        [--out DIR] [--record-only]

(Against the goalie, 1v1: bench_hfo_goalie_learning.py, the same record with the capture rate.)

Runs the chosen arms (default: every arm of the file) seed by seed, each resuming from its checkpoint, and after
every finished run rewrites benchmarks/hfo_learning.md: per arm, each finished seed's greedy goal rate and mean
steps to goal over 1000 episodes, their medians over seeds (the issue's measure), the cost per sample, and the
figures of the greedy goal rate during training. ``--record-only`` trains nothing: it writes the record from the
runs already under DIR (``pamdp reproduce benchmarks/hfo_learning.toml --out DIR`` makes the same runs).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
from _record import (
    HERE,
    arm_runs,
    progress_rows,
    record_head,
    seed_by_seed_main,
    write_record,
)

from pamdp.experiments import load_experiment
from pamdp.experiments.report import write_report
from pamdp.logger import success_of

RECORD = HERE / "hfo_learning.md"


CAPTURED = "CAPTURED_BY_DEFENSE"


def _arm_row(label: str, jobs, captures: bool = False) -> str:
    """One line of the table: the finished seeds' goal rates and steps, their medians, the cost per sample, and
    where the unfinished seeds stand; ``captures``: also each seed's share of episodes the goalie captured."""
    runs, partial = arm_runs(jobs, "eval/success_rate")
    done = [(seed, *success_of(e), e.get("endings", {}).get(CAPTURED, 0.0)) for seed, e, _ in runs]
    costs = [cost for _, _, cost in runs]
    per_seed = ", ".join(
        (f"{s}: {r:.3f} in {n:.1f}" if n else f"{s}: {r:.3f}") + (f" (captured {c:.3f})" if captures else "")
        for s, r, n, c in done
    )
    rates = [r for _, r, _, _ in done]
    steps = [n for _, _, n, _ in done if n]
    return (
        f"| {label} | {jobs[0][0].total_steps:,} | {len(done)} of {len(jobs)} | {per_seed or '-'} "
        f"| {f'{np.median(rates):.3f}' if rates else '-'} | {f'{np.median(steps):.1f}' if steps else '-'} "
        f"| {f'{np.median(costs):.2f}' if costs else '-'} | {'; '.join(partial) or '-'} |"
    )


def write(exp, arms: dict, out_root: str, command: str, record: Path = RECORD, captures: bool = False) -> None:
    """Rewrite ``record`` (its hand-written notes kept) from the runs of ``arms`` under ``out_root``."""
    lines = record_head(exp.description, command, rewritten=True) + [
        "- each arm with the preset its `--env` picks unless named, `action_mask = true` unless the label says "
        f'"no mask" ([{exp.name}.toml]({exp.name}.toml)); goal rate and steps to goal'
        + (", and the share of episodes the goalie captured" * captures)
        + ": 1000 greedy episodes of each seed's final model",
        "",
        "| arm | samples | seeds done | goal rate in steps, per seed | median goal rate | median steps to goal "
        "| CPU ms per sample | unfinished |",
        "|---|---|---|---|---|---|---|---|",
    ]
    lines += [_arm_row(label, jobs, captures) for label, jobs in arms.items()]
    lines += [
        "",
        "CPU ms per sample: the run's CPU time in training (its greedy evaluations left out) over its samples, "
        "median over the finished seeds. Unfinished: each started seed's samples so far and its last greedy "
        "evaluation.",
    ]
    started = [out.parent for jobs in arms.values() for _, out in jobs if progress_rows(out)]
    if started:
        report = write_report(list(dict.fromkeys(started)), Path(out_root) / exp.name / f"report-{exp.name}")
        for key, name in (("greedy_success_png", "greedy goal rate"), ("success_png", "training goal rate")):
            if key in report:
                figure = HERE / "results" / f"{exp.name}_{key.removesuffix('_png')}.png"
                figure.parent.mkdir(exist_ok=True)
                shutil.copy(report[key], figure)
                lines += ["", f"![{name}](results/{figure.name})"]
        lines += [
            "",
            "Greedy goal rate: 100 greedy episodes every `eval_every` epochs, mean +- std over seeds. Training goal "
            "rate: the share of each epoch's (stochastic, exploring) episodes that scored.",
        ]
    write_record(lines, record)


if __name__ == "__main__":
    exp = load_experiment(HERE / "hfo_learning.toml")
    seed_by_seed_main(__doc__, exp, lambda arms, out, command: write(exp, arms, out, command))
