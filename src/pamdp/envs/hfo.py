"""Half Field Offense 1v0 (empty goal) with HFO's low-level actions, features and shaped reward.

``pamdp/HalfFieldOffense-v0`` simulates the RoboCup 2D soccer server as HFO runs it (``--fullstate``,
one offense agent, no goalie; ``shared/specs/hfo.md``): the physics are in ``hfo_physics.py``, the
features and reward in ``hfo_features.py``, the batched NumPy version in ``hfo_vector.py``. A test
replays recordings of the real server (``tests/test_hfo_traces.py``).

Actions are ``(a, (dash, turn, kick))`` with ``a`` in {0: DASH, 1: TURN, 2: KICK}; only the chosen
action's parameters are read, in HFO's units:

- DASH(power in [0, 100], direction in [-180, 180] degrees off the body, rounded to a multiple of 45),
- TURN(direction in [-180, 180]), compensated for the player's speed as HFO's agent does,
- KICK(power in [0, 100], direction in [-180, 180]), silently dropped when the ball is not kickable.

Finite parameters outside those boxes are handled as HFO handles them: dash power is clamped to
[-100, 100] (negative power dashes backwards at twice the stamina cost), kick power to [0, 100], and
directions to [-180, 180]. Malformed or non-finite actions raise ``ValueError``.
"""

from __future__ import annotations

import math
import struct

import gymnasium
import numpy as np
from gymnasium import spaces

from pamdp.envs import hfo_physics as phys
from pamdp.envs.hfo_features import PROFILES, low_level_features_one, shaped_reward_one
from pamdp.envs.hfo_interface import (
    ACTION_FORM,
    ACTION_NAMES,
    PARAM_SIZES,
    check_options,
    draw_half_field,
    hfo_action_space,
    parse_reset_options,
)
from pamdp.envs.hfo_physics import GOAL, IN_GAME, OUT_OF_BOUNDS, OUT_OF_TIME, STATUS_NAMES, HFOGame
from pamdp.envs.hfo_vector import HalfFieldOffenseVectorEnv

__all__ = ["HalfFieldOffenseEnv", "HalfFieldOffenseVectorEnv", "hfo_action_space"]


