"""Where an experiment stands, read from its run directories: ``pamdp reproduce NAME --status``.

The paper's experiments take tens of CPU-hours on a laptop and are run over many sittings, each resuming
where the last one stopped. This reads every run's directory without training anything and reports, per run,
whether it is finished, partial (it resumes from its checkpoint) or not started, how many samples it has and
how long it trained, and for the experiment the training time still to go, extrapolated from the time per
sample its runs have taken so far. A run whose directory is gone but whose summary was kept
(``--recorded``) is "recorded", and counts as done.
"""

from __future__ import annotations

import csv
import dataclasses
import json
import math
import statistics
import time
from pathlib import Path

from pamdp.experiments.runner import RunSpec, is_finished
from pamdp.logger import success_of

__all__ = ["RunStatus", "run_status", "recorded_status", "format_status", "remaining_seconds"]

DONE, PARTIAL, NOT_STARTED, RECORDED = "done", "partial", "not started", "recorded"
RECENT_EPOCHS = 5  # a run's pace is taken over its last epochs: code, load and phases change it as a run goes


@dataclasses.dataclass
class RunStatus:
    """One run's state, from its directory."""

    label: str
    seed: int
    out: str
    state: str  # "done", "partial", "not started" or "recorded" (its summary kept, its directory not at hand)
    steps: int  # samples trained on so far (from progress.csv)
    total_steps: int
    train_seconds: float  # summed epoch times from progress.csv
    last_return: float | None  # mean training return of the last epoch
    greedy_return: float | None  # the final greedy evaluation, once done
    success_rate: float | None  # of the final greedy evaluation, where the env reports success
    idle_seconds: float | None  # since progress.csv was last written; small while a run is training
    seconds_per_step: float | None = None  # the run's pace, from :func:`recent_pace`; None before it has one


def _float(value) -> float | None:
    try:
        x = float(value)
    except (TypeError, ValueError):
        return None
    return x if math.isfinite(x) else None


def epoch_seconds(row: dict) -> float:
    """Training seconds of one ``progress.csv`` row: its CPU time where logged (runs since 2026-11-29), which
    leaves out the time a run spent suspended, else its wall-clock time."""
    cpu = _float(row.get("time/epoch_cpu_seconds"))
    return cpu if cpu is not None else (_float(row.get("time/epoch_seconds")) or 0.0)


def recent_pace(rows: list[dict]) -> float | None:
    """Training seconds per sample over a run's last ``RECENT_EPOCHS`` epochs at its full rate of updates.

    An off-policy run's first epochs fill its replay buffer and update little or not at all (``train/updates``):
    they are many times faster than the rest, so they are left out, and a run that has had none but such
    epochs has no pace yet (``None``). Epochs that log no updates (on-policy runs) all count.
    """
    ends = [_float(row.get("time/total_timesteps")) or 0.0 for row in rows]
    samples = [end - start for start, end in zip([0.0, *ends], ends)]
    updates = [_float(row.get("train/updates")) for row in rows]
    steady = list(range(len(rows)))
    if any(u is not None for u in updates):
        rates = [(u or 0.0) / n if n > 0 else 0.0 for u, n in zip(updates, samples)]
        if max(rates) <= 0:
            return None
        steady = [i for i, rate in enumerate(rates) if rate >= 0.9 * max(rates)]  # updates come in whole batches
    last = steady[-RECENT_EPOCHS:]
    span, spent = sum(samples[i] for i in last), sum(epoch_seconds(rows[i]) for i in last)
    return spent / span if span > 0 and spent > 0 else None


def run_status(spec: RunSpec, out: str | Path, now: float | None = None) -> RunStatus:
    """The state of ``spec``'s run in directory ``out``."""
    from pamdp.algos.checkpoints import CHECKPOINT, FINAL_MODEL

    out = Path(out)
    steps, seconds, last_return, idle, recent = 0, 0.0, None, None, None
    progress = out / "progress.csv"
    if progress.exists():
        with open(progress, newline="") as f:
            rows = list(csv.DictReader(f))
        seconds = sum(epoch_seconds(row) for row in rows)
        if rows:
            steps = int(_float(rows[-1].get("time/total_timesteps")) or 0)
            last_return = _float(rows[-1].get("charts/episodic_return"))
            recent = recent_pace(rows)
        idle = (time.time() if now is None else now) - progress.stat().st_mtime
    greedy = goal = None
    if is_finished(out, spec):
        state = DONE
        if (out / "evaluation.json").exists():
            result = json.loads((out / "evaluation.json").read_text())
            greedy, goal = _float(result.get("mean_return")), _float(success_of(result)[0])
    elif (out / CHECKPOINT).exists() or (out / FINAL_MODEL).exists() or steps > 0:
        state = PARTIAL
    else:
        state = NOT_STARTED
    return RunStatus(
        spec.label,
        spec.seed,
        str(out),
        state,
        steps,
        spec.total_steps,
        seconds,
        last_return,
        greedy,
        goal,
        idle,
        recent,
    )


