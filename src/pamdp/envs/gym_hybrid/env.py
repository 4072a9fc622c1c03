"""gym-hybrid's Moving-v0 and Sliding-v0 (Thomas Hirtz) as scalar Gymnasium envs, from ``shared/specs/gym_hybrid.md``.

An agent in the square field [-1, 1]² must stop inside a target circle of radius 0.1. Every agent step is a
parameterised action ``(a, p)``, and every action ends with the agent moving for ``delta_t`` at its speed:

====  ==========  ===============  ================================================================
 a    name        parameter range  effect
====  ==========  ===============  ================================================================
 0    accelerate  [0, 1]           add ``0.5 p`` to the speed (Sliding: a thrust along the heading)
 1    turn        [-1, 1]          turn the heading by ``(π/2) p``
 2    break       none             slow down by 0.1, or stop below 0.1
====  ==========  ===============  ================================================================

Moving's agent moves along its heading; Sliding's keeps a velocity direction of its own that thrust
changes by vector addition, so turning does not redirect its motion. Each step pays the decrease of the
distance to the target minus 0.001; stopping (speed exactly 0) strictly inside the target ends the episode
with a bonus of 1 (``info["is_success"]``), leaving the field or taking a 201st step ends it with -1. Both
are ``terminated``: the elapsed fraction of the 200 steps is in the observation.

The dynamics are ``dynamics.step`` (compiled), shared with the batched envs of ``batched.py``.
"""

from __future__ import annotations

import math
import numbers

import gymnasium
import numpy as np
from gymnasium import spaces

import pamdp.envs.gym_hybrid.dynamics as dyn
from pamdp.envs.gym_hybrid.render import RENDER_FPS, draw_gym_hybrid
from pamdp.envs.scalar import ScalarEnv, number, split_action

__all__ = ["MovingEnv", "SlidingEnv", "gym_hybrid_action_space", "parse_action", "check_settings"]

ACTION_FORM = "(a, (p_accelerate, p_turn, p_break)) with a in {0, 1, 2}, p_accelerate and p_turn finite"


def gym_hybrid_action_space() -> spaces.Tuple:
    """``Tuple(Discrete(3), Tuple(Box(0, 1, (1,)), Box(-1, 1, (1,)), Box(0,)))``, float32 (§3): break has no
    parameter, hence its zero-size box."""
    boxes = (
        spaces.Box(np.float32(0.0), np.float32(1.0), shape=(1,), dtype=np.float32),
        spaces.Box(np.float32(-1.0), np.float32(1.0), shape=(1,), dtype=np.float32),
        spaces.Box(np.float32(0.0), np.float32(0.0), shape=(0,), dtype=np.float32),
    )
    return spaces.Tuple((spaces.Discrete(3), spaces.Tuple(boxes)))


def check_settings(**settings) -> np.ndarray:
    """The original constructor's settings (``dynamics.SETTING_NAMES``; missing ones take
    ``dynamics.DEFAULTS``) as the settings row of the compiled functions, or ``ValueError`` naming a bad one."""
    row = dyn.DEFAULTS.copy()
    for name, v in settings.items():
        if name not in dyn.SETTING_NAMES:
            raise ValueError(f"unknown setting {name!r}; expected one of {list(dyn.SETTING_NAMES)}")
        if name == "max_step":
            if isinstance(v, bool) or not isinstance(v, numbers.Integral) or v < 1:
                raise ValueError(f"max_step={v!r}; expected a positive integer")
        elif isinstance(v, bool) or not isinstance(v, numbers.Real) or not math.isfinite(v):
            raise ValueError(f"{name}={v!r}; expected a finite number")
        elif name != "penalty" and v <= 0:
            raise ValueError(f"{name}={v!r}; expected a positive number")
        row[dyn.SETTING_NAMES.index(name)] = float(v)
    return row


