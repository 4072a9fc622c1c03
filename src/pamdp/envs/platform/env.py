"""Platform as a pamdp domain: its contract and its two envs (the task: ``pamdp.envs.platform``). Actions,
observations, ``state``, ``info`` and the noise's exact replay: ``docs/environments.md``, "Platform" and "Each
domain's batched actions, ``state`` and ``info``"."""

from __future__ import annotations

import numpy as np
from gymnasium import spaces

import pamdp.envs.platform.physics as physics
from pamdp.envs.platform.render import RENDER_FPS, draw_platform
from pamdp.envs.scalar import env_classes
from pamdp.envs.vector import Domain, column, every_copy, hybrid_space, split_actions

__all__ = ["Platform", "PlatformEnv", "PlatformVectorEnv", "ZeroNoise", "platform_action_space"]


class ZeroNoise:
    """A stand-in for a generator whose standard normals are all zero: the noise-free dynamics (assigned after
    ``reset()`` to ``np_random`` or ``np_randoms``, until a seeded reset)."""

    def standard_normal(self, size=None):
        return 0.0 if size is None else np.zeros(size)


def platform_action_space() -> spaces.Tuple:
    """``Tuple(Discrete(3), Tuple(Box(1), Box(1), Box(1)))`` with boxes [0, 30], [0, 720], [0, 430]."""
    return hybrid_space(*((0.0, hi, 1) for hi in physics.PARAM_MAX))


class Platform(Domain):
    name = "Platform"
    render_fps = RENDER_FPS
    state_size, initial_state = physics.STATE_SIZE, physics.INITIAL_STATE
    draw = "standard_normal"
    step_draws = physics.MAX_DRAWS
    buffer_size = scalar_buffer_size = 2048  # a step takes ~150 normals, at most physics.MAX_DRAWS
    max_episode_steps = 200

    def __init__(self):
        self.action_space = platform_action_space()
        self.observation_space = spaces.Box(0.0, 1.0, shape=(physics.OBS_SIZE,), dtype=np.float64)
        self.trace = np.empty((physics.MAX_SUBSTEPS, physics.TRACE_SIZE))  # the scalar env's sub-steps
        self.substeps = 0

    def state(self, states):
        return {
            "player": states[:, physics.X : physics.VY + 1].copy(),
            "enemies": states[:, physics.E1X :].reshape(-1, 2, 2).copy(),
        }

    def parse(self, actions, n):
        """``a`` (n,) and the chosen parameters ``p`` (n,), float64, clipped into their boxes."""
        expected = (
            f"(a, (p_run, p_hop, p_leap)) with a an int array of shape ({n},) in 0..2 and each p a finite "
            f"array of shape ({n}, 1) or ({n},)"
        )
        a, params = split_actions(actions, self.name, n, expected, 3, 3)
        columns = np.array([column(p, n, i, expected) for i, p in enumerate(params)], dtype=np.float64)
        chosen = np.empty(n)
        j = physics.choose(a, columns, chosen)
        if j >= 0:
            raise ValueError(f"parameter {j} contains {columns[j][~np.isfinite(columns[j])]}; expected {expected}")
        return a.astype(np.int64, copy=False), chosen

    def reset(self, env, mask, options, seeded, obs):
        env._states[mask] = physics.INITIAL_STATE
        self.substeps = 0
        physics.observe(env._states, obs)
        return every_copy(env.num_envs, substeps=np.zeros(env.num_envs, dtype=np.int64))

    def step(self, env, parsed, resetting, obs, rewards, terminated, truncated):
        (a, p), streams, substeps = parsed, env.streams, np.zeros(env.num_envs, dtype=np.int64)
        env._states[resetting] = physics.INITIAL_STATE
        trace = self.trace if env.num_envs == 1 and env.render_mode else self.trace[:0]  # no rows: no record
        physics.step_copies(
            env._states, a, p, ~resetting, streams.buffers, streams.cursors, rewards, terminated, substeps, trace
        )
        self.substeps = int(substeps[0])
        physics.observe(env._states, obs)
        return every_copy(env.num_envs, substeps=substeps)

    def frame(self, env, i):
        s = env._states[i]
        return draw_platform(s[physics.X], s[physics.Y], s[physics.E1X], s[physics.E2X])

    def substep_frames(self, env):
        return [draw_platform(*row) for row in self.trace[: self.substeps]]


PlatformEnv, PlatformVectorEnv = env_classes(Platform, __name__, "PlatformEnv", "PlatformVectorEnv")