def recorded_status(spec: RunSpec, summary: dict) -> RunStatus:
    """The state of ``spec``'s run as its kept ``summary`` (:mod:`pamdp.experiments.summary`) records it: done, with
    the summary's training time (CPU, else wall) and final figures."""
    final = summary.get("final") or {}
    seconds = summary.get("cpu_seconds") if summary.get("cpu_seconds") is not None else summary.get("wall_seconds")
    return RunStatus(
        spec.label,
        spec.seed,
        summary.get("origin") or "",
        RECORDED,
        int(summary.get("samples") or spec.total_steps),
        spec.total_steps,
        float(seconds or 0.0),
        None,  # a summary keeps the greedy evaluations, not the training returns
        _float(final.get("mean_return")),
        _float(final.get("success_rate")),
        None,
    )


def _minutes(seconds: float) -> str:
    return f"{seconds / 60:.0f} min" if seconds < 5940 else f"{seconds / 3600:.1f} h"


def remaining_seconds(statuses: list[RunStatus]) -> tuple[float, dict[str, int]]:
    """Training time still to go over the unfinished runs that have a pace to go by, and per label (setting),
    how many unfinished runs have none.

    A run's time per sample is its own (over its last ``RECENT_EPOCHS`` epochs) if it has trained, else the
    median of its setting's (its label's) runs.
    Another setting's pace is no guide (PATRPO's minutes say nothing of PASVG(0)'s hours), so a setting none of
    whose runs has trained is counted, not guessed.
    """
    by_label: dict[str, list[float]] = {}
    for s in statuses:
        if s.seconds_per_step is not None:
            by_label.setdefault(s.label, []).append(s.seconds_per_step)
    total, unknown = 0.0, {}
    for s in statuses:
        if s.state in (DONE, RECORDED):
            continue
        rate = s.seconds_per_step
        if rate is None and s.label in by_label:
            rate = statistics.median(by_label[s.label])
        if rate is None:
            unknown[s.label] = unknown.get(s.label, 0) + 1
            continue
        total += rate * max(s.total_steps - s.steps, 0)
    return total, unknown


def format_status(name: str, statuses: list[RunStatus], workers: int = 1) -> str:
    """A markdown table of the runs and a summary line with the training time still to go."""
    goal = any(s.success_rate is not None for s in statuses)
    head = "| run | seed | state | samples | trained | last epoch's return | greedy return |" + (
        " success rate |" if goal else ""
    )
    lines = [head, "|---" * (head.count("|") - 1) + "|"]
    for s in statuses:
        share = f"{s.steps:,} / {s.total_steps:,}" if s.state not in (DONE, RECORDED) else f"{s.total_steps:,}"
        state = s.state
        if s.state == PARTIAL and s.idle_seconds is not None:  # a run in training writes every epoch
            state += f" (last epoch {_minutes(s.idle_seconds)} ago)"
        cells = [
            s.label,
            str(s.seed),
            state,
            share,
            _minutes(s.train_seconds) if s.train_seconds else "-",
            f"{s.last_return:.3f}" if s.last_return is not None else "-",
            f"{s.greedy_return:.3f}" if s.greedy_return is not None else "-",
        ]
        if goal:
            cells.append(f"{s.success_rate:.3f}" if s.success_rate is not None else "-")
        lines.append("| " + " | ".join(cells) + " |")
    counts = {k: sum(s.state == k for s in statuses) for k in (DONE, PARTIAL, NOT_STARTED, RECORDED)}
    left, unknown = remaining_seconds(statuses)
    done = counts[DONE] + counts[RECORDED]
    summary = f"{name}: {done} of {len(statuses)} runs done"
    if counts[RECORDED]:
        summary += f" ({counts[RECORDED]} recorded in kept summaries, their directories not here)"
    summary += f", {counts[PARTIAL]} partial, {counts[NOT_STARTED]} not started"
    trained = sum(s.train_seconds for s in statuses)
    if trained > 0:
        summary += f"; {_minutes(trained)} of training so far"
    if done < len(statuses):
        if left > 0:
            workers = max(1, workers)
            summary += (
                f"; about {_minutes(left)} of training to go at the runs' own recent pace"
                f" (~{_minutes(left / workers)} with {workers} side by side)"
            )
        if unknown:
            arms = ", ".join(f"{label} ({n} run{'s' if n > 1 else ''})" for label, n in unknown.items())
            summary += f"; not counted, as none of their runs has trained yet: {arms}"
    return "\n".join(lines) + "\n\n" + summary + "\n"
