"""HFO's LOW_LEVEL_FEATURE_SET for one agent, no teammates, no opponents, and H&S's shaped reward.

Spec sections 2.8 (features) and 2.9 (reward) of ``shared/specs/hfo.md``. Each comes twice: over
batches of NumPy arrays for the batched env, and in plain ``math`` for one state (``*_one``), because
NumPy's per-call overhead on length-1 arrays would make the scalar env ten times slower. The tests
check the two against each other.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

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


def _directions(x, y):
    """Unit vectors of the velocities (x, y) and their lengths; the zero vector's direction is (1, 0).

    Exact for velocities decayed to 1e-160 and below, whose squares underflow: the components are first
    divided by the larger one. (A held player's velocity decays by 0.4 per cycle for hundreds of
    cycles; HFO takes its direction with atan2, which has no such trouble.)
    """
    m = np.maximum(np.abs(x), np.abs(y))
    any_zero = not m.min() > 0.0
    zero = m == 0.0 if any_zero else None
    safe = m + zero if any_zero else m  # m + 0.0 is m: only the zero vectors divide by 1
    ux, uy = x / safe, y / safe
    length = ux * ux
    length += uy * uy
    np.sqrt(length, out=length)  # >= 1 where m > 0: the larger component is now +-1
    if any_zero:
        np.add(length, zero, out=safe)
        ux /= safe
        uy /= safe
        ux[zero], uy[zero] = 1.0, 0.0
    else:
        ux /= length
        uy /= length
    length *= m
    return ux, uy, length


def _scaled_into(x, hi, out):
    """Spec 2.8's normalised scalar for lo = 0: [0, hi] onto [-1, 1], clipping, written to ``out``."""
    np.maximum(x, 0.0, out=out)
    np.minimum(out, hi, out=out)
    out *= 2.0
    out /= hi
    out -= 1.0


def _proximity_into(q, out=None):
    """1 when touching, -1 at distance ``n`` or farther, from ``q = d / n`` (overwritten unless ``out``)."""
    out = q if out is None else out
    np.maximum(q, 0.0, out=out)
    np.minimum(out, 1.0, out=out)
    out *= -2.0  # 1 - 2q and 1 + (-2q) are the same number: negation and doubling are exact
    out += 1.0
    return out


