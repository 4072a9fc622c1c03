"""A hand-written scorer for HFO 1v0, the reference row of the benchmarks (spec 2.12, item 8).

It reads only the observation: if the ball is kickable, KICK(100) towards the goal centre; else, if the
ball is more than 10 degrees off the body direction, TURN towards it; else DASH(100, 0). On the real
server this scores in almost every episode in about 70 steps.
"""

from __future__ import annotations

import numpy as np

from pamdp.envs.hfo.dynamics import BALL_COS, BALL_SIN, GOAL_COS, GOAL_SIN, KICKABLE

TURN_THRESHOLD = 10.0
"""Degrees off the body beyond which the scorer turns to the ball instead of dashing."""


def scripted_scorer_batch(obs: np.ndarray) -> tuple:
    """Actions for a batch of observations ``(N, n_features)``, in the batched env's format."""
    obs = np.asarray(obs, dtype=np.float64)
    ball = np.degrees(np.arctan2(obs[:, BALL_SIN], obs[:, BALL_COS]))
    goal = np.degrees(np.arctan2(obs[:, GOAL_SIN], obs[:, GOAL_COS]))
    kickable = obs[:, KICKABLE] > 0.0
    a = np.where(kickable, 2, np.where(np.abs(ball) > TURN_THRESHOLD, 1, 0))
    n = obs.shape[0]
    dash = np.tile(np.array([100.0, 0.0], dtype=np.float32), (n, 1))
    turn = ball[:, None].astype(np.float32)
    kick = np.stack([np.full(n, 100.0), goal], axis=1).astype(np.float32)
    return a, (dash, turn, kick)


def scripted_scorer(obs: np.ndarray) -> tuple:
    """The action for one observation, in the scalar env's format ``(a, (dash, turn, kick))``."""
    a, (dash, turn, kick) = scripted_scorer_batch(np.asarray(obs)[None])
    return int(a[0]), (dash[0], turn[0], kick[0])
