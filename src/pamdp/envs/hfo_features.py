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


def _unit(x, y):
    """Unit vector of (x, y) and its length; the zero vector's direction is heading 0, i.e. (1, 0)."""
    length = np.sqrt(x * x + y * y)  # not np.hypot: several times slower, and the scalar twin must agree
    nonzero = length > 0.0
    safe = np.where(nonzero, length, 1.0)
    return np.where(nonzero, x / safe, 1.0), np.where(nonzero, y / safe, 0.0), length


def _velocity_direction(x, y):
    """Like :func:`_unit`, but exact for velocities decayed to 1e-160 and below, whose squares underflow.

    (A held player's velocity decays by 0.4 per cycle for hundreds of cycles; HFO takes its direction
    with atan2, which has no such trouble.)
    """
    m = np.maximum(np.abs(x), np.abs(y))
    nonzero = m > 0.0
    safe = np.where(nonzero, m, 1.0)
    ux, uy, length = _unit(x / safe, y / safe)
    return np.where(nonzero, ux, 1.0), np.where(nonzero, uy, 0.0), length * m


def _scaled(x, lo, hi):
    """Spec 2.8's normalised scalar: [lo, hi] onto [-1, 1], clipping."""
    return 2.0 * (np.clip(x, lo, hi) - lo) / (hi - lo) - 1.0


def _proximity(d, n):
    """1 when touching, -1 at distance ``n`` or farther."""
    return 1.0 - 2.0 * np.clip(d / n, 0.0, 1.0)


def low_level_features(
    px, py, pvx, pvy, body, stamina, bx, by, bvx, bvy, kickable, collided_ball, collided_post, last_action_ok,
    profile: FeatureProfile,
) -> np.ndarray:  # fmt: skip
    """The ``(N, profile.n_features)`` float64 feature matrix of N states given as ``(N,)`` arrays.

    Angles are in degrees; flags are booleans (``kickable`` is the agent's own test, see
    ``HFOGame.agent_kickable``). Every feature lies in [-1, 1].
    """
    n = np.shape(px)[0]
    out = np.empty((n, profile.n_features))
    theta = np.radians(body)
    cos_t, sin_t = np.cos(theta), np.sin(theta)
    out[:, 0:2] = 1.0  # self position and velocity are valid under fullstate
    # Own velocity direction relative to the body, as body minus velocity heading (sign order of HFO).
    ux, uy, speed = _velocity_direction(pvx, pvy)
    out[:, 2] = sin_t * ux - cos_t * uy
    out[:, 3] = cos_t * ux + sin_t * uy
    out[:, 4] = _scaled(speed, 0.0, SELF_SPEED_MAX)
    out[:, 5] = sin_t
    out[:, 6] = cos_t
    out[:, 7] = _scaled(stamina, 0.0, STAMINA_MAX)
    out[:, 8] = -1.0  # frozen
    out[:, 9] = np.where(collided_ball, 1.0, -1.0)
    out[:, 10] = -1.0  # colliding with a player
    out[:, 11] = np.where(collided_post, 1.0, -1.0)
    # Landmarks and the ball: bearing heading(L - p) - body as (sin, cos), and proximity.
    targets_x = np.concatenate([np.broadcast_to(LANDMARKS[:, 0], (n, 11)), np.reshape(bx, (n, 1))], axis=1)
    targets_y = np.concatenate([np.broadcast_to(LANDMARKS[:, 1], (n, 11)), np.reshape(by, (n, 1))], axis=1)
    lx, ly, dist = _unit(targets_x - np.reshape(px, (n, 1)), targets_y - np.reshape(py, (n, 1)))
    c, s = cos_t[:, None], sin_t[:, None]
    bearing_sin, bearing_cos = ly * c - lx * s, lx * c + ly * s
    proximity = _proximity(dist, profile.max_dist)
    out[:, 12] = np.where(kickable, 1.0, -1.0)
    out[:, 13:46:3] = bearing_sin[:, :11]
    out[:, 14:46:3] = bearing_cos[:, :11]
    out[:, 15:46:3] = proximity[:, :11]
    out[:, 46] = _proximity(px, profile.oob_x)
    out[:, 47] = _proximity(PITCH_HALF_LENGTH - px, profile.oob_x)
    out[:, 48] = _proximity(PITCH_HALF_WIDTH + py, profile.oob_y)
    out[:, 49] = _proximity(PITCH_HALF_WIDTH - py, profile.oob_y)
    out[:, 50] = 1.0
    out[:, 51] = bearing_sin[:, 11]
    out[:, 52] = bearing_cos[:, 11]
    out[:, 53] = proximity[:, 11]
    out[:, 54] = 1.0
    vx, vy, ball_speed = _velocity_direction(bvx, bvy)
    out[:, 55] = _scaled(ball_speed, 0.0, BALL_SPEED_MAX)
    out[:, 56] = vy  # a ball at rest has heading 0: (sin, cos) = (0, 1)
    out[:, 57] = vx
    if profile.n_features > LAST_ACTION_OK:
        out[:, LAST_ACTION_OK] = np.where(last_action_ok, 1.0, -1.0)
    return out


