"""N copies of Platform stepped at once: ``gymnasium.make_vec("pamdp/Platform-v0", num_envs=N)``.

The copies run ``physics.step``, the scalar env's dynamics, in one compiled loop (``physics.step_copies``);
each copy draws from its own generator (``pamdp.envs.vector``), so copy i follows a scalar env reset with
copy i's seed step for step, noise included.
"""

from __future__ import annotations

import numpy as np

import pamdp.envs.platform.physics as physics
from pamdp.envs.platform.env import BUFFER_SIZE, PlatformEnv
from pamdp.envs.platform.render import draw_platform
from pamdp.envs.vector import BatchedVectorEnv, column, split_actions

__all__ = ["PlatformVectorEnv", "parse_actions"]

PARAM_HIGH = np.array(physics.PARAM_MAX)


class PlatformVectorEnv(BatchedVectorEnv):
    """``num_envs`` independent Platform episodes, stepped together.

    Actions are batched like ``batch_space`` of the scalar action space: ``(a, (p_run, p_hop, p_leap))``
    with ``a`` an integer array of shape ``(N,)`` and each ``p`` of shape ``(N, 1)`` (``(N,)`` is
    accepted too); :meth:`pamdp.spaces.HybridActionSpace.to_env_batch` produces this format. Observations
    are ``(N, 9)`` float64; ``info["substeps"]`` is an ``(N,)`` int array (0 for a copy that was reset).

    Episodes auto-reset in Gymnasium's default *next-step* mode: the step that ends an episode returns its
    last observation with ``terminated`` or ``truncated`` set; the next ``step`` ignores that copy's action,
    resets it, and returns the reset observation with reward 0 and both flags false.

    Noise: copy i draws from its own generator, ``np_randoms[i]``; ``reset(seed=s)`` seeds copy i with
    ``s + i`` (or ``reset(seed=[...])`` with one seed each). Assign ``venv.np_randoms = [ZeroNoise()] * N``
    after ``reset()`` for the noise-free dynamics.

    Args:
        num_envs: number of copies N.
        max_episode_steps: episodes are truncated after this many agent steps (the registration's 200;
            ``make_vec`` passes it in). ``None`` never truncates.
        render_mode: ``None`` or ``"rgb_array"``; :meth:`render` then returns one frame per copy.
    """

    draw = "standard_normal"
    draws_per_step = physics.MAX_DRAWS
    buffer_size = BUFFER_SIZE

    def __init__(self, num_envs: int = 1, max_episode_steps: int | None = 200, render_mode: str | None = None):
        super().__init__(num_envs, PlatformEnv(), max_episode_steps, render_mode)
        self._states = np.tile(physics.INITIAL_STATE, (self.num_envs, 1))

    @property
    def state(self) -> dict[str, np.ndarray]:
        """A copy of the state, batched like the scalar env's: ``player`` (N, 4), ``enemies`` (N, 2, 2)."""
        s = self._states
        return {
            "player": s[:, physics.X : physics.VY + 1].copy(),
            "enemies": s[:, physics.E1X :].reshape(-1, 2, 2).copy(),
        }

    def _frames(self) -> tuple:
        X, Y, E1X, E2X = physics.X, physics.Y, physics.E1X, physics.E2X
        return tuple(draw_platform(s[X], s[Y], s[E1X], s[E2X]) for s in self._states)

    # -- the shell's hooks ------------------------------------------------------------------------
    def _reset_copies(self, mask, options):
        self._states[mask] = physics.INITIAL_STATE
        return self._observations(), _info(np.zeros(self.num_envs, dtype=np.int64))

    def _step_copies(self, actions, resetting):
        a, p = parse_actions(actions, self.num_envs)
        self._states[resetting] = physics.INITIAL_STATE
        n = self.num_envs
        rewards, terminated, substeps = np.zeros(n), np.zeros(n, dtype=bool), np.zeros(n, dtype=np.int64)
        streams = self.streams
        physics.step_copies(
            self._states, a, p, ~resetting, streams.buffers, streams.cursors, rewards, terminated, substeps
        )
        return self._observations(), rewards, terminated, np.zeros(n, dtype=bool), _info(substeps)

    def _observations(self) -> np.ndarray:
        out = np.empty((self.num_envs, physics.OBS_SIZE))
        physics.observe(self._states, out)
        return out


def _info(substeps: np.ndarray) -> dict:
    # Every copy reports its sub-steps (0 after a reset), hence an all-true "_substeps" mask.
    return {"substeps": substeps, "_substeps": np.ones(substeps.shape, dtype=bool)}


def parse_actions(actions, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Check a batch of ``n`` Platform actions; return ``a`` (n,) and the chosen parameters ``p`` (n,),
    float64, clipped into their boxes."""
    expected = (
        f"(a, (p_run, p_hop, p_leap)) with a an int array of shape ({n},) in 0..2 and each p a finite "
        f"array of shape ({n}, 1) or ({n},)"
    )
    a, params = split_actions(actions, "Platform", n, expected, 3, 3)
    columns = []
    for i, p in enumerate(params):
        p = column(p, n, i, expected).astype(np.float64)
        if not np.isfinite(p).all():
            raise ValueError(f"parameter {i} contains {p[~np.isfinite(p)]}; expected {expected}")
        columns.append(p)
    chosen = np.stack(columns)[a, np.arange(n)]
    return a.astype(np.int64), np.clip(chosen, 0.0, PARAM_HIGH[a])
