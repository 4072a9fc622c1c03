"""Platform's dynamics (Masson, Ranchod & Konidaris 2016, as ``cycraig/gym-platform`` codes them), written once
and compiled by Numba.

:func:`step` advances one copy by one agent step and :func:`step_copies` loops it over the copies (the scalar
env's one copy included). A copy's state is a float64 row of
:data:`STATE_SIZE` numbers (:data:`X` ... :data:`E2DX`), updated in place. Section numbers in comments
(``§7.6``) refer to the project's written account of that code.

Noise: the step reads standard normals from ``draws``, starting at ``cursor``, in the spec's §9 order
(the jump's two numbers at take-off, then in every sub-step the player's, then the enemy's), and returns
the cursor after the last one it used. NumPy's ``normal(0, s)`` is ``0.0 + s * z`` with ``z`` the next
standard normal, and a block of standard normals equals as many single draws, so with ``draws`` taken
from ``numpy.random.RandomState(S)`` the step replays the reference implementation bit for bit
(``pamdp.envs.vector`` keeps such buffers per copy). All arithmetic is float64, and ``fastmath`` stays
off: reassociation or fused multiply-adds would change the roundings.

Everything the compiled functions read is defined in this file: Numba's on-disk cache is keyed on this
file alone, so a constant imported from elsewhere could go stale in the cache.
"""

from __future__ import annotations

import math

import numba
import numpy as np

# --- §1 geometry (pixels, y up; positions are lower-left corners) -----------------------------------
PLATFORM_HEIGHT = 40.0
"""Every platform spans y in [0, 40], so an entity standing on one has y == 40 exactly."""
PLATFORMS = ((0.0, 250.0), (475.0, 275.0), (985.0, 50.0))
"""``(x, width)`` of the three platforms; the gaps are 225 and 235 wide."""
X_GOAL = 1035.0
"""Right edge of the last platform: reaching it ends the episode with return 1."""
PLAYER_W, PLAYER_H = 20.0, 30.0
"""Player and enemies are 20 x 30 boxes."""
ENEMY_BOUNDS = ((0.0, 230.0), (475.0, 730.0))
"""Patrol interval ``[L, R] = [P.x, P.x + width - 20]`` of enemy 1 (platform 1) and enemy 2 (platform 2)."""

# --- §2 constants -----------------------------------------------------------------------------------
DT = 0.05
GRAVITY = 9.8
DECAY = 0.99
VX_MAX = 100.0
VY_MAX = 200.0
VX_GROUND = 70.0
AX_MAX = (VX_MAX - VX_GROUND) / DT
"""600: caps any single impulse to +-30 in vx (computed as the reference does, so clips compare equal)."""
AY_MAX = VY_MAX / DT
ENEMY_SPEED = 30.0
ENEMY_NOISE = 0.5 * DT
PLAYER_NOISE = 0.5 * DT
JUMP_DEV = 1.0
RUN, HOP, LEAP = 0, 1, 2
HOP_DY0, LEAP_DY0 = 35.0, 25.0
"""Vertical take-off speed of each jump."""
PARAM_MAX = (30.0, 720.0, 430.0)
"""Upper bound of each action's parameter box (the lower bound is 0)."""
RUN_SUBSTEPS = 20
"""The reference counts 1.0 down by dt while > 0: exactly 20 sub-steps."""

# --- the state of one copy --------------------------------------------------------------------------
X, Y, VX, VY, E1X, E1DX, E2X, E2DX = range(8)
STATE_SIZE = 8
INITIAL_STATE = np.array([0.0, PLATFORM_HEIGHT, 0.0, 0.0, 230.0, -ENEMY_SPEED, 730.0, -ENEMY_SPEED])
"""§5: deterministic; all randomness is in the dynamics."""
MAX_SUBSTEPS = 200
"""More sub-steps than one agent step can take. A step starts on a platform (a run that leaves one ends
the episode in the next sub-step, the player being below the walking surface beside the platform) and a
jump leaves it at most 35 upwards, so the player is back at the walking surface after at most
2 * 35 / (g * dt) + 2 = 145 airborne sub-steps, where it lands or falls."""
MAX_DRAWS = 2 + 2 * MAX_SUBSTEPS
"""More normals than one agent step can take: two at a jump's take-off, two per sub-step."""
TRACE_SIZE = 4
"""Per sub-step, :func:`step` can record the player's x, y and the enemies' x (for rendering)."""

