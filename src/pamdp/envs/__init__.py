"""Parameterized-action domains, registered with Gymnasium on ``import pamdp``.

- ``pamdp/Platform-v0``: Masson, Ranchod & Konidaris' Platform (``platform/``).
- ``pamdp/HalfFieldOffense-v0``: Half Field Offense 1v0, empty goal (``hfo/``).

Each domain's folder holds its dynamics (compiled by Numba), its scalar ``gymnasium.Env`` and its batched
``gymnasium.vector.VectorEnv``, registered as its ``vector_entry_point``, so ``gymnasium.make_vec(id,
num_envs=N, vectorization_mode="vector_entry_point")`` returns the batched version. What the batched envs
share is ``vector.py``; ``rendering.py`` has the drawing primitives and episode-to-GIF recording.
"""

from __future__ import annotations

import gymnasium

_REGISTRATIONS = {
    "pamdp/Platform-v0": dict(
        entry_point="pamdp.envs.platform.env:PlatformEnv",
        vector_entry_point="pamdp.envs.platform.batched:PlatformVectorEnv",
        max_episode_steps=200,
    ),
    "pamdp/HalfFieldOffense-v0": dict(
        entry_point="pamdp.envs.hfo.env:HalfFieldOffenseEnv",
        vector_entry_point="pamdp.envs.hfo.batched:HalfFieldOffenseVectorEnv",
    ),
}


def register_envs() -> None:
    """Register pamdp's environments with Gymnasium (idempotent)."""
    for env_id, kwargs in _REGISTRATIONS.items():
        if env_id not in gymnasium.registry:
            gymnasium.register(id=env_id, **kwargs)
