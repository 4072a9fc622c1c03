"""Catch Point (HyAR, Li et al., ICLR 2022, and its code ``TJU-DRL-LAB/AI-Optimizer``):
``pamdp/CatchPoint-v0``.

- ``env.py``: the domain contract, :class:`CatchPoint`, and its envs :class:`CatchPointEnv` (scalar) and
  :class:`CatchPointVectorEnv` (batched);
- ``render.py``: the top view.

The dynamics, shared with Hard Move, are HyAR's particle world in ``pamdp.envs.particle``.

An agent on a plane either pushes itself in a chosen direction or tries to catch a target point; a catch
succeeds within 0.2 of the target, and 11 failed catches are allowed per episode:

====  =====  ========================  ==================================================
 a    name   parameter                 effect
====  =====  ========================  ==================================================
 0    move   angle θ in [-π, π]        push with force 2 in direction (sin θ, cos θ)
 1    catch  none (an empty box)       no push; catch if within 0.2 after this step
====  =====  ========================  ==================================================

The reward is minus the squared distance to the target, ``20 - d2`` for a catch, 0 once the budget of
failed catches is spent. An episode ends (``terminated``) on a catch or on the step after the 11th failed
catch; the registration's 25-step limit is ``truncated``. The dynamics are ``pamdp.envs.particle``'s.
"""

from pamdp.envs.catch_point.env import CatchPoint, CatchPointEnv, CatchPointVectorEnv, catch_point_action_space
from pamdp.envs.catch_point.render import draw_catch_point

__all__ = ["CatchPoint", "CatchPointEnv", "CatchPointVectorEnv", "catch_point_action_space", "draw_catch_point"]
