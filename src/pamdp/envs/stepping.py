"""How an env's copies are stepped and their episodes counted: Gymnasium's next-step autoreset, the action masks
an env reports, and each episode's return, length and success. Training (the on- and off-policy loops) and the
evaluation step their envs through :class:`VectorStepper`; how the envs are made is :mod:`pamdp.envs.backends`'s."""

from __future__ import annotations

import dataclasses

import gymnasium
import numpy as np

__all__ = ["VectorStepper", "Step", "info_action_masks", "EpisodeTracker", "successes", "success_summary"]


def info_action_masks(infos: dict, num_envs: int, n_actions: int) -> np.ndarray:
    """The discrete actions allowed in each copy's current state, bool ``(num_envs, n_actions)``, from a vector
    env's infos (Gymnasium's dict of arrays: ``infos["action_mask"]`` ``(N, K)`` beside ``infos["_action_mask"]``,
    which copies report one).

    True means the action has an effect now. A copy that reports no mask, or a mask allowing nothing, gets all
    actions allowed; a mask of another shape is a ``ValueError``.
    """
    masks = np.ones((num_envs, n_actions), dtype=bool)
    if "action_mask" not in infos:
        return masks
    reported = np.asarray(infos["action_mask"])
    if reported.shape != (num_envs, n_actions):
        raise ValueError(
            f"info['action_mask'] of shape {reported.shape}; expected ({num_envs}, {n_actions}) (one bool per "
            "env copy and discrete action)"
        )
    has = np.asarray(infos.get("_action_mask", np.ones(num_envs, dtype=bool)), dtype=bool)
    has &= reported.any(axis=1)
    masks[has] = reported[has].astype(bool)
    return masks


@dataclasses.dataclass
class Step:
    """One step of every copy of a vector env, as :meth:`VectorStepper.step` returns it: ``(N, ...)`` arrays.

    ``obs`` and ``masks`` are the copies' states before the step (``masks``: their allowed actions, ``None``
    without action masks), ``next_obs`` and ``next_masks`` after it. ``valid`` is false on the autoreset steps
    (see :class:`VectorStepper`); ``terminated`` and ``done`` (terminated or truncated) are true only where valid.
    ``ended`` lists the copies whose episode ended, ``flatnonzero(done)``, and ``returns``, ``lengths`` and
    ``successes`` those episodes' (a success ``None`` where the env did not report one).
    """

    obs: np.ndarray
    masks: np.ndarray | None
    reward: np.ndarray
    terminated: np.ndarray
    done: np.ndarray
    valid: np.ndarray
    next_obs: np.ndarray
    next_masks: np.ndarray | None
    info: dict
    returns: np.ndarray
    lengths: np.ndarray
    successes: list[bool | None]

    @property
    def ended(self) -> np.ndarray:
        return np.flatnonzero(self.done)


class VectorStepper:
    """Steps a vector env with Gymnasium's next-step autoreset, keeping the episodes' accounts.

    Such an env resets a finished copy on the *next* step and ignores that step's action: the step is marked
    invalid (no sample, no reward counted). The stepper holds each copy's current observation and allowed actions
    (``masked``: from ``info["action_mask"]``, :func:`info_action_masks`); its :attr:`episodes` keep the running
    and finished episodes' returns and lengths. Training (the on- and off-policy loops) and evaluation step their
    envs through it.
    """

    def __init__(self, env: gymnasium.vector.VectorEnv, n_actions: int, masked: bool, seed: int):
        self.env, self.n_actions, self.masked = env, n_actions, masked
        self.obs, info = env.reset(seed=seed)
        self.masks = self._masks(info)
        self.prev_done = np.zeros(env.num_envs, dtype=bool)
        self.episodes = EpisodeTracker(env.num_envs)

    def _masks(self, info: dict) -> np.ndarray | None:
        return info_action_masks(info, self.env.num_envs, self.n_actions) if self.masked else None

    def step(self, action) -> Step:
        """Step every copy with the env's ``action`` and move on to the new observations."""
        obs, masks = self.obs, self.masks
        next_obs, reward, terminated, truncated, info = self.env.step(action)
        valid = ~self.prev_done
        done = (terminated | truncated) & valid
        ended = self.episodes.step(np.asarray(reward, dtype=np.float64), done, valid, info)
        self.obs, self.masks, self.prev_done = next_obs, self._masks(info), done
        return Step(obs, masks, reward, terminated & valid, done, valid, next_obs, self.masks, info, *ended)


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
    ``charts/success_rate`` and ``charts/steps_to_success`` (runs recorded before: :data:`~pamdp.logger.RENAMED`).
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
