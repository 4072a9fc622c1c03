"""gym-hybrid's two domains (Thomas Hirtz): ``pamdp/Moving-v0`` and ``pamdp/Sliding-v0``.

- ``dynamics.py``: the dynamics of one copy, once for both agents, compiled by Numba (spec:
  ``shared/specs/gym_hybrid.md``);
- ``env.py``: the scalar envs, :class:`MovingEnv` and :class:`SlidingEnv`;
- ``batched.py``: N copies in one compiled loop, :class:`MovingVectorEnv` and :class:`SlidingVectorEnv`;
- ``render.py``: the top view.
"""

from pamdp.envs.gym_hybrid.batched import MovingVectorEnv, SlidingVectorEnv
from pamdp.envs.gym_hybrid.env import MovingEnv, SlidingEnv, gym_hybrid_action_space
from pamdp.envs.gym_hybrid.render import draw_gym_hybrid

__all__ = [
    "MovingEnv",
    "SlidingEnv",
    "MovingVectorEnv",
    "SlidingVectorEnv",
    "gym_hybrid_action_space",
    "draw_gym_hybrid",
]
