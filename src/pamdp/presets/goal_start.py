"""Masson's hand-set start on Goal, and carried over to Hard Goal, as P-DQN's ``param_passthrough`` values.

Bester et al.'s Goal script (``run_goal_pdqn.py`` of cycraig/MP-DQN, ``initialise_params`` with ``scale_actions``)
starts its parameter network from Masson, Ranchod & Konidaris' hand-set linear map (AAAI 2016) of the observation
to the parameters, both in [-1, 1] units: so does the ``goal`` preset of :mod:`pamdp.presets.domains`. The map
reads Goal's observation layout (:data:`BALL_X` ...) and aims its shots through the env's own shot mapping.
"""

from __future__ import annotations

from pamdp.envs.goal.dynamics import HALF_GOAL, OBS_SIZE, hard_goal_shot

__all__ = ["MASSON_GOAL_START", "MASSON_HARD_GOAL_START", "linear_map"]

BALL_X, BALL_Y, KEEPER_TO_BALL_X, KEEPER_TO_BALL_Y = 10, 11, 14, 15
"""The features of Goal's observation Masson's kick reads: the ball's x, y and the unit vector from the keeper to
the ball (``pamdp.envs.goal.dynamics.observe``)."""
POST = HALF_GOAL - 1
"""Where Masson shoots: 1 m inside either post (y = +-6.01)."""


def linear_map(n_obs: int, rows: tuple[tuple[float, dict[int, float]], ...]) -> tuple[float, ...]:
    """A :attr:`~pamdp.algos.pdqn.PDQNConfig.param_passthrough` value from one ``(bias, {feature: weight})`` per
    parameter: each row the ``n_obs`` weights, then the bias."""
    return tuple(v for bias, weights in rows for v in (*(weights.get(i, 0.0) for i in range(n_obs)), bias))


# Masson's kick-to in metres is x = Bx + 2.5 + 1.25 f14, y = (5/6) By + (5/3) f15 (the port reads only x: it kicks
# towards (x, x)); in [-1, 1] units of the observation (Bx = 10 (f10 + 1), By = 15 f11) and of kick-to's box
# ([0, 40] x [-15, 15]) these rows.
_MASSON_KICK = ((-0.375, {BALL_X: 0.5, KEEPER_TO_BALL_X: 0.0625}), (0.0, {BALL_Y: 5 / 6, KEEPER_TO_BALL_Y: 1 / 9}))

MASSON_GOAL_START = linear_map(OBS_SIZE, (*_MASSON_KICK, (POST / HALF_GOAL, {}), (-POST / HALF_GOAL, {})))
"""Goal's parameters kick-to x, y; shoot-left y; shoot-right y, from Masson's start."""


def _hard_goal_aim(j: int, y: float) -> float:
    """The parameter of a Hard Goal shot into part ``j`` that aims at goal-line ``y``: the env's mapping is linear."""
    at_0, at_1 = hard_goal_shot(j, 0.0), hard_goal_shot(j, 1.0)
    return float((y - at_0) / (at_1 - at_0))


# Masson's start carried over to Hard Goal (not published): kick-to as on Goal; the shots into the goal mouth's
# outer parts (j = 0 and 4: actions 1, 6 and 5, 10) 1 m inside either post; the three inner parts at their middles.
_HARD_GOAL_SHOTS = (_hard_goal_aim(0, -POST), 0.0, 0.0, 0.0, _hard_goal_aim(4, POST))
MASSON_HARD_GOAL_START = linear_map(OBS_SIZE, (*_MASSON_KICK, *((p, {}) for p in _HARD_GOAL_SHOTS * 2)))
"""Hard Goal's parameters kick-to x, y, then the ten shots' (two of each of the five parts), from Masson's start."""
