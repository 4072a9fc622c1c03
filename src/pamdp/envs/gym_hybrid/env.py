"""gym-hybrid's Moving and Sliding as one pamdp domain: its contract and its envs (the task:
``pamdp.envs.gym_hybrid``). Actions, observations, ``state``, the resets' draws and the original constructor's
settings (defaults: the original's): ``docs/environments.md``, "Moving and Sliding (gym-hybrid)" and "Each
domain's batched actions, ``state`` and ``info``"."""

from __future__ import annotations

import numpy as np
from gymnasium import spaces

import pamdp.envs.gym_hybrid.dynamics as dyn
from pamdp.envs.gym_hybrid.dynamics import check_settings
from pamdp.envs.gym_hybrid.render import RENDER_FPS, draw_gym_hybrid
from pamdp.envs.scalar import env_classes
from pamdp.envs.vector import Domain, column, hybrid_space, split_actions

__all__ = ["GymHybrid", "MovingEnv", "SlidingEnv", "MovingVectorEnv", "SlidingVectorEnv", "check_settings"]

ACTION_FORM = "(a, (p_accelerate, p_turn, p_break)) with a in {0, 1, 2}, p_accelerate and p_turn finite"


def gym_hybrid_action_space() -> spaces.Tuple:
    """``Tuple(Discrete(3), Tuple(Box(0, 1, (1,)), Box(-1, 1, (1,)), Box(0,)))``, float32 (break: no parameter)."""
    return hybrid_space((0.0, 1.0, 1), (-1.0, 1.0, 1), (0.0, 0.0, 0))


class GymHybrid(Domain):
    name = "gym-hybrid"
    render_fps = RENDER_FPS
    state_size, initial_state = dyn.STATE_SIZE, dyn.INITIAL_STATE
    reset_draws = scalar_buffer_size = dyn.DRAWS_PER_RESET
    buffer_size = 64 * dyn.DRAWS_PER_RESET  # 64 resets' numbers: a copy is topped up once every 64 episodes

    def __init__(
        self,
        sliding: bool = False,
        max_turn: float = np.pi / 2,
        max_acceleration: float = 0.5,
        delta_t: float = 0.005,
        max_step: int = 200,
        penalty: float = 0.001,
        break_value: float = 0.1,
    ):
        self.sliding = bool(sliding)
        self.settings = check_settings(
            max_turn=max_turn, max_acceleration=max_acceleration, delta_t=delta_t, max_step=max_step,
            penalty=penalty, break_value=break_value,
        )  # fmt: skip
        self.action_space = gym_hybrid_action_space()
        self.observation_space = spaces.Box(-np.inf, np.inf, shape=(dyn.OBS_SIZE,), dtype=np.float64)

    def parse(self, actions, n):
        """``a`` (n,) and the accelerate and turn parameters (n,), float32 or float64 as given, not yet clipped."""
        expected = f"{ACTION_FORM} arrays of shape ({n}, 1) or ({n},), p_break of shape ({n}, 0); a of shape ({n},)"
        a, params = split_actions(actions, self.name, n, expected, n_params=3)
        columns = [column(params[i], n, i, expected) for i in range(2)]
        columns = [p if p.dtype in (np.float32, np.float64) else p.astype(np.float64) for p in columns]
        if np.shape(params[2]) != (n, 0):
            raise ValueError(f"invalid break parameters of shape {np.shape(params[2])}; expected {expected}")
        bad = dyn.first_bad_action(a, *columns)  # one compiled pass instead of a NumPy pass per check
        if bad >= 0:
            raise ValueError(
                f"copy {bad}: discrete action {int(a[bad])}, parameters {float(columns[0][bad])}, "
                f"{float(columns[1][bad])}; expected {expected}"
            )
        return a, columns[0], columns[1]

    def reset(self, env, mask, options, seeded, obs):
        dyn.reset_copies(env._states, mask, self.settings, env.streams.buffers, env.streams.cursors, obs)
        return {}

    def step(self, env, parsed, resetting, obs, rewards, terminated, truncated):
        (a, p_accelerate, p_turn), streams, goal = parsed, env.streams, np.empty(env.num_envs, dtype=bool)
        dyn.step_copies(
            env._states, a, p_accelerate, p_turn, resetting, self.settings, self.sliding,
            streams.buffers, streams.cursors, obs, rewards, terminated, goal,
        )  # fmt: skip
        return {"is_success": goal, "_is_success": terminated.copy()}

    def frame(self, env, i):
        return draw_gym_hybrid(env._states[i], self.sliding)


MovingEnv, MovingVectorEnv = env_classes(GymHybrid, __name__, "MovingEnv", "MovingVectorEnv")
SlidingEnv, SlidingVectorEnv = env_classes(GymHybrid, __name__, "SlidingEnv", "SlidingVectorEnv", sliding=True)
