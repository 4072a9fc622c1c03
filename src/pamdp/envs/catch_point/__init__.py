"""Catch Point (HyAR, Li et al., ICLR 2022): ``pamdp/CatchPoint-v0``.

- ``env.py``: the domain contract, :class:`CatchPoint`, and its envs :class:`CatchPointEnv` (scalar) and
  :class:`CatchPointVectorEnv` (batched);
- ``render.py``: the top view.

The dynamics, shared with Hard Move, are HyAR's particle world in ``pamdp.envs.particle``.
"""

from pamdp.envs.catch_point.env import CatchPoint, CatchPointEnv, CatchPointVectorEnv, catch_point_action_space
from pamdp.envs.catch_point.render import draw_catch_point

__all__ = ["CatchPoint", "CatchPointEnv", "CatchPointVectorEnv", "catch_point_action_space", "draw_catch_point"]
