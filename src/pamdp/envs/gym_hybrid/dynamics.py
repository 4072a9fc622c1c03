"""gym-hybrid's Moving and Sliding, written once from ``shared/specs/gym_hybrid.md`` and compiled by Numba.

The two domains share everything but the agent's ACCELERATE and BREAK (spec §3), so every function takes
``sliding`` (False: Moving, the agent moves along its heading; True: Sliding, it keeps a velocity direction
of its own). A copy's state is a float64 row of :data:`STATE_SIZE` numbers (:data:`X` ... :data:`T`),
updated in place; the constructor's settings are a row of :data:`N_SETTINGS` numbers (:data:`DEFAULTS`).
:func:`step` advances one copy by one agent step and :func:`reset` starts its episode; the scalar env calls
them for its one copy, :func:`step_copies` loops them over the copies of the batched env.

Random numbers: only a reset draws, six uniforms in the spec's §5 order, read from ``draws`` (standard
uniforms of the copy's generator, ``pamdp.envs.vector``) as ``low + (high - low) * u``, which is how
NumPy's ``uniform`` computes them. Bit for bit with the original: every ``** 2`` of the original is C's
``pow`` (:func:`pow2`), the trigonometric functions and square roots are the C library's (what NumPy calls
on this project's x86-64 builds), the operations keep the original's order, and ``fastmath`` stays off.

Everything the compiled functions read is defined in this file: Numba's on-disk cache is keyed on this
file alone, so a constant imported from elsewhere could go stale in the cache.
"""

from __future__ import annotations

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

# --- the state of one copy --------------------------------------------------------------------------
X, Y, SPEED, THETA, PHI, TX, TY, T = range(8)
"""Agent position, speed (>= 0), heading, velocity direction (Sliding only), target centre, step count."""
STATE_SIZE = 8
ACCELERATE, TURN, BREAK = 0, 1, 2
OBS_SIZE = 10
DRAWS_PER_RESET = 6
"""Uniforms one reset takes: the target's x, y and radius (drawn, unused), the agent's x, y and heading."""

jit = numba.njit(cache=True, fastmath=False, nogil=True)


@jit
def pow2(v):
    """C's ``pow(v, 2)``, which the original's ``** 2`` calls; it differs from ``v * v`` in the last bit
    for a few inputs. Numba and LLVM turn a constant exponent 2 into ``v * v``, so the exponent is made a
    run-time value: ``2 + 0 * v`` is exactly 2 for every finite ``v``."""
    return v ** (2.0 + 0.0 * v)


@jit
def clip(v, lo, hi):
    """The original's ``max(min(v, hi), lo)``, with Python's choice between equal values (-0.0 stays)."""
    m = hi if hi < v else v
    return lo if lo > m else m


@jit
def distance(state):
    """§2: the agent's distance to the target's centre."""
    return np.sqrt(pow2(state[X] - state[TX]) + pow2(state[Y] - state[TY]))


@jit
def reset(state, draws, cursor):
    """§5: a new target and agent from the six uniforms ``draws[cursor:cursor + 6]``; returns the next
    cursor. The velocity direction is kept, as in the original (a reset leaves the agent at rest)."""
    u = draws[cursor : cursor + DRAWS_PER_RESET]
    state[TX] = -TARGET_LIMIT + (TARGET_LIMIT - -TARGET_LIMIT) * u[0]
    state[TY] = -TARGET_LIMIT + (TARGET_LIMIT - -TARGET_LIMIT) * u[1]
    # u[2] is the target's radius, uniform(0.1, 0.1): drawn and unused.
    state[X] = -FIELD + (FIELD - -FIELD) * u[3]
    state[Y] = -FIELD + (FIELD - -FIELD) * u[4]
    state[THETA] = 0.0 + (TWO_PI - 0.0) * u[5]
    state[SPEED] = 0.0
    state[T] = 0.0
    return cursor + DRAWS_PER_RESET


