"""gym-hybrid's two domains (Thomas Hirtz, ``thomashirtz/gym-hybrid``): ``pamdp/Moving-v0`` and
``pamdp/Sliding-v0``.

- ``dynamics.py``: the dynamics of one copy, once for both agents, compiled by Numba, and their loops over
  the copies;
- ``env.py``: the domain contract, :class:`GymHybrid` (Sliding is its variant ``sliding=True``), and its envs
  :class:`MovingEnv`, :class:`SlidingEnv` (scalar), :class:`MovingVectorEnv`, :class:`SlidingVectorEnv`
  (batched);
- ``render.py``: the top view.

An agent in the square field [-1, 1]² must stop inside a target circle of radius 0.1. Every agent step is a
parameterised action ``(a, p)``, and every action ends with the agent moving for ``delta_t`` at its speed:

====  ==========  ===============  ================================================================
 a    name        parameter range  effect
====  ==========  ===============  ================================================================
 0    accelerate  [0, 1]           add ``0.5 p`` to the speed (Sliding: a thrust along the heading)
 1    turn        [-1, 1]          turn the heading by ``(π/2) p``
 2    break       none             slow down by 0.1, or stop below 0.1
====  ==========  ===============  ================================================================

Moving's agent moves along its heading; Sliding's (the variant ``sliding=True``) keeps a velocity direction
of its own that thrust changes by vector addition, so turning does not redirect its motion. Each step pays
the decrease of the distance to the target minus 0.001; stopping (speed exactly 0) strictly inside the
target ends the episode with a bonus of 1 (``info["is_success"]``), leaving the field or taking a 201st
step ends it with -1. Both are ``terminated``: the elapsed fraction of the 200 steps is in the observation.
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