def ball_to_goal(features: np.ndarray) -> np.ndarray:
    """2 d(ball, goal) / Dmax recovered from the features by the law of cosines, as H&S's code does."""
    ball_dist = 1.0 - features[:, BALL_PROXIMITY]
    goal_dist = 1.0 - features[:, GOAL_PROXIMITY]
    # cos(alpha_ball - alpha_goal) from the (sin, cos) pairs: the same number as H&S's
    # cos(atan2(...) - atan2(...)), without three transcendental calls per game.
    cos_alpha = features[:, BALL_COS] * features[:, GOAL_COS] + features[:, BALL_SIN] * features[:, GOAL_SIN]
    squared = ball_dist**2 + goal_dist**2 - 2.0 * ball_dist * goal_dist * cos_alpha
    return np.sqrt(np.maximum(squared, 0.0))


def shaped_reward(prev_features, features, holder, kick_bonus_due, goal) -> np.ndarray:
    """Hausknecht & Stone's reward between consecutive feature rows (spec 2.9), before the quirk flags.

    ``r = Δ ball proximity + 1[first time kickable] + 3 · (−Δ ball-to-goal, if the agent holds the ball)
    + 5 · 1[goal]``. ``kick_bonus_due`` says the kick bonus has not been paid yet this episode.
    Returns the reward and whether the kick bonus was paid now.
    """
    move_to_ball = features[:, BALL_PROXIMITY] - prev_features[:, BALL_PROXIMITY]
    kick_bonus = kick_bonus_due & (features[:, KICKABLE] - prev_features[:, KICKABLE] >= 1.0)
    kick_to_goal = np.where(holder, ball_to_goal(prev_features) - ball_to_goal(features), 0.0)
    reward = move_to_ball + kick_bonus + 3.0 * kick_to_goal + np.where(goal, 5.0, 0.0)
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
    for lx, ly in _LANDMARK_LIST + [(bx, by)]:
        dx, dy = lx - px, ly - py
        d = _norm(dx, dy)
        if d > 0.0:
            dx, dy = dx / d, dy / d
        else:
            dx, dy = 1.0, 0.0
        q = d / max_dist
        out += (dy * cos_t - dx * sin_t, dx * cos_t + dy * sin_t, 1.0 - 2.0 * q if q < 1.0 else -1.0)
    ball = out[46:49]  # the ball's bearing and proximity came last; they go after the OOB block
    del out[46:49]
    nx, ny = profile.oob_x, profile.oob_y
    for d, n in ((px, nx), (PITCH_HALF_LENGTH - px, nx), (PITCH_HALF_WIDTH + py, ny), (PITCH_HALF_WIDTH - py, ny)):
        out.append(1.0 - 2.0 * min(max(d / n, 0.0), 1.0))
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
