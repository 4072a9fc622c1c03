"""Robot Soccer Goal's dynamics (``cycraig/gym-goal``, with MP-DQN's scaled features), written once and compiled
by Numba.

:func:`reset` puts one copy at the start of an episode and :func:`step` advances it by (part of) one
agent step; :func:`reset_copies` and :func:`step_copies` loop them over the copies (the scalar env's one copy
included). A copy's state is a float64 row of :data:`STATE_SIZE` numbers
(player, keeper, ball: position, velocity and, for the two players, orientation; then the agent-step
counter), updated in place. Section numbers in comments (``§7.1``) refer to the project's
written account of that code.

Noise: every random number is a uniform one, ``uniform(lo, hi) = lo + (hi - lo) * u`` with ``u`` the
next number of the copy's ``draws`` (NumPy's ``random()``: a block of them equals as many single draws,
and NumPy's own ``uniform`` computes exactly this), taken in the spec's §9 order. With ``draws`` from
``numpy.random.RandomState(S)`` the copy replays the original driven by that generator.

A shot runs until the episode ends, so one agent step can take any number of sub-steps (and numbers).
:func:`step` therefore runs sub-steps only while a whole sub-step's numbers (:data:`SUBSTEP_DRAWS`) are
left, and says whether the agent step is finished; the caller tops up the numbers and calls again with
the sub-steps done so far, which resumes the same agent step.

Floating point (§10): ``math.atan2`` for every angle, including the kick's direction, for which the
original uses NumPy's ``arctan2`` (on the recordings' AVX-512 build NumPy's differs from libm's in the last
bit for some inputs; no other choice is exact there, and the drift stays far below the tolerance of 1e-12);
libm's ``cos`` / ``sin``; ``math.sqrt(x*x + y*y)`` for lengths, but the observation's ``np.linalg.norm``
as the recordings' OpenBLAS computes it, ``sqrt(fma(dy, dy, dx*dx))``. ``fastmath`` stays off.

Everything the compiled functions read is defined in this file: Numba's on-disk cache is keyed on this
file alone, so a constant imported from elsewhere could go stale in the cache.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numba import types
from numba.extending import intrinsic

# --- §1 field and constants (metres; x towards the goal, y across) ----------------------------------
HALF_LENGTH = 20.0
"""The goal line is x = L/2 = 20; the simulated field is x in [0, 20], y in [-15, 15]."""
HALF_WIDTH = 15.0
GOAL_WIDTH = 14.02
HALF_GOAL = GOAL_WIDTH / 2
"""The goal mouth is y in [-7.01, 7.01]."""
NET_BACK = HALF_LENGTH + 2.44
"""The back of the net: a ball with 20 <= x <= 22.44 in the mouth is a goal."""
GOAL_AREA_X = HALF_LENGTH - 5.5
GOAL_AREA_HALF = 18.32 / 2
CATCHABLE = 2.0
CATCH_PROBABILITY = 1.0
KICKABLE = 0.9 + 0.7
INERTIA_MOMENT = 5.0
POWER_MAX = 100.0
GOAL_REWARD = 50.0
SHOOT_X = 20.4
"""A shot aims at (20.4, y)."""
PI = math.pi
TWO_PI = 2 * math.pi

# Entities: offset of their state in a row, and (size, rand, accel_max, speed_max, power_rate, decay).
PLAYER, KEEPER, BALL = 0, 5, 10
"""Offsets of the entities in a state row: position (2), velocity (2), then orientation (player, keeper)."""
PLAYER_CONFIG = (0.9, 0.1, 1.0, 1.0, 0.006, 0.4)
KEEPER_CONFIG = (0.9, 0.1, 1.0, 1.0, 0.006, 0.4)
BALL_CONFIG = (0.4, 0.05, 2.7, 2.7, 0.027, 0.94)
BALL_DECAY = BALL_CONFIG[5]

# --- §2 the state of one copy -----------------------------------------------------------------------
PX, PY, PVX, PVY, PHI, KX, KY, KVX, KVY, PSI, BX, BY, BVX, BVY, TIME = range(15)
STATE_SIZE = 15
TIME_LIMIT = 100
"""The agent step that brings the counter to 100 ends the episode without simulating (truncated)."""
SUBSTEP_DRAWS = 7
"""The most numbers one sub-step takes: the player's ACCEL (3), the keeper's (3), the catch (1)."""
RESET_DRAWS = 1
KICK_TO = 0
"""Action 0 kicks towards a point; every other action of Goal shoots."""
TRACE_SIZE = 8
"""Per sub-step, :func:`step` can record Px, Py, phi, Kx, Ky, psi, Bx, By (for rendering)."""

# --- §3 observation scaling (float32 bounds of the original's boxes, as float64) --------------------
OBS_SIZE = 17
OBS_LOW = np.array(
    [-0.0, -15.0, -1.0, -1.0, -3.1415927410125732] * 2  # player, keeper: x, y, vx, vy, orientation
    + [-0.0, -15.0, -3.0, -3.0, -1.0, -1.0, -7.010000228881836]  # ball: x, y, vx, vy; f14, f15, f16
)
OBS_DEN = np.array(
    [20.0, 30.0, 2.0, 2.0, 6.2831854820251465] * 2 + [20.0, 30.0, 6.0, 6.0, 2.0, 2.0, 21.030000686645508]
)

jit = numba.njit(cache=True, fastmath=False, nogil=True, error_model="numpy")


@intrinsic
def fma(typingctx, x, y, z):
    """``x * y + z`` rounded once (LLVM's ``llvm.fma``: the hardware instruction, or libm's ``fma``)."""
    sig = types.float64(types.float64, types.float64, types.float64)

    def codegen(context, builder, signature, args):
        return builder.fma(*args)

    return sig, codegen


# --- §7.0 helpers ----------------------------------------------------------------------------------
@jit
def bound(x, lo, hi):
    return lo if x < lo else hi if x > hi else x


@jit
def norm(x, y):
    return math.sqrt(x * x + y * y)


@jit
def angle_between(x0, y0, x1, y1):
    return math.atan2(y1 - y0, x1 - x0)


@jit
def wrap(x):
    while x > PI:
        x -= TWO_PI
    while x < -PI:
        x += TWO_PI
    return x


@jit
def uniform(lo, hi, draws, cursor):
    """NumPy's ``uniform(lo, hi)`` from the uniform ``draws[cursor]``."""
    return lo + (hi - lo) * draws[cursor]


