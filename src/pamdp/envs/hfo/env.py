"""Half Field Offense 1v0 and 1v1 as a pamdp domain: its contract and its two envs. Actions, observations,
``info``, reset options, random streams and the constructor's settings: ``docs/environments.md``, "Half Field
Offense" and "Each domain's batched actions, ``state`` and ``info``"."""

from __future__ import annotations

import numpy as np
from gymnasium import spaces

import pamdp.envs.hfo.dynamics as dyn
from pamdp.envs.hfo import defense, interface
from pamdp.envs.hfo.interface import kick_mask
from pamdp.envs.scalar import env_classes
from pamdp.envs.vector import Domain, every_copy

__all__ = ["HalfFieldOffense", "HalfFieldOffenseEnv", "HalfFieldOffenseVectorEnv", "kick_mask"]

_STATUS_NAMES = np.array(dyn.STATUS_NAMES)


class HalfFieldOffense(Domain):
    name = "Half Field Offense"
    state_size = dyn.STATE_SIZE
    # The shell's buffers stay empty: the numbers come from the copies' own streams.

    def __init__(
        self,
        defense_npcs: int = 0,
        profile: str = "hfo2017",
        deterministic: bool = False,
        timeout_terminal: bool = False,
        body_reset: str = "carry",
        first_step_reward: bool = False,
        terminal_deltas: bool = False,
    ):
        interface.check_settings(profile, body_reset, defense_npcs)
        self.profile = dyn.PROFILES[profile]
        self.settings = dyn.settings(
            self.profile, deterministic, timeout_terminal, terminal_deltas, first_step_reward, body_reset == "uniform"
        )
        self.goalie = defense_npcs == 1
        self.reset_options = ("ball", "player", "body") + ("goalie_body",) * self.goalie
        # The goalie's block (8 features) and its uniform number come before the last-action flag.
        self.n_features = self.profile.n_features + (9 if self.profile.n_features == 59 else 8) * self.goalie
        if self.goalie:
            self.state_size, self.name = defense.STATE_SIZE, "Half Field Offense 1v1"
        self._step_batch = defense.step_batch if self.goalie else dyn.step_batch
        self._reset_batch = defense.reset_batch if self.goalie else dyn.reset_batch
        self.feature_names = interface.feature_names(self.profile.n_features, self.goalie)
        self.observation_space = spaces.Box(-1.0, 1.0, (self.n_features,), dtype=np.float32)
        self.action_space = interface.hfo_action_space()

    def initial_states(self, n):
        self.copy_streams = np.zeros((n, 4), dtype=np.uint64)
        self._sources: list = [None] * n  # the generator that seeded each copy's stream
        self._seen = -1  # the streams' replacements when they were last followed
        states = np.zeros((n, self.state_size))  # the first episode faces the goal (body 0)
        for row in states if self.goalie else ():
            defense.new_goalie(row)
        return states

    def state(self, states):
        return states

    parse = staticmethod(interface.parse_actions)

    def _follow(self, env) -> None:
        """Seed the stream of every copy whose generator is a new one."""
        if env.streams.replacements == self._seen:
            return
        self._seen = env.streams.replacements
        for i, rng in enumerate(env.streams.generators):
            if rng is not self._sources[i]:
                dyn.seed_stream(self.copy_streams[i], rng.random(4))
                self._sources[i] = rng

    def check_options(self, options, n):
        interface.reset_options(options, n, shell_keys=("reset_mask",), goalie=self.goalie)

    def reset(self, env, mask, options, seeded, obs):
        placements = interface.reset_options(options, env.num_envs, shell_keys=("reset_mask",), goalie=self.goalie)
        self._follow(env)
        env._states[mask & seeded, dyn.BODY] = 0.0  # a new server run faces the goal
        for i in np.flatnonzero(mask & seeded) if self.goalie else ():
            defense.new_goalie(env._states[i])  # and starts a new goalie program
        self._reset_batch(env._states, self.copy_streams, mask, self.settings, placements, obs)
        return self._infos(env)

    def step(self, env, parsed, resetting, obs, rewards, terminated, truncated):
        (a, dash, turn, kick), status = parsed, np.empty(env.num_envs, dtype=np.int64)
        self._follow(env)
        self._step_batch(
            env._states, self.copy_streams, a, dash, turn, kick, resetting, self.settings, obs, rewards, status,
            terminated, truncated,
        )  # fmt: skip
        infos = self._infos(env, status)
        infos["is_success"], infos["_is_success"] = status == dyn.GOAL, terminated | truncated
        return infos

    def _infos(self, env, status=None) -> dict:
        names = _STATUS_NAMES[status] if status is not None else np.full(env.num_envs, "IN_GAME")
        step = env._states[:, dyn.STEPS].astype(np.int64)
        return every_copy(env.num_envs, status=names, step=step, action_mask=kick_mask(env._states))

    def frame(self, env, i):
        return interface.draw_half_field(env._states[i], goalie=self.goalie)


HalfFieldOffenseEnv, HalfFieldOffenseVectorEnv = env_classes(
    HalfFieldOffense, __name__, "HalfFieldOffenseEnv", "HalfFieldOffenseVectorEnv"
)
