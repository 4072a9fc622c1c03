"""Hard Move with n = 4, 6, 8 or 10 actuators (HyAR, Li et al., ICLR 2022, and its code
``TJU-DRL-LAB/AI-Optimizer``): ``pamdp/HardMove-v0``.

- ``motions.py``: the actuators and the motion of each of the ``2 ** n`` discrete actions;
- ``env.py``: the domain contract, :class:`HardMove`, and its envs :class:`HardMoveEnv` (scalar) and
  :class:`HardMoveVectorEnv` (batched);
- ``render.py``: the top view.

The dynamics, shared with Catch Point, are HyAR's particle world in ``pamdp.envs.particle``.

An agent on a plane has ``n`` evenly spaced actuators (4, 6, 8 or 10, the variant); discrete action ``a``
(one of ``2 ** n``) switches on the actuators of its bits (the most significant bit is actuator 0) and its
one parameter ``p`` scales the resulting push. The agent must come within 0.2 of a target point. The reward
is minus the squared distance to the target, ``20 - d2`` on arrival, which ends the episode
(``terminated``, ``info["is_success"]``); the registration's 30-step limit is ``truncated``. The dynamics
are ``pamdp.envs.particle``'s.
"""

from pamdp.envs.hard_move.env import HardMove, HardMoveEnv, HardMoveVectorEnv, hard_move_action_space
from pamdp.envs.hard_move.motions import SIZES, motion_table
from pamdp.envs.hard_move.render import draw_hard_move

__all__ = [
    "HardMove",
    "HardMoveEnv",
    "HardMoveVectorEnv",
    "hard_move_action_space",
    "motion_table",
    "SIZES",
    "draw_hard_move",
]