@jit
def step(state, a, p, settings, sliding):
    """One agent step ``(a, p)`` of one copy (§3-4); ``p`` is the chosen action's parameter as given (it is
    clipped here, as the original clips it; break ignores it).

    Returns ``(reward, terminated, goal)``: the step's reward, whether the episode ended (at the goal,
    out of the field or past the step limit), and whether it ended at the goal.
    """
    d_prev = distance(state)
    state[T] += 1.0
    s, theta, phi = state[SPEED], state[THETA], state[PHI]
    if a == ACCELERATE:
        v = settings[MAX_ACCELERATION] * clip(p, 0.0, 1.0)
        if sliding:  # adds the thrust v (cos θ, sin θ) to the velocity s (cos φ, sin φ), in polar form
            delta = phi - theta
            s_new = np.sqrt((pow2(v) + pow2(s)) + ((2 * v) * s) * np.cos(delta))
            phi = theta + np.arctan2(s * np.sin(delta), v + s * np.cos(delta))
            s = s_new
        else:
            s = s + v
    elif a == TURN:
        theta = (theta + settings[MAX_TURN] * clip(p, -1.0, 1.0)) % TWO_PI  # floor-mod, as Python's %
    else:
        bv = settings[BREAK_VALUE]
        s = 0.0 if s < bv else s - bv
        if sliding and s == 0.0:
            phi = theta
    # MOVE, after every action: Moving goes along its heading, Sliding along its velocity.
    angle = phi if sliding else theta
    state[X] = state[X] + (settings[DELTA_T] * s) * np.cos(angle)
    state[Y] = state[Y] + (settings[DELTA_T] * s) * np.sin(angle)
    state[SPEED], state[THETA], state[PHI] = s, theta, phi

    # §4: the goal needs a full stop strictly inside the target; it is tested before leaving the field.
    d = distance(state)
    if d < TARGET_RADIUS and s == 0.0:
        return ((d_prev - d) - settings[PENALTY]) + 1.0, True, True
    if abs(state[X]) > FIELD or abs(state[Y]) > FIELD or state[T] > settings[MAX_STEP]:
        return -1.0, True, False
    return (d_prev - d) - settings[PENALTY], False, False


@jit
def observe(state, settings, out):
    """§4's ten features of one copy into ``out``: the heading θ (not φ), the distance, whether the agent
    is within the target (``d <= 0.1``, unlike the goal's ``d < 0.1``) and the elapsed fraction ``t / 200``."""
    d = distance(state)
    out[0], out[1], out[2] = state[X], state[Y], state[SPEED]
    out[3], out[4] = np.cos(state[THETA]), np.sin(state[THETA])
    out[5], out[6], out[7] = state[TX], state[TY], d
    out[8] = 0.0 if d > TARGET_RADIUS else 1.0
    out[9] = state[T] / settings[MAX_STEP]


@jit
def step_copies(states, a, p_accelerate, p_turn, resetting, settings, sliding, draws, cursors, obs, rewards, terminated, goal):
    """Every copy ``i``: :func:`reset` where ``resetting[i]``, else :func:`step` with action ``a[i]`` and
    its parameter (``p_accelerate[i]`` or ``p_turn[i]``); then its observation into ``obs[i]``. Row i of
    every array is copy i's; ``cursors``, ``obs``, ``rewards``, ``terminated`` and ``goal`` are written
    (zeros for a resetting copy)."""
    for i in range(states.shape[0]):
        if resetting[i]:
            cursors[i] = reset(states[i], draws[i], cursors[i])
            rewards[i], terminated[i], goal[i] = 0.0, False, False
        else:
            p = p_accelerate[i] if a[i] == ACCELERATE else p_turn[i]
            rewards[i], terminated[i], goal[i] = step(states[i], a[i], p, settings, sliding)
        observe(states[i], settings, obs[i])


@jit
def reset_copies(states, mask, settings, draws, cursors, obs):
    """:func:`reset` every copy where ``mask`` is true; every copy's observation into ``obs``."""
    for i in range(states.shape[0]):
        if mask[i]:
            cursors[i] = reset(states[i], draws[i], cursors[i])
        observe(states[i], settings, obs[i])
