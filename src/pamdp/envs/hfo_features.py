"""HFO's LOW_LEVEL_FEATURE_SET for one agent, no teammates, no opponents, and H&S's shaped reward.

Spec sections 2.8 (features) and 2.9 (reward) of ``shared/specs/hfo.md``. Each comes twice: over
batches of NumPy arrays for the batched env, and in plain ``math`` for one state (``*_one``), because
NumPy's per-call overhead on length-1 arrays would make the scalar env ten times slower. The tests
check the two against each other.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from pamdp.envs.hfo_physics import (
    GOAL_HALF_WIDTH,
    PENALTY_AREA_HALF_WIDTH,
    PENALTY_AREA_X,
    PITCH_HALF_LENGTH,
    PITCH_HALF_WIDTH,
    STAMINA_MAX,
)


@dataclass(frozen=True)
class FeatureProfile:
    """The normalisers and size of one HFO release's low-level features (spec 2.8 "version profiles")."""

    n_features: int
    """58 before HFO added the last-action flag (Aug 2017), 59 since."""
    max_dist: float
    """Dmax, the proximity normaliser of landmarks and the ball."""
    oob_x: float
    """N_x, normaliser of the left/right out-of-bounds proximities."""
    oob_y: float
    """N_y, normaliser of the top/bottom out-of-bounds proximities."""


_DMAX_2016 = float(np.hypot(PITCH_HALF_LENGTH, PITCH_HALF_WIDTH))  # 62.548
_DMAX_2018 = float(np.hypot(PITCH_HALF_LENGTH, 2.0 * PITCH_HALF_WIDTH))  # 85.908

PROFILES = {
    "hfo2016": FeatureProfile(58, _DMAX_2016, 52.5, 68.0),  # Hausknecht & Stone 2016
    "hfo2017": FeatureProfile(59, _DMAX_2016, 52.5, 68.0),  # Wei, Wicke & Luke 2018 (the seed paper)
    "hfo2019": FeatureProfile(59, _DMAX_2018, 1.1 * 52.5, 1.05 * 68.0),  # HFO master since March 2019
}

#: Feature indices the reward reads (spec 2.9).
KICKABLE, GOAL_SIN, GOAL_COS, GOAL_PROXIMITY = 12, 13, 14, 15
BALL_SIN, BALL_COS, BALL_PROXIMITY = 51, 52, 53
LAST_ACTION_OK = 58

#: Landmarks of features 13-45, in order: goal centre, goal posts top/bottom, penalty box centre and
#: top/bottom corners, "center field", corners top-left, top-right, bottom-right, bottom-left.
LANDMARKS = np.array(
    [
        (PITCH_HALF_LENGTH, 0.0),
        (PITCH_HALF_LENGTH, -GOAL_HALF_WIDTH),
        (PITCH_HALF_LENGTH, GOAL_HALF_WIDTH),
        (PENALTY_AREA_X, 0.0),
        (PENALTY_AREA_X, -PENALTY_AREA_HALF_WIDTH),
        (PENALTY_AREA_X, PENALTY_AREA_HALF_WIDTH),
        (0.0, 0.0),
        (0.0, -PITCH_HALF_WIDTH),
        (PITCH_HALF_LENGTH, -PITCH_HALF_WIDTH),
        (PITCH_HALF_LENGTH, PITCH_HALF_WIDTH),
        (0.0, PITCH_HALF_WIDTH),
    ]
)
SELF_SPEED_MAX = 0.46
BALL_SPEED_MAX = 5.0


def _directions(x, y, work, one, tiny):
    """Unit vectors of the velocities (x, y) and their lengths; the zero vector's direction is (1, 0).

    Exact for velocities decayed to 1e-160 and below, whose squares underflow: the components are first
    divided by the larger one. (A held player's velocity decays by 0.4 per cycle for hundreds of
    cycles; HFO takes its direction with atan2, which has no such trouble.) ``work``, shape
    ``(5,) + x.shape``, holds the temporaries and the three results; ``one`` and ``tiny`` are arrays
    of 1 and of the smallest positive float, of the shape of ``x``.
    """
    unit, length, m, t = work[:2], work[2], work[3], work[4]
    ux, uy = work[0], work[1]
    np.abs(x, out=ux)
    np.abs(y, out=uy)
    np.maximum(ux, uy, out=m)
    any_zero = not m.min() > 0.0
    if any_zero:  # max(m, tiny) is m but for the zero vectors, whose 0 / tiny is 0 as 0 / 1 is
        np.divide(x, np.maximum(m, tiny, out=t), out=ux)
        np.divide(y, t, out=uy)
    else:
        np.divide(x, m, out=ux)
        np.divide(y, m, out=uy)
    np.multiply(ux, ux, out=length)
    np.multiply(uy, uy, out=t)
    length += t
    np.sqrt(length, out=length)  # >= 1 where m > 0: the larger component is now +-1
    if any_zero:
        unit /= np.maximum(length, one, out=t)  # the zero vectors' length 0 divides by 1
        # putmask: a third of the cost of boolean-index assignment
        zero = m == 0.0
        np.putmask(ux, zero, 1.0)
        np.putmask(uy, zero, 0.0)
    else:
        unit /= length
    length *= m
    return ux, uy, length