@jit
def accel(s, e, config, power, theta, draws, cursor):
    """ACCEL of the entity at offset ``e``: its velocity gains a noisy, bounded push. Takes 3 numbers."""
    rand, accel_max, speed_max, power_rate = config[1], config[2], config[3], config[4]
    eps = uniform(-rand, rand, draws, cursor)
    theta = (1 + eps) * theta  # the noise multiplies the angle's value (quirk 8)
    rmax = rand * norm(s[e + 2], s[e + 3])
    n0 = uniform(-rmax, rmax, draws, cursor + 1)
    n1 = uniform(-rmax, rmax, draws, cursor + 2)
    c = power * power_rate
    ax = bound(c * math.cos(theta) + n0, -accel_max, accel_max)
    ay = bound(c * math.sin(theta) + n1, -accel_max, accel_max)
    s[e + 2] = bound(s[e + 2] + ax, -speed_max, speed_max)
    s[e + 3] = bound(s[e + 3] + ay, -speed_max, speed_max)
    return cursor + 3


@jit
def kick_power(s):
    dd = abs(wrap(angle_between(s[PX], s[PY], s[BX], s[BY]) - s[PHI]))
    dist = norm(s[PX] - s[BX], s[PY] - s[BY])
    return (1 - ((0.25 * dd) / PI)) - ((0.25 * dist) / KICKABLE)


@jit
def goal_distance(bx, by):
    """The penalty distance of §7.5, quirk 5 included (``7.01 - By`` behind the line, below the goal)."""
    if bx < HALF_LENGTH:
        if by < -HALF_GOAL:
            return norm(bx - HALF_LENGTH, by - (-HALF_GOAL))
        if by > HALF_GOAL:
            return norm(bx - HALF_LENGTH, by - HALF_GOAL)
        return HALF_LENGTH - bx
    if by < -HALF_GOAL:
        return HALF_GOAL - by
    if by > HALF_GOAL:
        return by - HALF_GOAL
    return 0.0


@jit
def keeper_target(bx, by):
    """§5: where the keeper starts, on the line from the ball to the goal centre, in the goal area."""
    g = -by / (HALF_LENGTH - bx)
    c = by - g * bx
    if bx < GOAL_AREA_X:
        x = bx
    elif by < -GOAL_AREA_HALF:
        x = (-GOAL_AREA_HALF - c) / g
    else:
        x = (GOAL_AREA_HALF - c) / g
    x = bound(x, GOAL_AREA_X, HALF_LENGTH)
    return x, bound(g * x + c, -GOAL_AREA_HALF, GOAL_AREA_HALF)