class HalfFieldOffenseEnv(gymnasium.Env):
    """HFO 1v0: score on an empty goal from a random start, with HFO's low-level actions and features.

    Args:
        render_mode: ``None`` or ``"rgb_array"`` (the half field from above).
        profile: feature set of an HFO release (spec 2.8): ``"hfo2016"`` (58 features, Hausknecht &
            Stone), ``"hfo2017"`` (59, the seed paper's; default) or ``"hfo2019"`` (59, current HFO
            normalisers). The reward reads the features, so it scales with the profile's Dmax.
        deterministic: zero the actuator noise (HFO's ``--deterministic``); placements stay random.
        timeout_terminal: report OUT_OF_TIME as ``terminated`` (as dqn-hfo and MP-DQN treated it)
            instead of ``truncated``. The untouched and trial clocks are not in the observation, so by
            default they count as truncation.
        body_reset: ``"carry"`` keeps the body angle from the end of the previous episode, as the real
            server does (the first episode faces the goal, and so does a reset with a seed, so that a
            seed reproduces an episode); ``"uniform"`` draws it in (-180, 180].
        first_step_reward: difference the first transition against the reset state. H&S's and
            gym-soccer's code start differencing after the first action, so by default the first
            transition pays only the goal bonus.
        terminal_deltas: pay the distance and kick terms on the terminal transition too. dqn-hfo zeroes
            them (only +5 for a goal survives), which is the default.

    ``info`` holds ``status`` ("IN_GAME", "GOAL", "OUT_OF_BOUNDS" or "OUT_OF_TIME") and ``step``, the
    number of actions taken this episode. The observation returned with a terminal status is the true
    terminal state. ``reset(options=...)`` accepts ``ball`` (x, y), ``player`` (x, y) and ``body``
    (degrees), in the server's metres (goal centre at (52.5, 0)); missing ones are drawn as usual.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(
        self,
        render_mode: str | None = None,
        profile: str = "hfo2017",
        deterministic: bool = False,
        timeout_terminal: bool = False,
        body_reset: str = "carry",
        first_step_reward: bool = False,
        terminal_deltas: bool = False,
    ):
        check_options(profile, body_reset)
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode={render_mode!r}; expected None or 'rgb_array'")
        self.render_mode = render_mode
        self.profile = PROFILES[profile]
        self.profile_name = profile
        self.deterministic = bool(deterministic)
        self.timeout_terminal = bool(timeout_terminal)
        self.body_reset = body_reset
        self.first_step_reward = bool(first_step_reward)
        self.terminal_deltas = bool(terminal_deltas)
        n = self.profile.n_features
        self.observation_space = spaces.Box(-1.0, 1.0, (n,), dtype=np.float32)
        self._pack_observation = struct.Struct(f"{n}f").pack_into
        self.action_space = hfo_action_space()
        self.game = HFOGame(self.np_random, deterministic=self.deterministic)
        self._steps = 0
        self._features = self._observe()
        self._kick_bonus_paid = False

    # --- Gymnasium API ------------------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        placement = parse_reset_options(options)
        game = self.game
        game.set_rng(self.np_random)  # a seed replaces the generator
        bx, by, px, py = game.draw_placement()
        if seed is not None:
            game.body = 0.0  # a seed starts a new server run, whose first episode faces the goal
        if self.body_reset == "uniform":
            game.body = phys.normalize_angle(360.0 * self.np_random.random() - 180.0)
        if "ball" in placement:
            bx, by = placement["ball"]
        if "player" in placement:
            px, py = placement["player"]
        if "body" in placement:
            game.body = phys.normalize_angle(float(placement["body"]))
        game.place(float(bx), float(by), float(px), float(py))
        self._steps = 0
        self._kick_bonus_paid = False
        self._features = self._observe()
        return self._observation(self._features), {"status": "IN_GAME", "step": 0}

    def step(self, action):
        a, x0, x1 = self._parse_action(action)
        game = self.game
        game.act(a, x0, x1)
        status = game.advance()
        self._steps += 1
        prev, features = self._features, self._observe()
        self._features = features
        goal = status == GOAL
        if (status != IN_GAME and not self.terminal_deltas) or (self._steps == 1 and not self.first_step_reward):
            reward = 5.0 if goal else 0.0
        else:
            reward, paid = shaped_reward_one(prev, features, game.holder, not self._kick_bonus_paid, goal)
            self._kick_bonus_paid |= paid
        timeout = status == OUT_OF_TIME
        terminated = goal or status == OUT_OF_BOUNDS or (timeout and self.timeout_terminal)
        truncated = timeout and not self.timeout_terminal
        info = {"status": STATUS_NAMES[status], "step": self._steps}
        return self._observation(features), reward, terminated, truncated, info

    def render(self):
        if self.render_mode != "rgb_array":
            return None
        g = self.game
        return draw_half_field(g.px, g.py, g.body, g.bx, g.by)

    # --- helpers ------------------------------------------------------------------------------
    def _observe(self) -> list:
        """The features of what the agent sees now, in float64 (the reward differences these)."""
        g = self.game
        return low_level_features_one(
            g.seen, g.agent_kickable(), g.collided_ball, g.collided_post, g.last_action_ok, self.profile
        )

    def _observation(self, features: list) -> np.ndarray:
        """``features`` as a new float32 array. ``struct`` casts each to float as NumPy does, in half the
        time of ``np.array`` on a list (a tenth of the step)."""
        obs = np.empty(len(features), np.float32)
        self._pack_observation(obs, 0, *features)
        return obs

    @staticmethod
    def _parse_action(action) -> tuple[int, float, float]:
        """``(a, first parameter, second parameter)`` of an action; range clamping is HFO's (hfo_physics)."""
        try:
            a_raw, params = action
            a = int(a_raw)
        except (TypeError, ValueError):
            raise ValueError(f"action {action!r} is malformed; expected {ACTION_FORM}") from None
        if a != a_raw or not 0 <= a <= 2:
            raise ValueError(f"discrete action {a_raw!r} is not 0 (DASH), 1 (TURN) or 2 (KICK)")
        try:
            p = params[a] if len(params) == 3 else None
            x = p.tolist() if isinstance(p, np.ndarray) else list(p)
        except (TypeError, ValueError, IndexError):
            x = None
        if not isinstance(x, list) or len(x) != PARAM_SIZES[a]:
            raise ValueError(
                f"parameters {params!r} are malformed for {ACTION_NAMES[a]}; expected {ACTION_FORM}, "
                f"{ACTION_NAMES[a]}'s entry holding {PARAM_SIZES[a]} number(s)"
            )
        try:
            x0, x1 = float(x[0]), float(x[-1])
        except (TypeError, ValueError):
            x0 = x1 = math.nan
        if not (math.isfinite(x0) and math.isfinite(x1)):
            raise ValueError(f"{ACTION_NAMES[a]} parameters {x} must be finite numbers")
        return a, x0, x1

    def close(self):
        pass