_LANDMARK_X, _LANDMARK_Y = LANDMARKS[:, :1].copy(), LANDMARKS[:, 1:].copy()
_CONSTANT_ROWS = ((0, 1.0), (1, 1.0), (8, -1.0), (10, -1.0), (50, 1.0), (54, 1.0))
_SPEED_MAX = np.array([[SELF_SPEED_MAX], [BALL_SPEED_MAX]])


class _Operands(NamedTuple):
    """Read-only arrays for N games that :func:`feature_rows` clips against, divides by or subtracts
    from. ``np.minimum`` and ``np.maximum`` run two to four times slower against a scalar than against
    an array of the same shape, and an operation with a column broadcast along the rows a third to
    half as fast."""

    neg_two: np.ndarray  # 12 rows
    zeros: np.ndarray  # 4 rows
    stamina_max: np.ndarray
    speed_max: np.ndarray  # own, ball
    one: np.ndarray  # 2 rows
    tiny: np.ndarray  # 2 rows of the smallest positive float
    speed_halves: np.ndarray  # half the speed caps
    oob_divisors: np.ndarray  # minus half the out-of-bounds normalisers
    landmark_x: np.ndarray  # 11 rows
    landmark_y: np.ndarray


@functools.lru_cache(maxsize=8)
def _operands(n: int, profile: FeatureProfile) -> _Operands:
    rows = np.empty((51, n))
    rows[:12] = -2.0
    rows[12:16] = 0.0
    rows[16] = STAMINA_MAX
    rows[17:19] = _SPEED_MAX
    rows[19:21] = 1.0
    rows[21:23] = np.nextafter(0.0, 1.0)
    rows[23:25] = _SPEED_MAX / 2.0
    rows[25:29] = -0.5 * np.array([[profile.oob_x], [profile.oob_x], [profile.oob_y], [profile.oob_y]])
    rows[29:40] = _LANDMARK_X
    rows[40:51] = _LANDMARK_Y
    rows.flags.writeable = False
    return _Operands(
        rows[:12], rows[12:16], rows[16], rows[17:19], rows[19:21], rows[21:23], rows[23:25], rows[25:29],
        rows[29:40], rows[40:51],
    )  # fmt: skip


def constant_rows(out: np.ndarray) -> np.ndarray:
    """Write the features that are the same in every state (no teammates, no opponents) into the rows
    of ``out``, shape ``(n_features, N)``."""
    for row, value in _CONSTANT_ROWS:
        out[row] = value
    return out