# --- §5 reset --------------------------------------------------------------------------------------
@jit
def reset(s, draws, cursor):
    """Start an episode in the row ``s``; takes :data:`RESET_DRAWS` number. Returns the next cursor."""
    if cursor + RESET_DRAWS > draws.size:
        raise ValueError("reset needs RESET_DRAWS numbers in draws after cursor")
    for k in range(STATE_SIZE):
        s[k] = 0.0
    s[PY] = uniform(-HALF_WIDTH, HALF_WIDTH, draws, cursor)
    s[PHI] = angle_between(0.0, s[PY], HALF_LENGTH, 0.0)
    offset = KICKABLE - 1e-12  # the ball starts just kickable (quirk 9)
    s[BX] = 0.0 + offset * math.cos(s[PHI])
    s[BY] = s[PY] + offset * math.sin(s[PHI])
    s[KX], s[KY] = keeper_target(s[BX], s[BY])
    s[PSI] = angle_between(s[KX], s[KY], s[BX], s[BY])
    return cursor + RESET_DRAWS


# --- §7 one sub-step -------------------------------------------------------------------------------
@jit
def player_act(s, kick, tx, ty, draws, cursor):
    """§7.1: turn to or dash at the ball, or kick it towards ``(tx, ty)``. Returns the next cursor."""
    if norm(s[PX] - s[BX], s[PY] - s[BY]) > KICKABLE:
        beta = angle_between(s[PX], s[PY], s[BX], s[BY])
        if not abs(wrap(s[PHI] - beta)) < PI / 8:
            turn = wrap(beta - s[PHI])
            s[PHI] = s[PHI] + turn / (1 + INERTIA_MOMENT * norm(s[PVX], s[PVY]))
            return cursor
        return accel(s, PLAYER, PLAYER_CONFIG, 10.0, s[PHI], draws, cursor)
    ax = (1 - BALL_DECAY) * (tx - s[PX]) - s[BVX]
    ay = (1 - BALL_DECAY) * (ty - s[PY]) - s[BVY]
    kp = kick_power(s)
    power = norm(ax, ay) / (kp * BALL_CONFIG[4])
    d = math.atan2(ay, ax) - s[PHI]
    power = bound(power, -POWER_MAX, POWER_MAX) * kp
    return accel(s, BALL, BALL_CONFIG, power, s[PHI] + d, draws, cursor)


@jit
def keeper_act(s, draws, cursor):
    """§7.2: intercept a ball heading into the goal, else run to where the ball will stop."""
    ex = s[BX] + s[BVX] / (1 - BALL_DECAY)
    ey = s[BY] + s[BVY] / (1 - BALL_DECAY)
    dx, dy = ex - s[BX], ey - s[BY]
    g = dy / dx if dx != 0 else 0.0
    c = s[BY] - g * s[BX]
    gy = (g * 40.0) / 2 + c
    if ex > HALF_LENGTH and (-HALF_GOAL - CATCHABLE) <= gy <= (HALF_GOAL + CATCHABLE) and g != 0:
        g2 = -1 / g
        c2 = s[KY] - g2 * s[KX]
        bx = (c2 - c) / (g - g2)
        by = g * bx + c
        theta = angle_between(s[KX], s[KY], bx, by)
        cursor = accel(s, KEEPER, KEEPER_CONFIG, 20.0, theta, draws, cursor)
    else:
        theta = angle_between(s[KX], s[KY], ex, ey)
        cursor = accel(s, KEEPER, KEEPER_CONFIG, 8.0, theta, draws, cursor)
    s[PSI] = theta
    return cursor


@jit
def collide(s, e1, size1, e2, size2):
    """§7.4: two overlapping entities are pushed apart along their centre line and both bounce back."""
    dist = norm(s[e1] - s[e2], s[e1 + 1] - s[e2 + 1])
    if dist < size1 + size2:
        o = (size1 + size2 - dist) / 2
        t1 = angle_between(s[e1], s[e1 + 1], s[e2], s[e2 + 1])
        t2 = angle_between(s[e2], s[e2 + 1], s[e1], s[e1 + 1])
        s[e1] = s[e1] + o * math.cos(t2)
        s[e1 + 1] = s[e1 + 1] + o * math.sin(t2)
        s[e2] = s[e2] + o * math.cos(t1)
        s[e2 + 1] = s[e2 + 1] + o * math.sin(t1)
        for k in (e1 + 2, e1 + 3, e2 + 2, e2 + 3):
            s[k] = -s[k]