# --- §4 observation scaling -------------------------------------------------------------------------
OBS_SIZE = 9
OBS_SHIFT = np.array([20.0, 0.0, 0.0, 30.0, 0.0, 0.0, 0.0, 0.0, 0.0])
OBS_SCALE = np.array([1055.0, 100.0, 1035.0, 60.0, 275.0, 275.0, 235.0, 1035.0, 1.0])
PLATFORM_FEATURES = np.array(
    [
        [250.0, 275.0, 225.0, 0.0, 0.0],
        [275.0, 50.0, 235.0, 475.0, 0.0],
        [50.0, 0.0, 0.0, 985.0, 0.0],
    ]
)
"""(wd1, wd2, gap, pos, diff) while the player is before platform 2, on/over platform 2, on platform 3."""

# A player (20 wide) stands on platform P if P.x - 20 <= x <= P.x + width; x never leaves [0, 1035].
P1_RIGHT = PLATFORMS[0][0] + PLATFORMS[0][1]
P2_LEFT, P2_RIGHT = PLATFORMS[1][0] - PLAYER_W, PLATFORMS[1][0] + PLATFORMS[1][1]
P3_LEFT = PLATFORMS[2][0] - PLAYER_W
ENEMY2_FROM = PLATFORMS[1][0]
"""The active enemy is enemy 2 once the player's x is beyond 475 (strictly)."""

jit = numba.njit(cache=True, fastmath=False, nogil=True)


@jit
def clip(v, lo, hi):
    return lo if v < lo else hi if v > hi else v


@jit
def on_platform(x, y):
    """§7.1: standing exactly on top of some platform (exact float equality, as the reference)."""
    return y == PLATFORM_HEIGHT and (x <= P1_RIGHT or P2_LEFT <= x <= P2_RIGHT or x >= P3_LEFT)


@jit
def decollide(x, y, vx, vy, px, w):
    """§7 DECOLLIDE: push the player out of platform ``(px, w)`` along the axis of least overlap.

    Returns the new ``(x, y, vx, vy)``. Platforms span y in [0, 40]; the player's y is in (-30, 40) here.
    """
    new_x = px - PLAYER_W if x < px else px + w if x > px + w - PLAYER_W else x
    new_y = -PLAYER_H if y < 0.0 else PLATFORM_HEIGHT if y > PLATFORM_HEIGHT - PLAYER_H else y
    if new_x == x:
        return x, new_y, vx, 0.0
    if new_y == y or abs(x - new_x) < abs(y - new_y):
        return new_x, y, 0.0, vy
    return x, new_y, vx, 0.0


