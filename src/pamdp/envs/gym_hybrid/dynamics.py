"""gym-hybrid's Moving and Sliding (``thomashirtz/gym-hybrid``), written once and compiled by Numba.

The two domains share everything but the agent's ACCELERATE and BREAK (spec §3), so every function takes
``sliding`` (False: Moving, the agent moves along its heading; True: Sliding, it keeps a velocity direction
of its own). A copy's state is row i of a float64 array of :data:`STATE_SIZE` columns (:data:`X` ...
:data:`T`, and functions of them that a step would otherwise compute twice, :data:`D` ... :data:`SIN_PHI`),
updated in place; the constructor's settings are a row of :data:`N_SETTINGS` numbers (:data:`DEFAULTS`).
:func:`step` advances copy i by one agent step and :func:`reset` starts its episode; :func:`step_copies` and
:func:`reset_copies` loop them over the copies (the scalar env's one copy included).

Random numbers: only a reset draws, six uniforms in the spec's §5 order, read from ``draws`` (standard
uniforms of the copy's generator, ``pamdp.envs.vector``) as ``low + (high - low) * u``, which is how
NumPy's ``uniform`` computes them. Bit for bit with the original: every ``** 2`` of the original is C's
``pow`` (:func:`pow2`), the trigonometric functions and square roots are the C library's (what NumPy calls
on x86-64 without AVX-512), the operations keep the original's order, and ``fastmath`` stays off.

Everything the compiled functions read is defined in this file: Numba's on-disk cache is keyed on this
file alone, so a constant imported from elsewhere could go stale in the cache.
"""

from __future__ import annotations

import math
import numbers

import numba
import numpy as np

# --- §1 constants ------------------------------------------------------------------------------------
FIELD = 1.0
"""Half-size of the square field [-1, 1]²: leaving it (strictly) ends the episode with reward -1."""
TARGET_RADIUS = 0.1
TARGET_LIMIT = FIELD - TARGET_RADIUS
"""The target's centre is drawn in [-0.9, 0.9]² (computed as the original does)."""
TWO_PI = 2 * np.pi

# --- the settings (the original constructor's keyword arguments, §0) ---------------------------------
MAX_TURN, MAX_ACCELERATION, DELTA_T, MAX_STEP, PENALTY, BREAK_VALUE = range(6)
N_SETTINGS = 6
SETTING_NAMES = ("max_turn", "max_acceleration", "delta_t", "max_step", "penalty", "break_value")
DEFAULTS = np.array([np.pi / 2, 0.5, 0.005, 200.0, 0.001, 0.1])
"""The checked configuration: the values the recordings and every published result use."""


def check_settings(**settings) -> np.ndarray:
    """The original constructor's settings (:data:`SETTING_NAMES`; missing ones take
    :data:`DEFAULTS`) as the settings row of the compiled functions, or ``ValueError`` naming a bad one."""
    row = DEFAULTS.copy()
    for name, v in settings.items():
        if name not in SETTING_NAMES:
            raise ValueError(f"unknown setting {name!r}; expected one of {list(SETTING_NAMES)}")
        if name == "max_step":
            if isinstance(v, bool) or not isinstance(v, numbers.Integral) or v < 1:
                raise ValueError(f"max_step={v!r}; expected a positive integer")
        elif isinstance(v, bool) or not isinstance(v, numbers.Real) or not math.isfinite(v):
            raise ValueError(f"{name}={v!r}; expected a finite number")
        elif name != "penalty" and v <= 0:
            raise ValueError(f"{name}={v!r}; expected a positive number")
        row[SETTING_NAMES.index(name)] = float(v)
    return row


# --- the state of one copy --------------------------------------------------------------------------
X, Y, SPEED, THETA, PHI, TX, TY, T = range(8)
"""Agent position, speed (>= 0), heading, velocity direction (Sliding only), target centre, step count."""
D, COS_THETA, SIN_THETA, COS_PHI, SIN_PHI = range(8, 13)
"""Functions of the above, kept so that a step computes each once: the distance to the target and the cosines
and sines of the two angles (a stored value equals a recomputed one, bit for bit)."""
STATE_SIZE = 13
INITIAL_STATE = np.zeros(STATE_SIZE)
INITIAL_STATE[COS_PHI] = 1.0
"""A new env's state before its first reset: the velocity direction starts at 0 and no reset changes it."""
ACCELERATE, TURN, BREAK = 0, 1, 2
OBS_SIZE = 10
DRAWS_PER_RESET = 6
"""Uniforms one reset takes: the target's x, y and radius (drawn, unused), the agent's x, y and heading."""

jit = numba.njit(cache=True, fastmath=False, nogil=True)