@jit
def substep(s, kick, tx, ty, draws, cursor):
    """One tick of the simulation (§7). Returns ``(reward, done, cursor)``."""
    cursor = player_act(s, kick, tx, ty, draws, cursor)
    cursor = keeper_act(s, draws, cursor)
    for e, decay in ((PLAYER, PLAYER_CONFIG[5]), (KEEPER, KEEPER_CONFIG[5]), (BALL, BALL_CONFIG[5])):  # §7.3
        s[e] = s[e] + s[e + 2]
        s[e + 1] = s[e + 1] + s[e + 3]
        s[e + 2] = s[e + 2] * decay
        s[e + 3] = s[e + 3] * decay
    collide(s, PLAYER, PLAYER_CONFIG[0], KEEPER, KEEPER_CONFIG[0])
    collide(s, PLAYER, PLAYER_CONFIG[0], BALL, BALL_CONFIG[0])
    collide(s, KEEPER, KEEPER_CONFIG[0], BALL, BALL_CONFIG[0])
    bx, by = s[BX], s[BY]
    if HALF_LENGTH <= bx <= NET_BACK and -HALF_GOAL <= by <= HALF_GOAL:  # §7.5: a goal
        return GOAL_REWARD, True, cursor
    u = draws[cursor]  # the catch draw, every sub-step although the catch is certain (quirk 7)
    cursor += 1
    caught = u <= CATCH_PROBABILITY and norm(s[KX] - bx, s[KY] - by) < CATCHABLE
    if caught or not (0 <= bx <= HALF_LENGTH and -HALF_WIDTH <= by <= HALF_WIDTH):
        return -goal_distance(bx, by), True, cursor
    return 0.0, False, cursor


# --- §6 one agent step -----------------------------------------------------------------------------
@jit
def step(s, kick, tx, ty, draws, cursor, substeps, trace):
    """Run agent step ``kick`` (kick-to if true, else shoot) at the target ``(tx, ty)`` for one copy.

    ``s``: the copy's row, updated in place. ``tx, ty``: the kick's target ``(x, x)`` or the shot's
    ``(20.4, y)``, parameters already clipped. ``draws[cursor:]``: uniform numbers, at least
    :data:`SUBSTEP_DRAWS` of them. ``substeps``: 0 to start an agent step, else the sub-steps it has run,
    to resume it. ``trace``: ``(rows, TRACE_SIZE)``; sub-step k writes row k while ``k < rows`` (pass
    ``rows = 0`` to record nothing).

    Returns ``(reward, terminated, truncated, substeps, cursor, finished)``. ``finished`` is false when the
    step stopped before its end because fewer than :data:`SUBSTEP_DRAWS` numbers were left in ``draws``
    or ``trace`` was full: top them up and call again with the returned ``substeps`` and ``cursor``.
    """
    if cursor + SUBSTEP_DRAWS > draws.size:
        raise ValueError("step needs SUBSTEP_DRAWS numbers in draws after cursor")
    if substeps == 0:
        s[TIME] += 1
        if s[TIME] == TIME_LIMIT:  # before any simulation (quirk 4)
            return -goal_distance(s[BX], s[BY]), False, True, 0, cursor, True
    rows = trace.shape[0]
    while cursor + SUBSTEP_DRAWS <= draws.size and (rows == 0 or substeps < rows):
        reward, done, cursor = substep(s, kick, tx, ty, draws, cursor)
        if substeps < rows:
            for j, k in enumerate((PX, PY, PHI, KX, KY, PSI, BX, BY)):
                trace[substeps, j] = s[k]
        substeps += 1
        if done:
            return reward, True, False, substeps, cursor, True
        if kick and not (norm(s[PX] - s[BX], s[PY] - s[BY]) > KICKABLE or norm(s[BVX], s[BVY]) > 0.1):
            return reward, False, False, substeps, cursor, True
    return 0.0, False, False, substeps, cursor, False


@jit
def reset_copies(states, mask, draws, cursors):
    """:func:`reset` every copy ``i`` with ``mask[i]`` (row i of ``states`` and ``draws``)."""
    for i in range(states.shape[0]):
        if mask[i]:
            cursors[i] = reset(states[i], draws[i], cursors[i])