def feature_rows(
    px, py, bx, by, vx, vy, stamina, cos_t, sin_t, kickable, collided_ball, collided_post, last_action_ok,
    profile: FeatureProfile, out: np.ndarray, scratch: np.ndarray | None = None, constants: bool = True,
) -> np.ndarray:  # fmt: skip
    """The features of N states as the rows of ``out``, shape ``(profile.n_features, N)``, float64.

    The batched env's layout: one contiguous row per feature, so every operation runs over N games
    at once. ``vx, vy`` hold the player's (row 0) and the ball's (row 1) velocity, shape ``(2, N)``;
    ``cos_t, sin_t`` are the cosine and sine of the body angle (the caller keeps them from one turn to
    the next); the rest as :func:`low_level_features`. Every number equals the scalar twin's.
    ``scratch``, shape ``(5, 12, N)``, saves allocating the temporaries on each call;
    ``constants=False`` leaves the constant rows as they are (a caller reusing ``out`` wrote them).

    The normalisations ``2 v / hi - 1`` and ``1 - 2 min(q, 1)`` divide by ``hi / 2`` and ``-n / 2``
    instead of doubling: halving the divisor is exact, so ``v / (hi / 2)`` is the same rounding of
    the same quotient as ``(2 v) / hi``, and ``d / (-n / 2)`` is ``-2 (d / n)`` except below 1e-300,
    where adding 1 gives 1 either way.
    """
    n = px.shape[0]
    if scratch is None:
        scratch = np.empty((5, 12, n))
    ops = _operands(n, profile)
    if constants:
        constant_rows(out)
    # The flags as 2 f - 1. Rows 9 to 12 in one pass: row 10 (constant -1) is set to 0 for it.
    flags = out[9:13]
    np.copyto(flags[0], collided_ball)
    flags[1] = 0.0
    np.copyto(flags[2], collided_post)
    np.copyto(flags[3], kickable)
    flags *= 2.0
    flags -= 1.0
    if LAST_ACTION_OK < profile.n_features:
        np.multiply(last_action_ok, 2.0, out=out[LAST_ACTION_OK])
        out[LAST_ACTION_OK] -= 1.0
    out[5], out[6] = sin_t, cos_t
    # Own and ball velocity in one pass: direction and speed (its temporaries in the scratch's first
    # two rows, free until the landmarks).
    ux, uy, speed = _directions(vx, vy, scratch[:, :2], ops.one, ops.tiny)
    # Own velocity direction relative to the body, as body minus velocity heading (sign order of HFO).
    t = scratch[3, 0]
    np.multiply(sin_t, ux[0], out=out[2])
    np.multiply(cos_t, uy[0], out=t)
    out[2] -= t
    np.multiply(cos_t, ux[0], out=out[3])
    np.multiply(sin_t, uy[0], out=t)
    out[3] += t
    stamina_row = out[7]
    np.maximum(stamina, ops.zeros[0], out=stamina_row)
    np.minimum(stamina_row, ops.stamina_max, out=stamina_row)
    stamina_row /= STAMINA_MAX / 2.0
    stamina_row -= 1.0
    # The speeds are lengths, never negative: no lower clip.
    speed_rows = out[4:56:51]
    np.minimum(speed, ops.speed_max, out=speed_rows)
    speed_rows /= ops.speed_halves
    speed_rows -= 1.0
    out[56], out[57] = uy[1], ux[1]  # a ball at rest has heading 0: (sin, cos) = (0, 1)
    # Landmarks (rows 0-10) and the ball (row 11): bearing heading(L - p) - body as (sin, cos), proximity.
    # dx and dy side by side, so that each step below is one call for both.
    d, products, dist = scratch[:2], scratch[2:4], scratch[4]
    dx, dy = d[0], d[1]
    np.subtract(ops.landmark_x, px, out=dx[:11])
    np.subtract(bx, px, out=dx[11])
    np.subtract(ops.landmark_y, py, out=dy[:11])
    np.subtract(by, py, out=dy[11])
    np.multiply(d, d, out=products)
    np.add(products[0], products[1], out=dist)
    np.sqrt(dist, out=dist)
    if dist.min() > 0.0:
        d /= dist
    else:  # the player exactly on a landmark or the ball: heading 0
        zero = dist == 0.0
        d /= np.add(dist, zero, out=products[0])
        np.putmask(dx, zero, 1.0)
        np.putmask(dy, zero, 0.0)
    np.multiply(d, cos_t, out=products)
    dx_cos, dy_cos = products[0], products[1]
    np.multiply(d, sin_t, out=d)
    dx_sin, dy_sin = d[0], d[1]
    np.subtract(dy_cos[:11], dx_sin[:11], out=out[13:46:3])
    np.subtract(dy_cos[11], dx_sin[11], out=out[51])
    np.add(dx_cos[:11], dy_sin[:11], out=out[14:46:3])
    np.add(dx_cos[11], dy_sin[11], out=out[52])
    dist /= -profile.max_dist / 2.0  # -2 q, then 1 + max(-2 q, -2); q >= 0 already
    np.maximum(dist, ops.neg_two, out=dist)
    np.add(dist[:11], 1.0, out=out[15:46:3])
    np.add(dist[11], 1.0, out=out[53])
    # Out-of-bounds proximities, 1 - 2 clip(q, 0, 1) as 1 + clip(-2 q, -2, 0).
    oob = out[46:50]
    oob[0] = px
    np.subtract(PITCH_HALF_LENGTH, px, out=oob[1])
    np.add(PITCH_HALF_WIDTH, py, out=oob[2])
    np.subtract(PITCH_HALF_WIDTH, py, out=oob[3])
    oob /= ops.oob_divisors
    np.minimum(oob, ops.zeros, out=oob)
    np.maximum(oob, ops.neg_two[:4], out=oob)
    oob += 1.0
    return out