@jit
def c_pow2(v):
    """C's ``pow(v, 2)``. Numba and LLVM turn a constant exponent 2 into ``v * v``, so the exponent is made
    a run-time value: ``2 + 0 * v`` is exactly 2 for every finite ``v``."""
    return v ** (2.0 + 0.0 * v)


@jit
def pow2(v):
    """C's ``pow(v, 2)``, which the original's ``** 2`` calls, at a fraction of its cost.

    ``pow`` is not correctly rounded, so it differs from ``v * v`` in the last bit for a few inputs, those
    whose exact square lies almost halfway between two doubles. glibc bounds its error by 0.54 ulp
    (``sysdeps/ieee754/dbl-64/e_pow.c``): where the exact square is within 0.44 ulp of ``p = v * v``, every
    other double is farther from it than that, so ``pow`` returns ``p`` too. The square's error ``err`` is
    computed exactly (Dekker's splitting), and ``p + 1.125 err`` rounds back to ``p`` just when ``|err|`` is
    below 0.44 ulp (below half of that under a power of two, where the doubles are twice as dense); only
    the other inputs, and those whose square could lose digits, call :func:`c_pow2`.
    """
    p = v * v
    if not 1e-100 < abs(v) < 1e100:
        return c_pow2(v)
    c = 134217729.0 * v  # 2^27 + 1: v = hi + lo with 26-bit halves, so the products below are exact
    hi = c - (c - v)
    lo = v - hi
    err = ((hi * hi - p) + 2.0 * hi * lo) + lo * lo
    if p + 1.125 * err == p:
        return p
    return c_pow2(v)


@jit
def wrap_angle(a):
    """``a % 2π`` as Python computes it (floor-mod: ``fmod``, plus 2π if that is negative), without ``fmod``
    for the angles a turn can make."""
    if 0.0 < a < TWO_PI:
        return a
    if TWO_PI <= a < 2.0 * TWO_PI:
        return a - TWO_PI  # exact, as fmod's result is (Sterbenz)
    if -TWO_PI < a < 0.0:
        return a + TWO_PI  # fmod(a, 2π) = a, then Python adds 2π (and rounds)
    return a % TWO_PI


@jit
def clip(v, lo, hi):
    """The original's ``max(min(v, hi), lo)``, with Python's choice between equal values (-0.0 stays)."""
    m = hi if hi < v else v
    return lo if lo > m else m


@jit
def distance(states, i):
    """§2: copy ``i``'s distance from the agent to the target's centre."""
    return np.sqrt(pow2(states[i, X] - states[i, TX]) + pow2(states[i, Y] - states[i, TY]))


@jit
def refresh(states, i):
    """Compute copy ``i``'s stored functions (:data:`D`, :data:`COS_THETA` ... :data:`SIN_PHI`) from its state."""
    states[i, D] = distance(states, i)
    states[i, COS_THETA], states[i, SIN_THETA] = np.cos(states[i, THETA]), np.sin(states[i, THETA])
    states[i, COS_PHI], states[i, SIN_PHI] = np.cos(states[i, PHI]), np.sin(states[i, PHI])


@jit
def reset(states, i, draws, cursor):
    """§5: a new target and agent for copy ``i`` from the six uniforms ``draws[i, cursor:cursor + 6]``;
    returns the next cursor. The velocity direction is kept, as in the original (a reset leaves the agent at
    rest)."""
    u = draws[i]
    states[i, TX] = -TARGET_LIMIT + (TARGET_LIMIT - -TARGET_LIMIT) * u[cursor]
    states[i, TY] = -TARGET_LIMIT + (TARGET_LIMIT - -TARGET_LIMIT) * u[cursor + 1]
    # u[cursor + 2] is the target's radius, uniform(0.1, 0.1): drawn and unused.
    states[i, X] = -FIELD + (FIELD - -FIELD) * u[cursor + 3]
    states[i, Y] = -FIELD + (FIELD - -FIELD) * u[cursor + 4]
    states[i, THETA] = 0.0 + (TWO_PI - 0.0) * u[cursor + 5]
    states[i, SPEED] = 0.0
    states[i, T] = 0.0
    refresh(states, i)
    return cursor + DRAWS_PER_RESET