@jit
def step(state, a, p, draws, cursor, trace):
    """One agent step ``(a, p)`` of one copy (§6), ``p`` already clipped into its box.

    ``state``: the copy's row, updated in place. ``draws[cursor:]``: standard normals, at least
    :data:`MAX_DRAWS` of them. ``trace``: ``(rows, TRACE_SIZE)``; sub-step k writes row k while
    ``k < rows`` (pass ``rows = 0`` to record nothing).

    Returns ``(reward, done, substeps, cursor)``: the step's reward (§7.8, the progress since the step's
    start), whether the episode ended (§7.9), the number of sub-steps run, and the next unused draw.
    """
    if cursor + MAX_DRAWS > draws.size:
        raise ValueError("step needs MAX_DRAWS numbers in draws after cursor")
    x, y, vx, vy = state[X], state[Y], state[VX], state[VY]
    x0 = x
    dy0 = HOP_DY0 if a == HOP else LEAP_DY0
    T = 2.0 * dy0 / GRAVITY + 1.0  # roughly the flight time, so p / T is a horizontal speed
    substeps = 0
    reward, done = 0.0, False
    while True:  # §6
        # §7.1-2: the action acts while the player stands on a platform; in the air, gravity does.
        standing = on_platform(x, y)
        if not standing:
            ax, ay = 0.0, -GRAVITY
        elif a == RUN:
            ax, ay = p / DT, 0.0
        else:  # JUMP(p, dy0, dev): the take-off impulse, only reachable within +-30 of vx.
            dx = clip(p / T - vx, -AX_MAX, VY_MAX - dy0)
            n0 = -abs(0.0 + JUMP_DEV * draws[cursor])  # §9 draw 1
            n1 = -abs(0.0 + JUMP_DEV * draws[cursor + 1])
            cursor += 2
            ax, ay = (dx + n0) / DT, (dy0 + n1) / DT
        # ACCEL(ax, ay): bounded acceleration for one sub-step, minus a |Gaussian| friction on vx.
        vx += clip(ax, -AX_MAX, AX_MAX) * DT
        vy += clip(ay, -AY_MAX, AY_MAX) * DT
        vx -= abs(0.0 + PLAYER_NOISE * draws[cursor])  # §9 draw 2
        vx = max(clip(vx, -VX_MAX, VX_MAX), 0.0)
        vy = clip(vy, -VY_MAX, VY_MAX)
        if standing:  # §7.3
            vx = clip(vx, 0.0, VX_GROUND)

        # §7.4-5: only the enemy of the player's half (decided before the player moves) moves.
        e = E2X if x > ENEMY2_FROM else E1X
        lo, hi = ENEMY_BOUNDS[1] if e == E2X else ENEMY_BOUNDS[0]
        x = clip(x + vx * DT, 0.0, X_GOAL)
        y += vy * DT
        vx *= DECAY

        # §7.6: the enemy turns round at the ends of its platform, with a little noise on its speed.
        ex, edx = state[e], state[e + 1]
        if not lo < ex < hi:
            edx = -edx
        edx += 0.0 + ENEMY_NOISE * draws[cursor + 1]  # §9 draw 3
        cursor += 2
        edx = clip(edx, -ENEMY_SPEED, ENEMY_SPEED)
        state[e], state[e + 1] = clip(ex + edx * DT, lo, hi), edx

        # §7.7: landing on (or bumping into) a platform; either way horizontal speed is lost. Only a
        # player below the walking surface can overlap a platform.
        if y < PLATFORM_HEIGHT:
            for px, w in PLATFORMS:
                if px - PLAYER_W < x < px + w and -PLAYER_H < y < PLATFORM_HEIGHT:
                    x, y, vx, vy = decollide(x, y, vx, vy, px, w)
                    vx = 0.0
        state[X], state[Y], state[VX], state[VY] = x, y, vx, vy

        # §7.8-9. At the goal x == 1035 exactly, so this is also the goal reward (1035 - x0) / 1035.
        reward = (x - x0) / X_GOAL
        fell = y < PLATFORM_HEIGHT
        hit = (abs(x - state[E1X]) < PLAYER_W or abs(x - state[E2X]) < PLAYER_W) and (
            PLATFORM_HEIGHT - PLAYER_H < y < PLATFORM_HEIGHT + PLAYER_H
        )
        done = fell or hit or x >= X_GOAL
        if substeps < trace.shape[0]:
            trace[substeps, 0], trace[substeps, 1] = x, y
            trace[substeps, 2], trace[substeps, 3] = state[E1X], state[E2X]
        substeps += 1
        # §6: run lasts 20 sub-steps; a jump lasts until the player stands on a platform again.
        if done or (substeps == RUN_SUBSTEPS if a == RUN else on_platform(x, y)):
            return reward, done, substeps, cursor


@jit
def step_copies(states, a, p, stepping, draws, cursors, rewards, terminated, substeps, trace):
    """:func:`step` for every copy ``i`` with ``stepping[i]``: row i of ``states``, ``draws`` and the
    other arrays is copy i's; ``cursors``, ``rewards``, ``terminated`` and ``substeps`` are written.
    Copy 0 records its sub-steps in ``trace`` (the scalar env's rendering; no rows: nothing)."""
    no_trace = trace[:0]
    for i in range(states.shape[0]):
        if stepping[i]:
            rewards[i], terminated[i], substeps[i], cursors[i] = step(
                states[i], a[i], p[i], draws[i], cursors[i], trace if i == 0 else no_trace
            )


@jit
def choose(a, params, out):
    """Each copy's parameter of its action ``a[i]``, ``params[a[i], i]``, clipped into its box, into ``out``.
    Returns the first action whose parameter column holds a number that is not finite (checked in every
    column, before anything is written), else -1."""
    for j in range(params.shape[0]):
        for i in range(params.shape[1]):
            if not math.isfinite(params[j, i]):
                return j
    for i in range(a.shape[0]):
        out[i] = clip(params[a[i], i], 0.0, PARAM_MAX[a[i]])
    return -1


@jit
def observe(states, out):
    """§4's 9 scaled features of each copy (row of ``states``) into the rows of ``out``.

    The active enemy is enemy 2 if x > 475 else enemy 1. The platform features switch at x = 475 and
    x = 985 (with ``<``, so a player who lands on platform 2 at 455 < x < 475 still sees platform 1's
    features, as in the reference).
    """
    for i in range(states.shape[0]):
        s = states[i]
        x = s[X]
        e = E2X if x > ENEMY2_FROM else E1X
        section = (1 if x >= PLATFORMS[1][0] else 0) + (1 if x >= PLATFORMS[2][0] else 0)
        raw = (x, s[VX], s[e], s[e + 1])
        for j in range(4):
            out[i, j] = (raw[j] + OBS_SHIFT[j]) / OBS_SCALE[j]
        for j in range(5):
            out[i, 4 + j] = (PLATFORM_FEATURES[section, j] + OBS_SHIFT[4 + j]) / OBS_SCALE[4 + j]
