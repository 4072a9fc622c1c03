"""Hard Move with n = 4, 6, 8 or 10 actuators (HyAR, Li et al., ICLR 2022): ``pamdp/HardMove-v0``.

- ``motions.py``: the actuators and the motion of each of the ``2 ** n`` discrete actions;
- ``env.py``: the domain contract, :class:`HardMove`, and its envs :class:`HardMoveEnv` (scalar) and
  :class:`HardMoveVectorEnv` (batched);
- ``render.py``: the top view.

The dynamics, shared with Catch Point, are HyAR's particle world in ``pamdp.envs.particle``.
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
