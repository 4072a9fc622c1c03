"""What a run records: episode statistics while training, one CSV row and TensorBoard scalars per epoch."""

from __future__ import annotations

import csv
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["EpisodeTracker", "Logger", "successes", "success_summary", "RENAMED", "SUCCESS_KEYS", "success_of"]

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


def successes(info: dict | None, ended: np.ndarray) -> list[bool | None]:
    """``info["is_success"]`` of the copies where ``ended``, from a vector env's step: ``None`` for a copy
    that did not report it (Gymnasium's mask ``info["_is_success"]`` false, or no such key at all)."""
    if info is None or "is_success" not in info:
        return [None] * int(np.sum(ended))
    success = np.asarray(info["is_success"], dtype=bool)
    reported = np.asarray(info.get("_is_success", np.ones(len(success), dtype=bool)), dtype=bool)
    return [bool(s) if r else None for s, r in zip(success[ended], reported[ended])]


def success_summary(lengths: list[int], succeeded: list[bool | None]) -> tuple[float, float | None] | None:
    """``(success rate, mean length of the successful episodes)`` over the episodes that reported success
    (``None`` for the length when none succeeded); ``None`` when no episode reported it."""
    known = [(n, s) for n, s in zip(lengths, succeeded) if s is not None]
    if not known:
        return None
    steps = [n for n, s in known if s]
    return float(np.mean([s for _, s in known])), (float(np.mean(steps)) if steps else None)


class EpisodeTracker:
    """Running return and length per env copy; completed episodes are kept until :meth:`pop`.

    Where the env says whether an episode succeeded (``info["is_success"]`` at its end, the Gymnasium and SB3
    convention; a goal on Half Field Offense), the success rate and the mean length of the successful episodes
    are kept too, over the episodes whose end reported it: the training counterparts of
    :func:`pamdp.evaluation.evaluate`'s ``success_rate`` and ``mean_steps_to_success``, logged as
    ``charts/success_rate`` and ``charts/steps_to_success`` (runs recorded before: :data:`RENAMED`).
    """

    def __init__(self, num_envs: int):
        self.returns = np.zeros(num_envs)
        self.lengths = np.zeros(num_envs, dtype=np.int64)
        self.done_returns: list[float] = []
        self.done_lengths: list[int] = []
        self.done_goals: list[bool | None] = []  # per ended episode; None where the env reported no success

    def reset(self) -> None:
        self.returns[:] = 0.0
        self.lengths[:] = 0

    def step(
        self, rewards: np.ndarray, dones: np.ndarray, valid: np.ndarray, info: dict | None = None
    ) -> tuple[np.ndarray, np.ndarray, list[bool | None]]:
        """Add one vector step; ``valid`` is false for the autoreset steps of Gymnasium's vector envs. Returns the
        return, length and success of each episode that ended, in the order of the copies."""
        self.returns += np.where(valid, rewards, 0.0)
        self.lengths += valid
        ended = dones & valid
        returns, lengths = self.returns[ended], self.lengths[ended]
        goals = successes(info, ended) if ended.any() else []
        self.done_returns += returns.tolist()
        self.done_lengths += lengths.tolist()
        self.done_goals += goals
        self.returns[ended] = 0.0
        self.lengths[ended] = 0
        return returns, lengths, goals

    def pop(self) -> dict[str, float]:
        """Statistics of the episodes completed since the last call (empty if none)."""
        if not self.done_returns:
            return {}
        stats = {
            "charts/episodic_return": float(np.mean(self.done_returns)),
            "charts/episodic_length": float(np.mean(self.done_lengths)),
            "charts/episodes": float(len(self.done_returns)),
        }
        summary = success_summary(self.done_lengths, self.done_goals)
        if summary is not None:
            stats["charts/success_rate"] = summary[0]
            if summary[1] is not None:
                stats["charts/steps_to_success"] = summary[1]
        self.done_returns, self.done_lengths, self.done_goals = [], [], []
        return stats


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
