"""Hard Move (HyAR, Li et al. ICLR 2022) as a scalar Gymnasium env, from ``shared/specs/hard_move.md``.

An agent on a plane has ``n`` evenly spaced actuators; discrete action ``a`` (one of ``2 ** n``) switches
on the actuators of its bits (the most significant bit is actuator 0) and its one parameter ``p`` scales
the resulting push. The agent must come within 0.2 of a target point. The reward is minus the squared
distance to the target, ``20 - d2`` on arrival, which ends the episode (``terminated``); the registration's
30-step limit is ``truncated``. The dynamics are ``pamdp.envs.particle``'s (compiled), shared with the
batched env ``batched.HardMoveVectorEnv``.
"""

from __future__ import annotations

import numpy as np
from gymnasium import spaces

import pamdp.envs.particle as particle
from pamdp.envs.hard_move.motions import check_size, motion_table
from pamdp.envs.hard_move.render import draw_hard_move
from pamdp.envs.scalar import ScalarEnv, number, split_action

__all__ = ["HardMoveEnv", "hard_move_action_space", "parse_action"]


def hard_move_action_space(n: int) -> spaces.Tuple:
    """``Tuple(Discrete(2 ** n), Tuple(Box(-1, 1, (1,)) x 2 ** n))``, float32 (hard_move.md §2)."""
    box = {"low": np.float32(-1.0), "high": np.float32(1.0), "shape": (1,), "dtype": np.float32}
    k = 2 ** check_size(n)
    return spaces.Tuple((spaces.Discrete(k), spaces.Tuple(tuple(spaces.Box(**box) for _ in range(k)))))


class HardMoveEnv(ScalarEnv):
    """Hard Move with ``n`` actuators as a Gymnasium env (see the module docstring for the task).

    Action: ``(a, (p_0, ..., p_{2^n - 1}))`` with each ``p`` an array of shape ``(1,)`` (or a plain
    number); only ``p_a`` is read and checked (reading all ``2 ** n`` would cost more than the step). It is
    used as given, not clipped: ``|p| > 1`` pushes harder, ``p < 0`` backwards. A malformed action, or a
    NaN or infinite ``p_a``, raises ``ValueError``.

    Observation: ``[vx, vy, gx - ax, gy - ay]`` (float64): the agent's velocity, the target relative to
    the agent. ``info["is_success"]`` after a step: whether it reached the target (which ends the episode).

    Random numbers: ``reset`` draws the agent's then the target's position, ``uniform(-1, 1, 2)`` each,
    from ``self.np_random`` (as ``random()`` numbers, four per reset, never drawn ahead); a step draws
    none. Assign ``numpy.random.RandomState(S)`` to ``np_random`` and ``reset()`` without a seed to replay
    the original driven by ``np.random.seed(S)``; ``state`` is a copy of the internal state row (indices
    in ``pamdp.envs.particle``), ``motions`` the table of :func:`motion_table`.

    Args:
        n: number of actuators, 4, 6, 8 or 10.
        render_mode: ``None`` or ``"rgb_array"`` (the plane from above, see ``render.draw_hard_move``).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": particle.RENDER_FPS}
    observe = staticmethod(particle.observe)
    obs_size = particle.OBS_SIZE

    def __init__(self, n: int = 4, render_mode: str | None = None):
        self.n = check_size(n)
        obs_space = spaces.Box(-np.inf, np.inf, shape=(particle.OBS_SIZE,), dtype=np.float64)
        states = np.zeros((1, particle.STATE_SIZE))  # one row: the batched env's layout at N = 1
        super().__init__(render_mode, hard_move_action_space(self.n), obs_space, states, "random", particle.RESET_DRAWS)
        self.motions = motion_table(self.n)
        self._last_action: tuple[int, float] | None = None

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        streams = self._stream(particle.RESET_DRAWS)
        streams.cursors[0] = particle.reset(self._states[0], streams.buffers[0], streams.cursors[0])
        self._last_action = None
        return self._observation(), {}

    def step(self, action):
        a, p = parse_action(action, len(self.motions))
        mx, my = self.motions[a]
        reward, terminated = particle.hard_move_step(self._states[0], mx, my, p)
        self._last_action = (a, p)
        return self._observation(), reward, terminated, False, {"is_success": terminated}

    def _frame(self):
        return draw_hard_move(self._states[0], self.n, *(self._last_action or (None, 0.0)))


def parse_action(action, n_actions: int) -> tuple[int, float]:
    """Check one Hard Move ``action`` with ``n_actions`` discrete actions; return ``(a, p_a)``, ``p_a`` a
    float64. Only ``p_a`` is checked."""
    expected = (
        f"(a, (p_0, ..., p_{n_actions - 1})) with a in 0..{n_actions - 1} and p_a a finite number or shape-(1,) array"
    )
    a, params = split_action(action, "Hard Move", n_actions, None, expected)
    if not isinstance(params, (tuple, list)) or len(params) != n_actions:
        given = f"{len(params)} boxes" if isinstance(params, (tuple, list)) else f"a {type(params).__name__}"
        raise ValueError(f"invalid parameters ({given}); expected {expected}")
    return a, number(params[a], a, expected, "parameter p_")