def low_level_features(
    px, py, pvx, pvy, body, stamina, bx, by, bvx, bvy, kickable, collided_ball, collided_post, last_action_ok,
    profile: FeatureProfile,
) -> np.ndarray:  # fmt: skip
    """The ``(N, profile.n_features)`` float64 feature matrix of N states given as ``(N,)`` arrays.

    Angles are in degrees; flags are booleans (``kickable`` is the agent's own test, see
    ``HFOGame.agent_kickable``). Every feature lies in [-1, 1].
    """
    theta = np.radians(body)
    rows = np.empty((profile.n_features, np.shape(px)[0]))
    feature_rows(
        px, py, bx, by, np.stack((pvx, bvx)), np.stack((pvy, bvy)), stamina, np.cos(theta), np.sin(theta),
        kickable, collided_ball, collided_post, last_action_ok, profile, rows,
    )  # fmt: skip
    return rows.T


def ball_to_goal_rows(rows: np.ndarray) -> np.ndarray:
    """2 d(ball, goal) / Dmax recovered from feature rows by the law of cosines, as H&S's code does."""
    ball_dist = 1.0 - rows[BALL_PROXIMITY]
    goal_dist = 1.0 - rows[GOAL_PROXIMITY]
    # cos(alpha_ball - alpha_goal) from the (sin, cos) pairs: the same number as H&S's
    # cos(atan2(...) - atan2(...)), without three transcendental calls per game.
    cos_alpha = rows[BALL_COS] * rows[GOAL_COS]
    cos_alpha += rows[BALL_SIN] * rows[GOAL_SIN]
    squared = ball_dist * ball_dist
    squared += goal_dist * goal_dist
    ball_dist *= 2.0
    ball_dist *= goal_dist
    ball_dist *= cos_alpha
    squared -= ball_dist
    np.maximum(squared, 0.0, out=squared)
    return np.sqrt(squared, out=squared)


def ball_to_goal(features: np.ndarray) -> np.ndarray:
    """:func:`ball_to_goal_rows` of a ``(N, n_features)`` feature matrix."""
    return ball_to_goal_rows(features.T)


def shaped_reward(prev_rows, rows, holder, kick_bonus_due, goal, prev_to_goal, to_goal) -> np.ndarray:
    """Hausknecht & Stone's reward between consecutive feature rows (spec 2.9), before the quirk flags.

    ``r = Δ ball proximity + 1[first time kickable] + 3 · (−Δ ball-to-goal, if the agent holds the ball)
    + 5 · 1[goal]``. ``kick_bonus_due`` says the kick bonus has not been paid yet this episode;
    ``prev_to_goal, to_goal`` are :func:`ball_to_goal_rows` of the two rows (the env keeps the last).
    Returns the reward and whether the kick bonus was paid now.
    """
    reward = rows[BALL_PROXIMITY] - prev_rows[BALL_PROXIMITY]
    kick_bonus = kick_bonus_due & (rows[KICKABLE] - prev_rows[KICKABLE] >= 1.0)
    reward += kick_bonus
    kick_to_goal = np.where(holder, prev_to_goal - to_goal, 0.0)
    kick_to_goal *= 3.0
    reward += kick_to_goal
    reward += np.where(goal, 5.0, 0.0)
    return reward, kick_bonus


def _norm(x: float, y: float) -> float:
    return math.sqrt(x * x + y * y)


def _velocity_direction_one(x: float, y: float) -> tuple[float, float, float]:
    """:func:`_directions` for one vector: (unit x, unit y, length)."""
    ax, ay = abs(x), abs(y)
    m = ay if ay > ax else ax  # max(ax, ay), without the builtin's call (see low_level_features_one)
    if m == 0.0:
        return 1.0, 0.0, 0.0
    x, y = x / m, y / m
    length = math.sqrt(x * x + y * y)
    return x / length, y / length, length * m


_LANDMARK_LIST = [tuple(float(c) for c in xy) for xy in LANDMARKS]