@jit
def step(states, i, a, p, settings, sliding):
    """One agent step ``(a, p)`` of copy ``i`` (row i of ``states``; §3-4). ``p`` is the chosen action's
    parameter as given (it is clipped here, as the original clips it; break ignores it). The functions take
    the whole array and an index rather than a row, which would be a new array object per copy.

    Returns ``(reward, terminated, goal)``: the step's reward, whether the episode ended (at the goal,
    out of the field or past the step limit), and whether it ended at the goal.
    """
    d_prev = states[i, D]
    states[i, T] += 1.0
    s, theta, phi = states[i, SPEED], states[i, THETA], states[i, PHI]
    if a == ACCELERATE:
        v = settings[MAX_ACCELERATION] * clip(p, 0.0, 1.0)
        if sliding:  # adds the thrust v (cos θ, sin θ) to the velocity s (cos φ, sin φ), in polar form
            delta = phi - theta
            cos_delta, sin_delta = np.cos(delta), np.sin(delta)
            s_new = np.sqrt((pow2(v) + pow2(s)) + ((2 * v) * s) * cos_delta)
            phi = theta + np.arctan2(s * sin_delta, v + s * cos_delta)
            s = s_new
            states[i, COS_PHI], states[i, SIN_PHI] = np.cos(phi), np.sin(phi)
        else:
            s = s + v
    elif a == TURN:
        theta = wrap_angle(theta + settings[MAX_TURN] * clip(p, -1.0, 1.0))
        states[i, COS_THETA], states[i, SIN_THETA] = np.cos(theta), np.sin(theta)
    else:
        bv = settings[BREAK_VALUE]
        s = 0.0 if s < bv else s - bv
        if sliding and s == 0.0:
            phi = theta
            states[i, COS_PHI], states[i, SIN_PHI] = states[i, COS_THETA], states[i, SIN_THETA]
    states[i, SPEED], states[i, THETA], states[i, PHI] = s, theta, phi
    # MOVE, after every action: Moving goes along its heading, Sliding along its velocity.
    c, sn = (states[i, COS_PHI], states[i, SIN_PHI]) if sliding else (states[i, COS_THETA], states[i, SIN_THETA])
    x = states[i, X] = states[i, X] + (settings[DELTA_T] * s) * c
    y = states[i, Y] = states[i, Y] + (settings[DELTA_T] * s) * sn
    d = states[i, D] = distance(states, i)

    # §4: the goal needs a full stop strictly inside the target; it is tested before leaving the field.
    if d < TARGET_RADIUS and s == 0.0:
        return ((d_prev - d) - settings[PENALTY]) + 1.0, True, True
    if abs(x) > FIELD or abs(y) > FIELD or states[i, T] > settings[MAX_STEP]:
        return -1.0, True, False
    return (d_prev - d) - settings[PENALTY], False, False


@jit
def observe(states, i, settings, out):
    """§4's ten features of copy ``i`` into ``out[i]``: the heading θ (not φ), the distance, whether the agent
    is within the target (``d <= 0.1``, unlike the goal's ``d < 0.1``) and the elapsed fraction ``t / 200``."""
    out[i, 0], out[i, 1], out[i, 2] = states[i, X], states[i, Y], states[i, SPEED]
    out[i, 3], out[i, 4] = states[i, COS_THETA], states[i, SIN_THETA]
    out[i, 5], out[i, 6], out[i, 7] = states[i, TX], states[i, TY], states[i, D]
    out[i, 8] = 0.0 if states[i, D] > TARGET_RADIUS else 1.0
    out[i, 9] = states[i, T] / settings[MAX_STEP]


@jit
def first_bad_action(a, p_accelerate, p_turn):
    """The first copy whose discrete action is not 0, 1 or 2 or whose parameters are not finite; -1 if none."""
    for i in range(a.shape[0]):
        if not (0 <= a[i] <= 2 and np.isfinite(p_accelerate[i]) and np.isfinite(p_turn[i])):
            return i
    return -1


@jit
def step_copies(
    states, a, p_accelerate, p_turn, resetting, settings, sliding, draws, cursors, obs, rewards, terminated, goal
):
    """Every copy ``i``: :func:`reset` where ``resetting[i]``, else :func:`step` with action ``a[i]`` and
    its parameter (``p_accelerate[i]`` or ``p_turn[i]``); then its observation into ``obs[i]``. Row i of
    every array is copy i's; ``cursors``, ``obs``, ``rewards``, ``terminated`` and ``goal`` are written
    (zeros for a resetting copy)."""
    for i in range(states.shape[0]):
        if resetting[i]:
            cursors[i] = reset(states, i, draws, cursors[i])
            rewards[i], terminated[i], goal[i] = 0.0, False, False
        else:
            p = np.float64(p_accelerate[i] if a[i] == ACCELERATE else p_turn[i])
            rewards[i], terminated[i], goal[i] = step(states, i, a[i], p, settings, sliding)
        observe(states, i, settings, obs)


@jit
def reset_copies(states, mask, settings, draws, cursors, obs):
    """:func:`reset` every copy where ``mask`` is true; every copy's observation into ``obs``."""
    for i in range(states.shape[0]):
        if mask[i]:
            cursors[i] = reset(states, i, draws, cursors[i])
        observe(states, i, settings, obs)
