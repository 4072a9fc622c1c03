"""The scalar Half Field Offense env: one copy of ``dynamics``, stepped by its compiled ``step_one``."""

from __future__ import annotations

import gymnasium
import numpy as np
from gymnasium import spaces

import pamdp.envs.hfo.dynamics as dyn
from pamdp.envs.hfo.interface import check_settings, draw_half_field, hfo_action_space, parse_action, reset_options


def kick_mask(states: np.ndarray) -> np.ndarray:
    """The actions with an effect in one state vector ``(STATE_SIZE,)`` or a batch ``(N, STATE_SIZE)``: DASH and
    TURN always, KICK where the agent's kickable test passes (``dynamics.simulate`` drops it otherwise)."""
    mask = np.ones(states.shape[:-1] + (3,), dtype=bool)
    mask[..., dyn.KICK] = states[..., dyn.KICKABLE_NOW] != 0.0
    return mask


class HalfFieldOffenseEnv(gymnasium.Env):
    """HFO 1v0: score on an empty goal from a random start, with HFO's low-level actions and features.

    The simulation of rcssserver 15.2.2 and of HFO's agent and referee in ``shared/specs/hfo.md``; actions
    in HFO's units: DASH(power in [0, 100], direction in [-180, 180] degrees off the body, rounded to a
    multiple of 45), TURN(direction in [-180, 180], compensated for the player's speed as HFO's agent
    does), KICK(power in [0, 100], direction in [-180, 180], silently dropped when the ball is not
    kickable). Finite parameters outside those boxes are handled as HFO handles them: dash power is
    clamped to [-100, 100] (negative power dashes backwards at twice the stamina cost), kick power to
    [0, 100], and directions to [-180, 180]. Malformed or non-finite actions raise ``ValueError``.

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

    ``info`` holds ``status`` ("IN_GAME", "GOAL", "OUT_OF_BOUNDS" or "OUT_OF_TIME"), ``step``, the
    number of actions taken this episode, and ``action_mask``, bool ``(3,)``: which of DASH, TURN and KICK
    have an effect in the returned state (KICK only when the agent's kickable test passes, as HFO's agent
    sends it); when an episode ends also ``is_success`` (True on a goal). The
    observation returned with a terminal status is the true terminal state. ``reset(options=...)``
    accepts ``ball`` (x, y), ``player`` (x, y) and ``body`` (degrees), in the server's metres (goal
    centre at (52.5, 0)); missing ones are drawn as usual. Every random number (placements, actuator
    noise) comes from a stream seeded from ``np_random`` (``dynamics.seed_stream``; again whenever
    ``np_random`` is replaced, as by a seeded reset), as in each copy of :class:`HalfFieldOffenseVectorEnv`.
    ``state`` is the copy's state vector (indices in ``dynamics``).
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
        check_settings(profile, body_reset, render_mode)
        self.render_mode = render_mode
        self.profile = dyn.PROFILES[profile]
        self.settings = dyn.settings(
            self.profile, deterministic, timeout_terminal, terminal_deltas, first_step_reward, body_reset == "uniform"
        )
        n = self.profile.n_features
        self.observation_space = spaces.Box(-1.0, 1.0, (n,), dtype=np.float32)
        self.action_space = hfo_action_space()
        self.state = np.zeros(dyn.STATE_SIZE)  # the first episode faces the goal (body 0)
        self.stream = np.zeros(4, dtype=np.uint64)
        self._stream_source = None  # the generator that seeded the stream
        self._features = np.zeros(59)
        self._started = False

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        placement = reset_options(options, 1)[0]
        if seed is not None:
            self.state[dyn.BODY] = 0.0  # a seed starts a new server run, whose first episode faces the goal
        self._follow_np_random()
        obs = np.empty(self.profile.n_features, dtype=np.float32)
        dyn.reset_one(self.state, self.stream, self.settings, placement, self._features, obs)
        self._started = True
        return obs, {"status": "IN_GAME", "step": 0, "action_mask": kick_mask(self.state)}

    def step(self, action):
        if not self._started:
            raise gymnasium.error.ResetNeeded("call reset() before step()")
        a, x0, x1 = parse_action(action)
        self._follow_np_random()
        obs = np.empty(self.profile.n_features, dtype=np.float32)
        reward, status = dyn.step_one(self.state, self.stream, a, x0, x1, self.settings, self._features, obs)
        terminated, truncated = dyn.ending(status, self.settings)
        info = {
            "status": dyn.STATUS_NAMES[status],
            "step": int(self.state[dyn.STEPS]),
            "action_mask": kick_mask(self.state),
        }
        if terminated or truncated:
            info["is_success"] = status == dyn.GOAL
        return obs, reward, terminated, truncated, info

    def render(self):
        if self.render_mode != "rgb_array":
            return None
        return draw_half_field(self.state)

    def _follow_np_random(self) -> None:
        """Seed the stream from ``np_random`` if that is a new generator (a seeded reset or an assignment)."""
        rng = self.np_random
        if rng is not self._stream_source:
            dyn.seed_stream(self.stream, rng.random(4))
            self._stream_source = rng