def low_level_features_one(seen, kickable, collided_ball, collided_post, last_action_ok, profile) -> list:
    """:func:`low_level_features` for one state; ``seen = (px, py, pvx, pvy, body, stamina, bx, by, bvx, bvy)``.

    Written out with few function calls: this is the scalar env's hot path. The clips are conditionals
    rather than ``min`` and ``max``, whose calls on Python 3.11 cost several times the comparison; each
    keeps the builtin's comparison (``min(v, hi)`` is ``hi if hi < v else v``), so the numbers are the same.
    """
    px, py, pvx, pvy, body, stamina, bx, by, bvx, bvy = seen
    theta = math.radians(body)
    cos_t, sin_t = math.cos(theta), math.sin(theta)
    ux, uy, speed = _velocity_direction_one(pvx, pvy)
    if SELF_SPEED_MAX < speed:
        speed = SELF_SPEED_MAX
    if 0.0 > stamina:
        stamina = 0.0
    if STAMINA_MAX < stamina:
        stamina = STAMINA_MAX
    out = [
        1.0,
        1.0,
        sin_t * ux - cos_t * uy,  # body minus velocity heading
        cos_t * ux + sin_t * uy,
        2.0 * speed / SELF_SPEED_MAX - 1.0,
        sin_t,
        cos_t,
        2.0 * stamina / STAMINA_MAX - 1.0,
        -1.0,
        1.0 if collided_ball else -1.0,
        -1.0,
        1.0 if collided_post else -1.0,
        1.0 if kickable else -1.0,
    ]
    max_dist = profile.max_dist
    sqrt = math.sqrt
    for lx, ly in _LANDMARK_LIST:
        dx, dy = lx - px, ly - py
        d = sqrt(dx * dx + dy * dy)
        if d > 0.0:
            dx, dy = dx / d, dy / d
        else:
            dx, dy = 1.0, 0.0
        q = d / max_dist
        out += (dy * cos_t - dx * sin_t, dx * cos_t + dy * sin_t, 1.0 - 2.0 * q if q < 1.0 else -1.0)
    nx, ny = profile.oob_x, profile.oob_y
    for q in (px / nx, (PITCH_HALF_LENGTH - px) / nx, (PITCH_HALF_WIDTH + py) / ny, (PITCH_HALF_WIDTH - py) / ny):
        out.append(1.0 - 2.0 * (0.0 if 0.0 > q else 1.0 if 1.0 < q else q))  # min(max(q, 0), 1)
    # The ball, as a landmark, after the out-of-bounds block.
    dx, dy = bx - px, by - py
    d = sqrt(dx * dx + dy * dy)
    if d > 0.0:
        dx, dy = dx / d, dy / d
    else:
        dx, dy = 1.0, 0.0
    q = d / max_dist
    ball = (dy * cos_t - dx * sin_t, dx * cos_t + dy * sin_t, 1.0 - 2.0 * q if q < 1.0 else -1.0)
    out.append(1.0)
    out += ball
    out.append(1.0)
    bvx, bvy, ball_speed = _velocity_direction_one(bvx, bvy)
    out += (
        2.0 * (BALL_SPEED_MAX if BALL_SPEED_MAX < ball_speed else ball_speed) / BALL_SPEED_MAX - 1.0,
        bvy,
        bvx,
    )
    if profile.n_features > LAST_ACTION_OK:
        out.append(1.0 if last_action_ok else -1.0)
    return out


def _ball_to_goal_one(f) -> float:
    ball_dist, goal_dist = 1.0 - f[BALL_PROXIMITY], 1.0 - f[GOAL_PROXIMITY]
    cos_alpha = f[BALL_COS] * f[GOAL_COS] + f[BALL_SIN] * f[GOAL_SIN]
    squared = ball_dist**2 + goal_dist**2 - 2.0 * ball_dist * goal_dist * cos_alpha
    return math.sqrt(max(squared, 0.0))


def shaped_reward_one(prev, features, holder: bool, kick_bonus_due: bool, goal: bool) -> tuple[float, bool]:
    """:func:`shaped_reward` for one pair of feature lists."""
    move_to_ball = features[BALL_PROXIMITY] - prev[BALL_PROXIMITY]
    kick_bonus = kick_bonus_due and features[KICKABLE] - prev[KICKABLE] >= 1.0
    kick_to_goal = _ball_to_goal_one(prev) - _ball_to_goal_one(features) if holder else 0.0
    return move_to_ball + kick_bonus + 3.0 * kick_to_goal + (5.0 if goal else 0.0), kick_bonus
