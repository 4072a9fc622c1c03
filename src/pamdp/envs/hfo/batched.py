"""N copies of HFO 1v0 stepped at once: ``gymnasium.make_vec("pamdp/HalfFieldOffense-v0", num_envs=N)``.

The copies run ``dynamics.step_copy``, the scalar env's step, in one compiled loop
(``dynamics.step_batch``); each copy draws from its own generator (``pamdp.envs.vector``), so copy i
follows a scalar env reset with copy i's seed step for step, noise included.
"""

from __future__ import annotations

import gymnasium
import numpy as np

import pamdp.envs.hfo.dynamics as dyn
from pamdp.envs.hfo.env import HalfFieldOffenseEnv, kick_mask
from pamdp.envs.hfo.interface import draw_half_field, parse_actions, reset_options
from pamdp.envs.vector import BatchedVectorEnv, copy_seeds

_STATUS_NAMES = np.array(dyn.STATUS_NAMES)


class HalfFieldOffenseVectorEnv(BatchedVectorEnv):
    """``num_envs`` HFO 1v0 games, with Gymnasium's next-step autoreset.

    Takes the keyword arguments of :class:`pamdp.envs.hfo.HalfFieldOffenseEnv` (``settings``), and the
    shell's ``max_episode_steps`` (None: HFO's own clocks end the episodes). Actions are the
    ``batch_space`` of the scalar action space: ``(a[N], (dash[N, 2], turn[N, 1], kick[N, 2]))``. A copy
    that ended on the previous step is reset instead of stepped (its action is ignored) and returns its
    first observation with reward 0. ``infos`` holds ``status`` (strings), ``step`` and ``action_mask`` (bool
    ``(N, 3)``, as the scalar env's) per copy, and ``is_success`` (a goal) for the copies whose episode ended
    (``_is_success``). ``reset(options=...)``
    takes the scalar env's options, each once for every copy or per copy (a leading axis of size N),
    and the shell's ``reset_mask``.

    Seeding: ``reset(seed=s)`` seeds copy i's generator with ``s + i`` (or ``reset(seed=[...])`` one seed
    each) and, as in the scalar env, turns its player to face the goal. Copy i's numbers come from a
    stream (``copy_streams[i]``, ``dynamics.seed_stream``) seeded from its generator ``np_randoms[i]`` whenever
    that is a new one; the shell's buffers stay empty. ``states`` holds one state vector per copy
    (indices in ``dynamics``).
    """

    draw = "random"
    draws_per_step = 0  # the numbers come from the copies' streams, not from the shell's buffers

    def __init__(
        self, num_envs: int = 1, render_mode: str | None = None, max_episode_steps: int | None = None, **settings
    ):
        single = HalfFieldOffenseEnv(render_mode, **settings)
        super().__init__(num_envs, single, max_episode_steps, render_mode)
        self.profile, self.settings = single.profile, single.settings
        self.states = np.zeros((self.num_envs, dyn.STATE_SIZE))
        self.copy_streams = np.zeros((self.num_envs, 4), dtype=np.uint64)
        self._stream_sources: list = [None] * self.num_envs
        self._seeded = np.zeros(self.num_envs, dtype=bool)
        self._started = False

    def reset(self, *, seed=None, options: dict | None = None):
        self._seeded = np.array([s is not None for s in copy_seeds(seed, self.num_envs)])
        return super().reset(seed=seed, options=options)

    @BatchedVectorEnv.np_randoms.setter
    def np_randoms(self, generators) -> None:
        BatchedVectorEnv.np_randoms.fset(self, generators)
        self._follow_generators()

    def _follow_generators(self) -> None:
        """Seed the stream of every copy whose generator is a new one."""
        for i, rng in enumerate(self.streams.generators):
            if rng is not self._stream_sources[i]:
                dyn.seed_stream(self.copy_streams[i], rng.random(4))
                self._stream_sources[i] = rng

    def _frames(self) -> tuple:
        return tuple(draw_half_field(s) for s in self.states)

    def _reset_copies(self, mask, options):
        placements = reset_options(options, self.num_envs, shell_keys=("reset_mask",))
        self._follow_generators()
        self.states[mask & self._seeded, dyn.BODY] = 0.0  # a new server run faces the goal
        obs = np.empty((self.num_envs, self.profile.n_features), dtype=np.float32)
        dyn.reset_batch(self.states, self.copy_streams, mask, self.settings, placements, obs)
        self._started = True
        return obs, self._infos()

    def _step_copies(self, actions, resetting):
        if not self._started:
            raise gymnasium.error.ResetNeeded("call reset() before step()")
        n = self.num_envs
        a, dash, turn, kick = parse_actions(actions, n)
        obs = np.empty((n, self.profile.n_features), dtype=np.float32)
        reward, status = np.empty(n), np.empty(n, dtype=np.int64)
        terminated, truncated = np.empty(n, dtype=bool), np.empty(n, dtype=bool)
        dyn.step_batch(
            self.states, self.copy_streams, a, dash, turn, kick, resetting, self.settings, obs, reward, status,
            terminated, truncated,
        )  # fmt: skip
        infos = self._infos(status)
        infos["is_success"], infos["_is_success"] = status == dyn.GOAL, terminated | truncated
        return obs, reward, terminated, truncated, infos

    def _infos(self, status=None) -> dict:
        every = np.ones(self.num_envs, dtype=bool)
        names = _STATUS_NAMES[status] if status is not None else np.full(self.num_envs, "IN_GAME")
        steps = self.states[:, dyn.STEPS].astype(np.int64)
        return {
            "status": names,
            "_status": every,
            "step": steps,
            "_step": every,
            "action_mask": kick_mask(self.states),
            "_action_mask": every,
        }
