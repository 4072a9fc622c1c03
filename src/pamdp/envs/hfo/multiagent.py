"""Half Field Offense as a PettingZoo ``ParallelEnv`` (issue 47): the offense players as named agents.

Today the one offense agent, ``"offense_0"``, plays against HFO's goalie (``defense_npcs=1``, the default here) or
an empty goal (``defense_npcs=0``); the agents are built from ``offense_agents``, so more offense players will add
names, not change the API (a count other than 1 is refused until then). The dynamics are the single-agent env's,
wrapped: with the same seeds and actions the agent sees what ``gymnasium.make("pamdp/HalfFieldOffense-v0",
defense_npcs=...)`` returns, step for step. PettingZoo is an optional dependency (``pip install
"pamdp[multiagent]"``); ``import pamdp`` does not import it.
"""

from __future__ import annotations

import copy
import warnings
from collections.abc import Mapping

import numpy as np
from gymnasium.error import ResetNeeded

from pamdp.envs.hfo.env import HalfFieldOffenseEnv

try:
    from pettingzoo import ParallelEnv
except ModuleNotFoundError as error:
    raise ModuleNotFoundError(
        "pamdp.envs.hfo.multiagent needs PettingZoo: pip install 'pamdp[multiagent]'", name=error.name
    ) from error

__all__ = ["HalfFieldOffenseParallelEnv", "parallel_env"]

#: Reset options for the whole pitch; a player's own (``player``, ``body``) go under its agent's name.
PITCH_OPTIONS = ("ball", "goalie_body")
AGENT_OPTIONS = ("player", "body")


class HalfFieldOffenseParallelEnv(ParallelEnv):
    """Half Field Offense with its offense players as PettingZoo agents, all acting at once.

    Each agent has the single-agent env's observation space and hybrid action space
    (``Tuple(Discrete(3), Tuple(Box(2), Box(1), Box(2)))``, see :mod:`pamdp.envs.hfo`), and its info the same keys
    (``status``, ``step``, ``action_mask``, and ``is_success`` when the episode ends). An agent whose episode ends
    leaves ``agents``; ``reset`` brings them all back.

    ``reset(options=...)`` takes the single-agent env's options: ``ball`` and ``goalie_body`` for the pitch, and a
    player's ``player`` and ``body`` under its agent's name, e.g. ``{"ball": (40, 5), "offense_0": {"player": (30,
    0)}}``. Other keys are ignored with a warning: PettingZoo's own API test resets with ``{"options": 1}``.

    Args:
        offense_agents: how many offense players are agents; only 1 is implemented.
        defense_npcs: 1 for HFO's goalie, 0 for an empty goal.
        render_mode: ``None`` or ``"rgb_array"`` (the single-agent env's pictures).
        **settings: the single-agent env's other arguments (``max_episode_steps``, ``profile``, ``deterministic``,
            ... of :class:`~pamdp.envs.hfo.env.HalfFieldOffense`).
    """

    metadata = {"name": "half_field_offense_v0", "render_modes": ["rgb_array"], "is_parallelizable": True}

    def __init__(
        self, offense_agents: int = 1, defense_npcs: int = 1, render_mode: str | None = None, **settings: object
    ):
        if isinstance(offense_agents, bool) or offense_agents != 1:
            raise ValueError(f"offense_agents={offense_agents!r}; expected 1 (more offense agents are not implemented)")
        self._env = HalfFieldOffenseEnv(render_mode=render_mode, defense_npcs=defense_npcs, **settings)
        self.render_mode = render_mode
        self.metadata = {**self.metadata, "render_fps": self._env.metadata["render_fps"]}
        self.possible_agents = [f"offense_{i}" for i in range(offense_agents)]
        self.agents: list[str] = []
        # One space object per agent, so that seeding one agent's action sampling leaves the others' alone.
        self.observation_spaces = {a: copy.deepcopy(self._env.observation_space) for a in self.possible_agents}
        self.action_spaces = {a: copy.deepcopy(self._env.action_space) for a in self.possible_agents}

    def observation_space(self, agent: str):
        return self.observation_spaces[self._known(agent)]

    def action_space(self, agent: str):
        return self.action_spaces[self._known(agent)]

    def reset(self, seed: int | None = None, options: dict | None = None) -> tuple[dict, dict]:
        obs, info = self._env.reset(seed=seed, options=self._single_options(options))
        self.agents = list(self.possible_agents)
        (agent,) = self.agents
        return {agent: obs}, {agent: info}

    def step(self, actions: dict) -> tuple[dict, dict, dict, dict, dict]:
        if not self.agents:
            raise ResetNeeded("no agent is playing (the episode ended or never began): call reset() before step()")
        self._check_agents(actions)
        (agent,) = self.agents
        try:
            obs, reward, terminated, truncated, info = self._env.step(actions[agent])
        except ValueError as error:
            raise ValueError(f"{agent}: {error}") from None
        if terminated or truncated:
            self.agents = []
        return {agent: obs}, {agent: reward}, {agent: terminated}, {agent: truncated}, {agent: info}

    def render(self) -> np.ndarray | None:
        return self._env.render()

    def close(self) -> None:
        self._env.close()

    def _known(self, agent: str) -> str:
        if agent not in self.possible_agents:
            raise ValueError(f"unknown agent {agent!r}; expected one of {self.possible_agents}")
        return agent

    def _check_agents(self, actions) -> None:
        """Exactly one action for every playing agent, else a ``ValueError`` naming the extra or missing ones."""
        if not isinstance(actions, Mapping):
            raise ValueError(f"actions of type {type(actions).__name__}; expected a dict with keys {self.agents}")
        extra = [a for a in actions if a not in self.agents]
        if extra:
            raise ValueError(f"actions for unknown or finished agent(s) {extra}; expected keys {self.agents}")
        missing = [a for a in self.agents if a not in actions]
        if missing:
            raise ValueError(f"no action for agent(s) {missing}; expected one for each of {self.agents}")

    def _single_options(self, options: dict | None) -> dict | None:
        """The reset options as the single-agent env takes them: the pitch's, and agent 0's lifted out of its name."""
        if options is None:
            return None
        if not isinstance(options, Mapping):
            raise ValueError(f"reset options of type {type(options).__name__}; expected a dict")
        single, ignored = {}, []
        for key, value in options.items():
            if key in self.possible_agents:
                if not isinstance(value, Mapping) or set(value) - set(AGENT_OPTIONS):
                    raise ValueError(f"reset option {key}={value!r}; expected a dict with some of {AGENT_OPTIONS}")
                single.update(value)
            elif key in PITCH_OPTIONS:
                single[key] = value
            elif key in AGENT_OPTIONS:
                raise ValueError(
                    f"reset option {key!r} is a player's; expected it under an agent's name, e.g. "
                    f"{{{self.possible_agents[0]!r}: {{{key!r}: ...}}}}"
                )
            else:
                ignored.append(key)
        if ignored:
            expected = [*PITCH_OPTIONS, *self.possible_agents]
            warnings.warn(f"reset options {ignored} ignored; this env reads {expected}", stacklevel=3)
        return single


def parallel_env(defense_npcs: int = 1, **kwargs: object) -> HalfFieldOffenseParallelEnv:
    """HFO's offense as a PettingZoo ``ParallelEnv``, by PettingZoo's naming convention: 1v1 against the goalie by
    default, ``defense_npcs=0`` for the empty goal; ``kwargs`` as :class:`HalfFieldOffenseParallelEnv` takes them."""
    return HalfFieldOffenseParallelEnv(defense_npcs=defense_npcs, **kwargs)
