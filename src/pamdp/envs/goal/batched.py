"""N copies of Goal or Hard Goal stepped at once: ``gymnasium.make_vec("pamdp/Goal-v0", num_envs=N)``.

The copies run ``dynamics.step``, the scalar env's dynamics, in one compiled loop (``dynamics.step_copies``);
each copy draws from its own generator (``pamdp.envs.vector``), so copy i follows a scalar env reset with
copy i's seed step for step, noise included. A shot can take more numbers than a copy keeps drawn ahead:
the loop then stops that copy's step, its numbers are topped up, and the loop resumes the copies still
pending.
"""

from __future__ import annotations

import numpy as np

import pamdp.envs.goal.dynamics as dyn
from pamdp.envs.goal.env import BUFFER_SIZE, GoalEnv, HardGoalEnv, _state_dict
from pamdp.envs.goal.render import draw_goal
from pamdp.envs.vector import BatchedVectorEnv

__all__ = ["GoalVectorEnv", "HardGoalVectorEnv"]

_DRAWN = (dyn.PX, dyn.PY, dyn.PHI, dyn.KX, dyn.KY, dyn.PSI, dyn.BX, dyn.BY)


class GoalVectorEnv(BatchedVectorEnv):
    """``num_envs`` independent Goal episodes, stepped together.

    Actions are batched like ``batch_space`` of the scalar action space: ``(a, (p_0, p_1, ...))`` with
    ``a`` an integer array of shape ``(N,)``, ``p_0`` of shape ``(N, 2)`` and the others ``(N, 1)`` (``(N,)``
    is accepted too); :meth:`pamdp.spaces.HybridActionSpace.to_env_batch` produces this format.
    Observations are ``(N, 17)`` float64; ``info["substeps"]`` is an ``(N,)`` int array (0 for a copy that
    was reset), ``info["is_success"]`` (a goal) is set for the copies whose episode ended
    (``info["_is_success"]``).

    Episodes auto-reset in Gymnasium's default *next-step* mode: the step that ends an episode returns its
    last observation with ``terminated`` or ``truncated`` set; the next ``step`` ignores that copy's action,
    resets it, and returns the reset observation with reward 0 and both flags false.

    Noise: copy i draws from its own generator, ``np_randoms[i]``; ``reset(seed=s)`` seeds copy i with
    ``s + i`` (or ``reset(seed=[...])`` with one seed each).

    Args:
        num_envs: number of copies N.
        max_episode_steps: episodes are truncated after this many agent steps besides the domain's own
            limit (the registration sets none). ``None`` leaves it to the domain.
        render_mode: ``None`` or ``"rgb_array"``; :meth:`render` then returns one frame per copy.
    """

    draw = "random"
    draws_per_step = dyn.SUBSTEP_DRAWS
    """A copy's step needs at least one sub-step's numbers; it is resumed after a top-up if it needs more."""
    buffer_size = BUFFER_SIZE
    single_env_class = GoalEnv

    def __init__(self, num_envs: int = 1, max_episode_steps: int | None = None, render_mode: str | None = None):
        self._single = self.single_env_class()
        super().__init__(num_envs, self._single, max_episode_steps, render_mode)
        self._states = np.zeros((self.num_envs, dyn.STATE_SIZE))

    @property
    def state(self) -> dict[str, np.ndarray]:
        """A copy of the state, batched like the scalar env's: ``player`` (N, 5), ``keeper`` (N, 5),
        ``ball`` (N, 4), ``time`` (N,)."""
        return _state_dict(self._states)

    def _frames(self) -> tuple:
        return tuple(draw_goal(*(s[k] for k in _DRAWN)) for s in self._states)

    # -- the shell's hooks ------------------------------------------------------------------------
    def _reset_copies(self, mask, options):
        dyn.reset_copies(self._states, mask, self.streams.buffers, self.streams.cursors)
        return self._observations(), _info(np.zeros(self.num_envs, dtype=np.int64))

    def _step_copies(self, actions, resetting):
        n = self.num_envs
        kick, tx, ty = self._single.targets(*self._single.check_actions(actions, n))
        streams = self.streams
        dyn.reset_copies(self._states, resetting, streams.buffers, streams.cursors)
        rewards, substeps = np.zeros(n), np.zeros(n, dtype=np.int64)
        terminated, truncated = np.zeros(n, dtype=bool), np.zeros(n, dtype=bool)
        pending = ~resetting
        while dyn.step_copies(
            self._states, kick, tx, ty, pending, streams.buffers, streams.cursors, substeps, rewards, terminated,
            truncated,
        ):  # fmt: skip
            streams.refill(dyn.SUBSTEP_DRAWS)
        infos = _info(substeps)
        infos["is_success"] = terminated & (rewards == dyn.GOAL_REWARD)
        infos["_is_success"] = terminated | truncated
        return self._observations(), rewards, terminated, truncated, infos

    def _observations(self) -> np.ndarray:
        out = np.empty((self.num_envs, dyn.OBS_SIZE))
        dyn.observe(self._states, out)
        return out


class HardGoalVectorEnv(GoalVectorEnv):
    """``num_envs`` independent Hard Goal episodes (:class:`pamdp.envs.goal.HardGoalEnv`'s actions), stepped
    together; otherwise exactly :class:`GoalVectorEnv`."""

    single_env_class = HardGoalEnv


def _info(substeps: np.ndarray) -> dict:
    # Every copy reports its sub-steps (0 after a reset), hence an all-true "_substeps" mask.
    return {"substeps": substeps, "_substeps": np.ones(substeps.shape, dtype=bool)}
