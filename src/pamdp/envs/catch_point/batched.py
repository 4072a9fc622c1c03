"""N copies of Catch Point stepped at once: ``gymnasium.make_vec("pamdp/CatchPoint-v0", num_envs=N)``.

The copies run ``particle.catch_point_step``, the scalar env's dynamics, in one compiled loop
(``particle.catch_point_copies``); each copy draws its resets from its own generator
(``pamdp.envs.vector``), so copy i follows a scalar env reset with copy i's seed step for step.
"""

from __future__ import annotations

import functools

import numpy as np

import pamdp.envs.particle as particle
from pamdp.envs.catch_point.env import CatchPointEnv
from pamdp.envs.catch_point.render import draw_catch_point
from pamdp.envs.vector import BatchedVectorEnv, column, split_actions

__all__ = ["CatchPointVectorEnv", "action_arrays"]

RESETS_BUFFERED = 256
"""Episodes' worth of uniforms drawn at a time per copy."""


class CatchPointVectorEnv(BatchedVectorEnv):
    """``num_envs`` independent Catch Point episodes, stepped together.

    Actions are batched like ``batch_space`` of the scalar action space: ``(a, (theta, catch))`` with
    ``a`` an integer array of shape ``(N,)``, ``theta`` of shape ``(N, 1)`` (``(N,)`` is accepted too)
    and ``catch`` of shape ``(N, 0)``; :meth:`pamdp.spaces.HybridActionSpace.to_env_batch` produces this
    format. Observations are ``(N, 4)`` float64; ``info["failed_catches"]`` and ``info["is_success"]``
    (this step caught the point) are ``(N,)`` arrays, the latter reported (``info["_is_success"]``) by
    the copies that stepped rather than reset.

    Episodes auto-reset in Gymnasium's default *next-step* mode: the step that ends an episode returns its
    last observation with ``terminated`` or ``truncated`` set; the next ``step`` ignores that copy's
    action, resets it, and returns the reset observation with reward 0 and both flags false.

    Copy i draws its resets from its own generator, ``np_randoms[i]``; ``reset(seed=s)`` seeds copy i
    with ``s + i`` (or ``reset(seed=[...])`` with one seed each).

    Args:
        num_envs: number of copies N.
        max_episode_steps: episodes are truncated after this many agent steps (the registration's 25;
            ``make_vec`` passes it in). ``None`` never truncates.
        render_mode: ``None`` or ``"rgb_array"``; :meth:`render` then returns one frame per copy.
    """

    draw = "random"
    draws_per_step = particle.RESET_DRAWS
    buffer_size = particle.RESET_DRAWS * RESETS_BUFFERED

    def __init__(self, num_envs: int = 1, max_episode_steps: int | None = 25, render_mode: str | None = None):
        super().__init__(num_envs, CatchPointEnv(), max_episode_steps, render_mode)
        self._states = np.zeros((self.num_envs, particle.STATE_SIZE))
        self._last_actions = np.full(self.num_envs, -1, dtype=np.int64)

    @property
    def states(self) -> np.ndarray:
        """A copy of the copies' state rows ``(N, STATE_SIZE)`` (indices in ``pamdp.envs.particle``)."""
        return self._states.copy()

    def _frames(self) -> tuple:
        return tuple(draw_catch_point(s, a) for s, a in zip(self._states, self._last_actions))

    # -- the shell's hooks ------------------------------------------------------------------------
    def _reset_copies(self, mask, options):
        particle.reset_copies(self._states, mask, self.streams.buffers, self.streams.cursors)
        self._last_actions[mask] = -1
        obs = np.empty((self.num_envs, particle.OBS_SIZE))
        particle.observe(self._states, obs)
        return obs, self._info()

    def _step_copies(self, actions, resetting):
        n, streams = self.num_envs, self.streams
        a, theta = action_arrays(actions, n)
        obs, rewards = np.empty((n, particle.OBS_SIZE)), np.zeros(n)
        terminated, caught = np.zeros(n, dtype=bool), np.zeros(n, dtype=bool)
        bad = particle.catch_point_copies(
            self._states, a, theta, resetting, streams.buffers, streams.cursors, obs, rewards, terminated, caught
        )
        if bad >= 0:
            raise ValueError(f"copy {bad}: action {a[bad]} with angle {theta[bad]}; expected {expected_actions(n)}")
        if self.render_mode is not None:
            self._last_actions[:] = np.where(resetting, -1, a)
        return obs, rewards, terminated, np.zeros(n, dtype=bool), self._info(caught, ~resetting)

    def _info(self, caught: np.ndarray | None = None, stepped: np.ndarray | None = None) -> dict:
        """As Gymnasium's vector envs merge the scalar envs' infos: every copy reports its failed catches,
        the copies that stepped (rather than reset) whether they caught the point."""
        fails = self._states[:, particle.FAILS].astype(np.int64)
        info = {"failed_catches": fails, "_failed_catches": np.ones(self.num_envs, dtype=bool)}
        if caught is not None:
            info["is_success"], info["_is_success"] = caught, stepped
        return info


@functools.cache  # the check of every batch needs it
def expected_actions(n: int) -> str:
    return (
        f"(a, (theta, catch)) with a an int array of shape ({n},) in {{0, 1}}, theta a finite array of "
        f"shape ({n}, 1) or ({n},) and catch an array of shape ({n}, 0) (or ({n}, 1), ignored)"
    )


def action_arrays(actions, n: int) -> tuple[np.ndarray, np.ndarray]:
    """A batch of ``n`` Catch Point actions as ``a`` (n,) int64 and ``theta`` (n,) float64, its structure,
    shapes and dtypes checked (``ValueError``); the compiled step checks the values."""
    expected = expected_actions(n)
    a, params = split_actions(actions, "Catch Point", n, expected, n_params=2)
    theta, catch = column(params[0], n, "angles", expected), np.shape(params[1])
    if catch not in ((n, 0), (n, 1)):
        raise ValueError(f"invalid catch parameters of shape {catch}; expected {expected}")
    return a.astype(np.int64, copy=False), theta.astype(np.float64, copy=False)
