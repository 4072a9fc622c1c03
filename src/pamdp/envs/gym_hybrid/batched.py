"""N copies of Moving or Sliding stepped at once: ``gymnasium.make_vec("pamdp/Moving-v0", num_envs=N)``.

The copies run ``dynamics.step``, the scalar envs' dynamics, in one compiled loop (``dynamics.step_copies``);
each copy draws its resets from its own generator (``pamdp.envs.vector``), so copy i follows a scalar env
reset with copy i's seed step for step, across autoresets.
"""

from __future__ import annotations

import gymnasium
import numpy as np

import pamdp.envs.gym_hybrid.dynamics as dyn
from pamdp.envs.gym_hybrid.env import ACTION_FORM, MovingEnv, SlidingEnv
from pamdp.envs.gym_hybrid.render import draw_gym_hybrid
from pamdp.envs.vector import BatchedVectorEnv, column, split_actions

__all__ = ["MovingVectorEnv", "SlidingVectorEnv", "parse_actions"]


class GymHybridVectorEnv(BatchedVectorEnv):
    """``num_envs`` independent episodes of Moving or Sliding (:attr:`single_env_class`), stepped together.

    Actions are batched like ``batch_space`` of the scalar action space: ``(a, (p_accelerate, p_turn,
    p_break))`` with ``a`` an integer array of shape ``(N,)``, ``p_accelerate`` and ``p_turn`` of shape
    ``(N, 1)`` (``(N,)`` is accepted too) and ``p_break`` of shape ``(N, 0)``. Observations are ``(N, 10)``
    float64; ``info["is_success"]`` says which of the copies whose episode ended (``info["_is_success"]``)
    reached the goal.

    Episodes auto-reset in Gymnasium's default *next-step* mode: the step that ends an episode returns its
    last observation with ``terminated`` set; the next ``step`` ignores that copy's action, resets it, and
    returns the reset observation with reward 0 and both flags false.

    Random numbers: copy i's resets draw from its own generator, ``np_randoms[i]``; ``reset(seed=s)`` seeds
    copy i with ``s + i`` (or ``reset(seed=[...])`` with one seed each).

    Args:
        num_envs: number of copies N.
        max_episode_steps: episodes are truncated after this many agent steps; ``None`` (the registration's
            choice) leaves the end to the domain's own step limit.
        render_mode: ``None`` or ``"rgb_array"``; :meth:`render` then returns one frame per copy.
        **settings: the scalar env's settings (``max_turn``, ``max_acceleration``, ``delta_t``,
            ``max_step``, ``penalty``, ``break_value``).
    """

    single_env_class = MovingEnv
    draw = "random"
    draws_per_step = dyn.DRAWS_PER_RESET
    buffer_size = 64 * dyn.DRAWS_PER_RESET
    """The numbers of 64 resets per copy: a copy's buffer is topped up once every 64 episodes."""

    def __init__(
        self, num_envs: int = 1, max_episode_steps: int | None = None, render_mode: str | None = None, **settings
    ):
        single = self.single_env_class(**settings)
        super().__init__(num_envs, single, max_episode_steps, render_mode)
        self.settings = single.settings
        self.sliding = single.sliding
        self._states = np.tile(dyn.INITIAL_STATE, (self.num_envs, 1))
        self._started = False

    @property
    def states(self) -> np.ndarray:
        """A copy of the copies' state rows, ``(N, dynamics.STATE_SIZE)``."""
        return self._states.copy()

    def _frames(self) -> tuple:
        return tuple(draw_gym_hybrid(s, self.sliding) for s in self._states)

    # -- the shell's hooks ------------------------------------------------------------------------
    def _reset_copies(self, mask, options):
        obs = np.empty((self.num_envs, dyn.OBS_SIZE))
        dyn.reset_copies(self._states, mask, self.settings, self.streams.buffers, self.streams.cursors, obs)
        self._started = True
        return obs, {}

    def _step_copies(self, actions, resetting):
        if not self._started:
            raise gymnasium.error.ResetNeeded("call reset() before step()")
        a, p_accelerate, p_turn = parse_actions(actions, self.num_envs)
        n = self.num_envs
        obs, rewards = np.empty((n, dyn.OBS_SIZE)), np.empty(n)
        terminated, goal = np.empty(n, dtype=bool), np.empty(n, dtype=bool)
        dyn.step_copies(
            self._states, a, p_accelerate, p_turn, resetting, self.settings, self.sliding,
            self.streams.buffers, self.streams.cursors, obs, rewards, terminated, goal,
        )  # fmt: skip
        infos = {"is_success": goal, "_is_success": terminated.copy()}
        return obs, rewards, terminated, np.zeros(n, dtype=bool), infos


class MovingVectorEnv(GymHybridVectorEnv):
    """N copies of ``pamdp/Moving-v0`` (see :class:`GymHybridVectorEnv`)."""

    single_env_class = MovingEnv


class SlidingVectorEnv(GymHybridVectorEnv):
    """N copies of ``pamdp/Sliding-v0`` (see :class:`GymHybridVectorEnv`)."""

    single_env_class = SlidingEnv


def parse_actions(actions, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Check a batch of ``n`` gym-hybrid actions; return ``a`` (n,) and the accelerate and turn parameters (n,),
    float32 or float64 as given (the compiled step widens them to float64), not yet clipped."""
    expected = f"{ACTION_FORM} arrays of shape ({n}, 1) or ({n},), p_break of shape ({n}, 0); a of shape ({n},)"
    a, params = split_actions(actions, "gym-hybrid", n, expected, n_params=3)
    columns = []
    for i in range(2):
        p = column(params[i], n, i, expected)
        columns.append(p if p.dtype in (np.float32, np.float64) else p.astype(np.float64))
    if np.shape(params[2]) != (n, 0):
        raise ValueError(f"invalid break parameters of shape {np.shape(params[2])}; expected {expected}")
    bad = dyn.first_bad_action(a, *columns)  # one compiled pass instead of a NumPy pass per check
    if bad >= 0:
        raise ValueError(
            f"copy {bad}: discrete action {int(a[bad])}, parameters {float(columns[0][bad])}, "
            f"{float(columns[1][bad])}; expected {expected}"
        )
    return a, columns[0], columns[1]
