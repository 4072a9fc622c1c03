"""gym-hybrid's two domains (Thomas Hirtz): ``pamdp/Moving-v0`` and ``pamdp/Sliding-v0``.

- ``dynamics.py``: the dynamics of one copy, once for both agents, compiled by Numba, and their loops over
  the copies;
- ``env.py``: the domain contract, :class:`GymHybrid` (Sliding is its variant ``sliding=True``), and its envs
  :class:`MovingEnv`, :class:`SlidingEnv` (scalar), :class:`MovingVectorEnv`, :class:`SlidingVectorEnv`
  (batched);
- ``render.py``: the top view.
"""

from pamdp.envs.gym_hybrid.env import (
    GymHybrid,
    MovingEnv,
    MovingVectorEnv,
    SlidingEnv,
    SlidingVectorEnv,
    gym_hybrid_action_space,
)
from pamdp.envs.gym_hybrid.render import draw_gym_hybrid

__all__ = [
    "GymHybrid",
    "MovingEnv",
    "SlidingEnv",
    "MovingVectorEnv",
    "SlidingVectorEnv",
    "gym_hybrid_action_space",
    "draw_gym_hybrid",
]
