"""Parameterized-action domains, registered with Gymnasium on ``import pamdp``.

- ``pamdp/Platform-v0``: Masson, Ranchod & Konidaris' Platform (``platform/``).
- ``pamdp/HalfFieldOffense-v0``: Half Field Offense 1v0, empty goal (``hfo/``).
- ``pamdp/HalfFieldOffenseGoalie-v0``: Half Field Offense 1v1 against HFO's goalie (``hfo/``, ``defense_npcs=1``).
- ``pamdp/Goal-v0`` and ``pamdp/HardGoal-v0``: Robot Soccer Goal and HyAR's Hard Goal (``goal/``).
- ``pamdp/CatchPoint-v0``: HyAR's Catch Point (``catch_point/``).
- ``pamdp/HardMove-v0``: HyAR's Hard Move with ``n`` actuators, 4 to 10 (``hard_move/``).
- ``pamdp/Moving-v0`` and ``pamdp/Sliding-v0``: gym-hybrid's two domains (``gym_hybrid/``).

Each domain's folder holds its dynamics (compiled by Numba), its scalar ``gymnasium.Env`` and its batched
``gymnasium.vector.VectorEnv``, registered as its ``vector_entry_point``, so ``gymnasium.make_vec(id,
num_envs=N, vectorization_mode="vector_entry_point")`` returns the batched version. What the batched envs
share is ``vector.py``; ``rendering.py`` has the drawing primitives and episode-to-GIF recording. What the
algorithms and the evaluation use of this package knows no domain: ``backends.py`` makes an env from its id (checked
against Gymnasium's registry and its constructor), batched or stepped in turn, and ``stepping.py`` steps its copies
(autoreset, action masks) and counts their episodes.

Numba caches the compiled dynamics on disk, each function keyed by its own file only; importing this package first
deletes those caches if any source under ``envs/`` changed since they were written (``_numba_cache.py``), so an
edit of a module that a cached loop inlines (``hfo/goalie.py`` in ``hfo/defense.py``'s) is never run stale.
"""

from __future__ import annotations

import gymnasium

from pamdp.envs._numba_cache import guard as _guard_numba_cache

# Before any domain module is imported: they load their cached functions as they are imported or first called.
_guard_numba_cache()

_REGISTRATIONS = {
    "pamdp/Platform-v0": dict(
        entry_point="pamdp.envs.platform.env:PlatformEnv",
        vector_entry_point="pamdp.envs.platform.env:PlatformVectorEnv",
    ),
    "pamdp/HalfFieldOffense-v0": dict(
        entry_point="pamdp.envs.hfo.env:HalfFieldOffenseEnv",
        vector_entry_point="pamdp.envs.hfo.env:HalfFieldOffenseVectorEnv",
    ),
    "pamdp/HalfFieldOffenseGoalie-v0": dict(
        entry_point="pamdp.envs.hfo.env:HalfFieldOffenseEnv",
        vector_entry_point="pamdp.envs.hfo.env:HalfFieldOffenseVectorEnv",
        kwargs={"defense_npcs": 1},
    ),
    # No spec sets max_episode_steps: the envs keep their domain's time limit themselves (Platform 200, Catch Point
    # 25, Hard Move 30 steps), so that no Gymnasium TimeLimit zeroes the count before a reset is refused; Goal, Hard
    # Goal, Moving and Sliding end their episodes by their own step rules.
    "pamdp/Goal-v0": dict(
        entry_point="pamdp.envs.goal.env:GoalEnv",
        vector_entry_point="pamdp.envs.goal.env:GoalVectorEnv",
    ),
    "pamdp/HardGoal-v0": dict(
        entry_point="pamdp.envs.goal.env:GoalEnv",
        vector_entry_point="pamdp.envs.goal.env:GoalVectorEnv",
        kwargs={"hard": True},
    ),
    "pamdp/CatchPoint-v0": dict(
        entry_point="pamdp.envs.catch_point.env:CatchPointEnv",
        vector_entry_point="pamdp.envs.catch_point.env:CatchPointVectorEnv",
    ),
    "pamdp/HardMove-v0": dict(
        entry_point="pamdp.envs.hard_move.env:HardMoveEnv",
        vector_entry_point="pamdp.envs.hard_move.env:HardMoveVectorEnv",
    ),
    "pamdp/Moving-v0": dict(
        entry_point="pamdp.envs.gym_hybrid.env:MovingEnv",
        vector_entry_point="pamdp.envs.gym_hybrid.env:MovingVectorEnv",
    ),
    "pamdp/Sliding-v0": dict(
        entry_point="pamdp.envs.gym_hybrid.env:MovingEnv",
        vector_entry_point="pamdp.envs.gym_hybrid.env:MovingVectorEnv",
        kwargs={"sliding": True},
    ),
}


def register_envs() -> None:
    """Register pamdp's environments with Gymnasium (idempotent)."""
    for env_id, kwargs in _REGISTRATIONS.items():
        if env_id not in gymnasium.registry:
            gymnasium.register(id=env_id, **kwargs)