_LANDMARK_X, _LANDMARK_Y = LANDMARKS[:, :1].copy(), LANDMARKS[:, 1:].copy()
_FLAG_ROWS = (9, 11, 12, LAST_ACTION_OK)
_CONSTANT_ROWS = ((0, 1.0), (1, 1.0), (8, -1.0), (10, -1.0), (50, 1.0), (54, 1.0))
_SPEED_NORMALISERS = np.array([[SELF_SPEED_MAX], [BALL_SPEED_MAX]])


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
    ``scratch``, shape ``(5, 12, N)``, saves allocating the landmark temporaries on each call;
    ``constants=False`` leaves the constant rows as they are (a caller reusing ``out`` wrote them).
    """
    if constants:
        constant_rows(out)
    for row, flag in zip(_FLAG_ROWS, (collided_ball, collided_post, kickable, last_action_ok)):
        if row < profile.n_features:
            np.multiply(flag, 2.0, out=out[row])
            out[row] -= 1.0
    out[5], out[6] = sin_t, cos_t
    # Own and ball velocity in one pass: direction and speed.
    ux, uy, speed = _directions(vx, vy)
    # Own velocity direction relative to the body, as body minus velocity heading (sign order of HFO).
    np.multiply(sin_t, ux[0], out=out[2])
    out[2] -= cos_t * uy[0]
    np.multiply(cos_t, ux[0], out=out[3])
    out[3] += sin_t * uy[0]
    _scaled_into(stamina, STAMINA_MAX, out[7])
    # The speeds are lengths, never negative: the lower clip of _scaled_into is skipped.
    np.minimum(speed[0], SELF_SPEED_MAX, out=out[4])
    np.minimum(speed[1], BALL_SPEED_MAX, out=out[55])
    speed_rows = out[4:56:51]
    speed_rows *= 2.0
    speed_rows /= _SPEED_NORMALISERS
    speed_rows -= 1.0
    out[56], out[57] = uy[1], ux[1]  # a ball at rest has heading 0: (sin, cos) = (0, 1)
    # Landmarks (rows 0-10) and the ball (row 11): bearing heading(L - p) - body as (sin, cos), proximity.
    n = px.shape[0]
    dx, dy, dist, a, b = np.empty((5, 12, n)) if scratch is None else scratch
    np.subtract(_LANDMARK_X, px, out=dx[:11])
    np.subtract(bx, px, out=dx[11])
    np.subtract(_LANDMARK_Y, py, out=dy[:11])
    np.subtract(by, py, out=dy[11])
    np.multiply(dx, dx, out=dist)
    np.multiply(dy, dy, out=b)
    dist += b
    np.sqrt(dist, out=dist)
    zero = None if dist.min() > 0.0 else dist == 0.0
    safe = dist if zero is None else dist + zero
    dx /= safe
    dy /= safe
    if zero is not None:  # the player exactly on a landmark or the ball: heading 0
        dx[zero], dy[zero] = 1.0, 0.0
    np.multiply(dy, cos_t, out=a)
    np.multiply(dx, sin_t, out=b)
    np.subtract(a[:11], b[:11], out=out[13:46:3])
    np.subtract(a[11], b[11], out=out[51])
    np.multiply(dx, cos_t, out=a)
    np.multiply(dy, sin_t, out=b)
    np.add(a[:11], b[:11], out=out[14:46:3])
    np.add(a[11], b[11], out=out[52])
    dist /= profile.max_dist  # then 1 - 2 min(q, 1) as _proximity_into, q >= 0 already
    np.minimum(dist, 1.0, out=dist)
    dist *= -2.0
    np.add(dist[:11], 1.0, out=out[15:46:3])
    np.add(dist[11], 1.0, out=out[53])
    # Out-of-bounds proximities.
    oob = out[46:50]
    oob[0] = px
    np.subtract(PITCH_HALF_LENGTH, px, out=oob[1])
    np.add(PITCH_HALF_WIDTH, py, out=oob[2])
    np.subtract(PITCH_HALF_WIDTH, py, out=oob[3])
    oob /= np.array([[profile.oob_x], [profile.oob_x], [profile.oob_y], [profile.oob_y]])
    _proximity_into(oob)
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
    """:func:`_velocity_direction` for one vector: (unit x, unit y, length)."""
    m = max(abs(x), abs(y))
    if m == 0.0:
        return 1.0, 0.0, 0.0
    x, y = x / m, y / m
    length = math.sqrt(x * x + y * y)
    return x / length, y / length, length * m


_LANDMARK_LIST = [tuple(float(c) for c in xy) for xy in LANDMARKS]


def low_level_features_one(seen, kickable, collided_ball, collided_post, last_action_ok, profile) -> list:
    """:func:`low_level_features` for one state; ``seen = (px, py, pvx, pvy, body, stamina, bx, by, bvx, bvy)``.

    Written out with few function calls: this is the scalar env's hot path.
    """
    px, py, pvx, pvy, body, stamina, bx, by, bvx, bvy = seen
    theta = math.radians(body)
    cos_t, sin_t = math.cos(theta), math.sin(theta)
    ux, uy, speed = _velocity_direction_one(pvx, pvy)
    out = [
        1.0,
        1.0,
        sin_t * ux - cos_t * uy,  # body minus velocity heading
        cos_t * ux + sin_t * uy,
        2.0 * min(speed, SELF_SPEED_MAX) / SELF_SPEED_MAX - 1.0,
        sin_t,
        cos_t,
        2.0 * min(max(stamina, 0.0), STAMINA_MAX) / STAMINA_MAX - 1.0,
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
    for d, n in ((px, nx), (PITCH_HALF_LENGTH - px, nx), (PITCH_HALF_WIDTH + py, ny), (PITCH_HALF_WIDTH - py, ny)):
        out.append(1.0 - 2.0 * min(max(d / n, 0.0), 1.0))
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
        2.0 * min(ball_speed, BALL_SPEED_MAX) / BALL_SPEED_MAX - 1.0,
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