@jit
def step_copies(states, kick, tx, ty, pending, draws, cursors, substeps, rewards, terminated, truncated, trace):
    """:func:`step` for every copy ``i`` with ``pending[i]``; ``pending[i]`` is cleared once its agent
    step is finished. Row i of every array is copy i's; ``substeps`` (0 at the start of the agent step),
    ``cursors``, ``rewards`` and the flags are updated; copy 0 records its sub-steps in ``trace`` (the scalar
    env's rendering; no rows: nothing). Returns whether any copy is still pending."""
    no_trace = trace[:0]
    left = False
    for i in range(states.shape[0]):
        if pending[i]:
            rewards[i], terminated[i], truncated[i], substeps[i], cursors[i], done = step(
                states[i], kick[i], tx[i], ty[i], draws[i], cursors[i], substeps[i], trace if i == 0 else no_trace
            )
            pending[i] = not done
            left = left or not done
    return left


# --- §3 observation --------------------------------------------------------------------------------
@jit
def observe(states, out):
    """§3's 17 scaled features of each copy (row of ``states``) into the rows of ``out``."""
    for i in range(states.shape[0]):
        s = states[i]
        dx, dy = s[BX] - s[KX], s[BY] - s[KY]
        n = math.sqrt(fma(dy, dy, dx * dx))  # np.linalg.norm as the recordings' NumPy computes it
        if s[KX] == s[BX]:
            pos = -HALF_GOAL if s[KY] < s[BY] else HALF_GOAL
        else:
            g = (s[KY] - s[BY]) / (s[KX] - s[BX])
            c = s[BY] - g * s[BX]
            pos = min(max((g * 40.0) / 2 + c, -HALF_GOAL), GOAL_WIDTH)  # clipped at 14.02 (quirk 6)
        for j in range(OBS_SIZE):
            raw = s[j] if j < 14 else dx / n if j == 14 else dy / n if j == 15 else pos
            out[i, j] = (2.0 * (raw - OBS_LOW[j])) / OBS_DEN[j] - 1.0


# --- the actions' targets (NumPy: the envs' parser reads them, the compiled functions do not) ---------
KICK_LOW, KICK_HIGH = np.array([0.0, -15.0]), np.array([40.0, 15.0])
"""Kick-to's box, also the float64 bounds its parameters are clipped to."""
HARD_GOAL_INTERVALS = ((-1.0, -0.6), (-0.6, -0.2), (0.2, 0.2), (0.2, 0.6), (0.6, 1.0))
"""HyAR's five parts of the goal mouth, as positions in [-1, 1]; the third is HyAR's typo for
[-0.2, 0.2], so actions 3 and 8 always aim at the same point."""
_SLOPE = np.array([(lo - hi) / 2 for lo, hi in HARD_GOAL_INTERVALS])
_OFFSET = np.array([lo - 1 * m for (lo, _), m in zip(HARD_GOAL_INTERVALS, _SLOPE)])
_SHOT_RANGE, _SHOT_LOW = 14.020000457763672, -7.010000228881836
"""Goal's float32 shoot box, its width computed in float32, through which MP-DQN scales a position."""


def hard_goal_shot(j, p):
    """The goal-line y that Hard Goal's shot into part ``j`` (0..4) with parameter ``p`` aims at, before
    Goal's clip: HyAR's ``q = p * m_j + o_j`` (p = +1 gives the part's lower end; ``p`` is not clipped)
    scaled from [-1, 1] onto Goal's shoot box. Works on arrays."""
    q = p * _SLOPE[j] + _OFFSET[j]
    return (_SHOT_RANGE * (q + 1)) / 2.0 + _SHOT_LOW


def targets(a, columns, hard: bool) -> tuple:
    """Each copy's ``(kick, tx, ty)`` for :func:`step_copies` from its action ``a`` (int64) and the first numbers of
    every box's parameters ``columns`` (float64): kick-to aims at ``(x, x)`` with ``x`` clipped into [0, 40], a shot
    at ``(20.4, y)`` with ``y`` (Hard Goal: :func:`hard_goal_shot`'s) clipped into [-7.01, 7.01]."""
    x = np.clip(columns[0], KICK_LOW[0], KICK_HIGH[0])
    y = np.stack(columns[1:])[np.maximum(a - 1, 0), np.arange(a.shape[0])]
    if hard:
        y = hard_goal_shot((np.maximum(a, 1) - 1) % 5, y)
    y = np.clip(y, -HALF_GOAL, HALF_GOAL)
    kick = a == KICK_TO
    return kick, np.where(kick, x, SHOOT_X), np.where(kick, x, y)