class GymHybridEnv(ScalarEnv):
    """What Moving and Sliding share; :class:`MovingEnv` and :class:`SlidingEnv` choose the agent.

    Action: ``(a, (p_accelerate, p_turn, p_break))`` with ``a`` in {0, 1, 2}, ``p_accelerate`` and ``p_turn``
    arrays of shape ``(1,)`` (a plain number is accepted too) and ``p_break`` of shape ``(0,)``; only the
    chosen action's parameter is read, after clipping into its box. Malformed actions and NaN or infinite
    parameters raise ``ValueError``.

    Observation (float64): agent x, y, speed, cos and sin of its heading, target x, y, the distance to the
    target, 1 within the target (``d <= 0.1``) else 0, and the elapsed fraction ``t / max_step`` (1.005 on
    the last of at most 201 steps). ``info`` is empty but at the end of an episode: ``is_success``, True at
    the goal.

    Random numbers: ``reset`` draws six uniforms from ``self.np_random`` when it is called, in the
    original's order (the target, then the agent); nothing in a step is random. Assigning
    ``numpy.random.RandomState(S)`` to ``np_random`` after a first ``reset()`` replays the original driven
    by that generator.

    ``state`` is a copy of the internal state row (indices in ``dynamics``: the heading ``THETA`` and
    Sliding's velocity direction ``PHI``, which the observation does not show).

    Args:
        render_mode: ``None`` or ``"rgb_array"`` (the field from above, see ``render.draw_gym_hybrid``).
        max_turn, max_acceleration, delta_t, max_step, penalty, break_value: the original constructor's
            settings; the defaults are the original's and every published result's.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": RENDER_FPS}
    sliding = False
    """Which agent: Moving's (False) or Sliding's (True)."""

    def __init__(
        self,
        render_mode: str | None = None,
        max_turn: float = np.pi / 2,
        max_acceleration: float = 0.5,
        delta_t: float = 0.005,
        max_step: int = 200,
        penalty: float = 0.001,
        break_value: float = 0.1,
    ):
        obs_space = spaces.Box(-np.inf, np.inf, shape=(dyn.OBS_SIZE,), dtype=np.float64)
        # Exactly one reset's numbers at a time, so np_random holds no number drawn ahead between resets.
        states = dyn.INITIAL_STATE[None].copy()  # one row: the batched env's layout at N = 1
        super().__init__(render_mode, gym_hybrid_action_space(), obs_space, states, "random", dyn.DRAWS_PER_RESET)
        self.settings = check_settings(
            max_turn=max_turn, max_acceleration=max_acceleration, delta_t=delta_t, max_step=max_step,
            penalty=penalty, break_value=break_value,
        )  # fmt: skip
        self._started = False

    def _observation(self) -> np.ndarray:
        out = np.empty((1, dyn.OBS_SIZE))
        dyn.observe(self._states, 0, self.settings, out)
        return out[0]

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        streams = self._stream(dyn.DRAWS_PER_RESET)
        streams.cursors[0] = dyn.reset(self._states, 0, streams.buffers, streams.cursors[0])
        self._started = True
        return self._observation(), {}

    def step(self, action):
        if not self._started:
            raise gymnasium.error.ResetNeeded("call reset() before step()")
        a, p = parse_action(action)
        reward, terminated, goal = dyn.step(self._states, 0, a, p, self.settings, self.sliding)
        return self._observation(), reward, terminated, False, {"is_success": goal} if terminated else {}

    def _frame(self):
        return draw_gym_hybrid(self._states[0], self.sliding)


class MovingEnv(GymHybridEnv):
    """``pamdp/Moving-v0``: the agent moves along its heading (see :class:`GymHybridEnv`)."""

    sliding = False


class SlidingEnv(GymHybridEnv):
    """``pamdp/Sliding-v0``: the agent keeps sliding along its velocity, which thrust changes by vector
    addition and breaking to a stop re-aligns with the heading (see :class:`GymHybridEnv`)."""

    sliding = True


def parse_action(action) -> tuple[int, float]:
    """Check one gym-hybrid ``action``; return ``(a, p)`` with ``p`` the chosen action's parameter as a
    float64, not yet clipped (0.0 for break)."""
    expected = f"{ACTION_FORM} numbers or shape-(1,) arrays, p_break of shape (0,)"
    a, params = split_action(action, "gym-hybrid", 3, 3, expected)
    values = [number(params[0], 0, expected), number(params[1], 1, expected)]
    if np.shape(params[2]) != (0,):
        raise ValueError(f"invalid break parameter {params[2]!r}; expected {expected}")
    return a, values[a] if a < 2 else 0.0
