"""Catch Point as a pamdp domain: its contract and its two envs (the task: ``pamdp.envs.catch_point``). Actions,
observations, ``state``, ``info`` and the resets' draws: ``docs/environments.md``, "Catch Point and Hard Move" and
"Each domain's batched actions, ``state`` and ``info``"."""

from __future__ import annotations

import functools

import numpy as np

import pamdp.envs.particle as particle
from pamdp.envs.catch_point.render import draw_catch_point
from pamdp.envs.scalar import env_classes
from pamdp.envs.vector import column, every_copy, hybrid_space, split_actions

__all__ = ["CatchPoint", "CatchPointEnv", "CatchPointVectorEnv", "catch_point_action_space", "THETA_MAX"]

THETA_MAX = float(np.float32(np.pi))
"""The angle box is [-π, π] in float32, 3.1415927410125732 (HyAR's glue sends float32(p) * float32(π))."""


def catch_point_action_space():
    """``Tuple(Discrete(2), Tuple(Box(-π, π, (1,)), Box(0,)))``, float32."""
    return hybrid_space((-THETA_MAX, THETA_MAX, 1), (-1.0, 1.0, 0))


@functools.cache  # the check of every batch needs it
def expected_actions(n: int) -> str:
    return (
        f"(a, (theta, catch)) with a an int array of shape ({n},) in {{0, 1}}, theta a finite array of "
        f"shape ({n}, 1) or ({n},) and catch an array of shape ({n}, 0) (or ({n}, 1), ignored)"
    )


class CatchPoint(particle.ParticleDomain):
    name = "Catch Point"
    max_episode_steps = 25

    def __init__(self):
        super().__init__()
        self.action_space = catch_point_action_space()

    def parse(self, actions, n):
        """``a`` (n,) int64 and ``theta`` (n,) float64 (the compiled step checks the values)."""
        expected = expected_actions(n)
        a, params = split_actions(actions, self.name, n, expected, n_params=2)
        theta, catch = column(params[0], n, "angles", expected), np.shape(params[1])
        if catch not in ((n, 0), (n, 1)):
            raise ValueError(f"invalid catch parameters of shape {catch}; expected {expected}")
        return a.astype(np.int64, copy=False), theta.astype(np.float64, copy=False)

    def step(self, env, parsed, resetting, obs, rewards, terminated, truncated):
        (a, theta), n, streams, caught = parsed, env.num_envs, env.streams, np.zeros(env.num_envs, dtype=bool)
        bad = particle.catch_point_copies(
            env._states, a, theta, resetting, streams.buffers, streams.cursors, obs, rewards, terminated, caught
        )
        if bad >= 0:
            raise ValueError(f"copy {bad}: action {a[bad]} with angle {theta[bad]}; expected {expected_actions(n)}")
        return self.stepped(env, resetting, a, theta, caught)

    def infos(self, env, stepped=None, success=None) -> dict:
        fails = every_copy(env.num_envs, failed_catches=env._states[:, particle.FAILS].astype(np.int64))
        return fails | super().infos(env, stepped, success)

    def frame(self, env, i):
        return draw_catch_point(env._states[i], self.shown_action(i))


CatchPointEnv, CatchPointVectorEnv = env_classes(CatchPoint, __name__, "CatchPointEnv", "CatchPointVectorEnv")
