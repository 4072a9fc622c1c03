"""What a run records: one CSV row and TensorBoard scalars per epoch (the episodes' figures among them come from
:class:`~pamdp.envs.stepping.EpisodeTracker`), and how the figures of runs recorded under older names are read."""

from __future__ import annotations

import csv
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

__all__ = ["Logger", "RENAMED", "SUCCESS_KEYS", "success_of"]

RENAMED = {
    "charts/success_rate": "charts/goal_rate",
    "charts/steps_to_success": "charts/steps_to_goal",
    "eval/success_rate": "eval/goal_rate",
}
"""Logged names -> the names runs recorded before success had its general name (soccer's runs on disk)."""

SUCCESS_KEYS = (("success_rate", "mean_steps_to_success"), ("goal_rate", "mean_steps_to_goal"))
"""An evaluation's success keys, then the ones ``evaluation.json`` files written before held."""


def success_of(result: dict) -> tuple[float | None, float | None]:
    """``(success rate, mean steps to success)`` of an evaluation, by its keys or their old names (``None``
    where it has none)."""
    for rate, steps in SUCCESS_KEYS:
        if rate in result:
            return result[rate], result.get(steps)
    return None, None


class Logger:
    """One CSV row and a set of TensorBoard scalars per epoch, in ``run_dir/progress.csv`` and ``run_dir/tb``, and
    the same figures to every function of :attr:`sinks` (an experiment tracker's, such as
    :class:`~pamdp.callbacks.WandbCallback`): the one place a run's figures fan out from.

    On resume (``resume_step > 0``) rows logged after the checkpoint being resumed are dropped, so that a
    killed and restarted run leaves one clean log. Without ``run_dir`` only the sinks get the figures.
    """

    def __init__(self, run_dir: str | os.PathLike | None = None, resume_step: int = 0):
        self.sinks: list[Callable[[dict[str, float], int], None]] = []
        """Functions of ``(figures, step)`` that get what :meth:`record` records."""
        self.run_dir = None if run_dir is None else Path(run_dir)
        self.rows: list[dict[str, Any]] = []
        self._last_step: int | None = None
        self.writer = None
        if self.run_dir is None:
            return
        from torch.utils.tensorboard import SummaryWriter

        self.run_dir.mkdir(parents=True, exist_ok=True)
        self.csv_path = self.run_dir / "progress.csv"
        if self.csv_path.exists():
            with open(self.csv_path, newline="") as f:
                self.rows = [r for r in csv.DictReader(f) if float(r["time/total_timesteps"]) <= resume_step]
        if resume_step == 0:
            self.rows = []
        # TensorBoard drops the events at steps >= purge_step: those after the checkpoint, not its own epoch's
        self.writer = SummaryWriter(str(self.run_dir / "tb"), purge_step=resume_step + 1 if resume_step else None)

    def record(self, stats: dict[str, float], step: int) -> None:
        """Log ``stats`` at ``step``; a second call at the step just recorded adds to that step's row (a callback's
        figures of the epoch, such as :class:`~pamdp.callbacks.EvalCallback`'s)."""
        same_step, self._last_step = step == self._last_step, step
        if self.writer is not None:
            for key, value in stats.items():
                self.writer.add_scalar(key, value, step)
            self.writer.flush()
            if same_step:
                self.rows[-1] = {**self.rows[-1], **stats}
            else:
                self.rows.append(stats)
            columns: list[str] = []
            for row in self.rows:
                columns += [k for k in row if k not in columns]
            tmp = self.csv_path.with_suffix(".csv.tmp")
            with open(tmp, "w", newline="") as f:
                writer = csv.DictWriter(f, fieldnames=columns)
                writer.writeheader()
                writer.writerows(self.rows)
            os.replace(tmp, self.csv_path)
        for sink in self.sinks:
            sink(stats, step)

    def close(self) -> None:
        if self.writer is not None:
            self.writer.close()
