"""Catch Point (HyAR, Li et al., ICLR 2022): ``pamdp/CatchPoint-v0``.

- ``env.py``: the scalar env, :class:`CatchPointEnv` (spec: ``shared/specs/catch_point.md``);
- ``batched.py``: N copies in one compiled loop, :class:`CatchPointVectorEnv`;
- ``render.py``: the top view.

The dynamics, shared with Hard Move, are HyAR's particle world in ``pamdp.envs.particle``.
"""

from pamdp.envs.catch_point.batched import CatchPointVectorEnv
from pamdp.envs.catch_point.env import CatchPointEnv, catch_point_action_space
from pamdp.envs.catch_point.render import draw_catch_point

__all__ = ["CatchPointEnv", "CatchPointVectorEnv", "catch_point_action_space", "draw_catch_point"]
