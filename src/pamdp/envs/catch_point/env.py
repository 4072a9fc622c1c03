"""Catch Point (HyAR, Li et al. ICLR 2022) as a scalar Gymnasium env, from ``shared/specs/catch_point.md``.

An agent on a plane either pushes itself in a chosen direction or tries to catch a target point; a catch
succeeds within 0.2 of the target, and 11 failed catches are allowed per episode:

====  =====  ========================  ==================================================
 a    name   parameter                 effect
====  =====  ========================  ==================================================
 0    move   angle θ in [-π, π]        push with force 2 in direction (sin θ, cos θ)
 1    catch  none (an empty box)       no push; catch if within 0.2 after this step
====  =====  ========================  ==================================================

The reward is minus the squared distance to the target, ``20 - d2`` for a catch, 0 once the budget of
failed catches is spent. An episode ends (``terminated``) on a catch or on the step after the 11th failed
catch; the registration's 25-step limit is ``truncated``. The dynamics are ``pamdp.envs.particle``'s
(compiled), shared with the batched env ``batched.CatchPointVectorEnv``.
"""

from __future__ import annotations

import math

import numpy as np
from gymnasium import spaces

import pamdp.envs.particle as particle
from pamdp.envs.catch_point.render import draw_catch_point
from pamdp.envs.scalar import ScalarEnv, split_action

__all__ = ["CatchPointEnv", "catch_point_action_space", "parse_action", "THETA_MAX"]

THETA_MAX = float(np.float32(np.pi))
"""The angle box is [-π, π] in float32, 3.1415927410125732 (HyAR's glue sends float32(p) * float32(π))."""
EXPECTED = (
    "(a, (theta, catch)) with a in {0 (move), 1 (catch)}, theta a finite number or shape-(1,) array "
    "(radians) and catch an empty array (shape (0,); a shape-(1,) one is accepted and ignored)"
)


def catch_point_action_space() -> spaces.Tuple:
    """``Tuple(Discrete(2), Tuple(Box(-π, π, (1,)), Box(0,)))``, float32 (catch_point.md §3)."""
    theta = spaces.Box(np.float32(-THETA_MAX), np.float32(THETA_MAX), shape=(1,), dtype=np.float32)
    catch = spaces.Box(-1.0, 1.0, shape=(0,), dtype=np.float32)
    return spaces.Tuple((spaces.Discrete(2), spaces.Tuple((theta, catch))))


def observation_space() -> spaces.Box:
    """``Box(-inf, inf, (4,), float64)``: the agent's velocity and the target's position relative to it."""
    return spaces.Box(-np.inf, np.inf, shape=(particle.OBS_SIZE,), dtype=np.float64)


class CatchPointEnv(ScalarEnv):
    """Catch Point as a Gymnasium env (see the module docstring for the task).

    Action: ``(a, (theta, catch))``: ``theta`` an array of shape ``(1,)`` (or a plain number), used as
    given (neither clipped nor wrapped: sine and cosine are periodic); ``catch`` an array of shape
    ``(0,)``. A malformed action, or a NaN or infinite ``theta``, raises ``ValueError``.

    Observation: ``[vx, vy, gx - ax, gy - ay]`` (float64): the agent's velocity, the target relative to
    the agent. Neither the remaining budget nor the time is in it.

    ``info``: ``failed_catches`` (so far this episode) and, after a step, ``is_success``: whether this step
    caught the point, so at an episode's end it says whether the episode succeeded.

    Random numbers: ``reset`` draws the agent's then the target's position, ``uniform(-1, 1, 2)`` each,
    from ``self.np_random`` (as ``random()`` numbers, four per reset, never drawn ahead); a step draws
    none. Assign ``numpy.random.RandomState(S)`` to ``np_random`` and ``reset()`` without a seed to replay
    the original driven by ``np.random.seed(S)``; ``state`` is a copy of the internal state row (indices
    in ``pamdp.envs.particle``).

    Args:
        render_mode: ``None`` or ``"rgb_array"`` (the plane from above, see ``render.draw_catch_point``).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": particle.RENDER_FPS}
    observe = staticmethod(particle.observe)
    obs_size = particle.OBS_SIZE

    def __init__(self, render_mode: str | None = None):
        states = np.zeros((1, particle.STATE_SIZE))  # one row: the batched env's layout at N = 1
        super().__init__(
            render_mode, catch_point_action_space(), observation_space(), states, "random", particle.RESET_DRAWS
        )
        self._last_action: int | None = None

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        streams = self._stream(particle.RESET_DRAWS)
        streams.cursors[0] = particle.reset(self._states[0], streams.buffers[0], streams.cursors[0])
        self._last_action = None
        return self._observation(), {"failed_catches": 0}

    def step(self, action):
        a, theta = parse_action(action)
        reward, terminated, caught = particle.catch_point_step(self._states[0], a, theta)
        self._last_action = a
        info = {"failed_catches": int(self._states[0, particle.FAILS]), "is_success": caught}
        return self._observation(), reward, terminated, False, info

    def _frame(self):
        return draw_catch_point(self._states[0], self._last_action)


def parse_action(action) -> tuple[int, float]:
    """Check one Catch Point ``action``; return ``(a, theta)`` with ``theta`` a float64."""
    a, params = split_action(action, "Catch Point", 2, 2, EXPECTED)
    theta, catch = np.asarray(params[0]), np.asarray(params[1])
    if theta.shape not in ((), (1,)) or theta.dtype.kind not in "iuf":
        raise ValueError(f"invalid angle {params[0]!r}; expected {EXPECTED}")
    if catch.shape not in ((0,), (1,)):
        raise ValueError(f"invalid catch parameter {params[1]!r}; expected {EXPECTED}")
    value = float(theta.reshape(()))
    if not math.isfinite(value):
        raise ValueError(f"the angle is {value}; expected {EXPECTED}")
    return a, value
