"""Robot Soccer Goal (Masson, Ranchod & Konidaris, AAAI 2016) and HyAR's Hard Goal: ``pamdp/Goal-v0``,
``pamdp/HardGoal-v0``.

- ``dynamics.py``: the dynamics of one copy, once, compiled by Numba (spec: ``shared/specs/goal.md``);
- ``env.py``: the scalar envs, :class:`GoalEnv` and :class:`HardGoalEnv` (Goal with HyAR's shots);
- ``batched.py``: N copies in one compiled loop, :class:`GoalVectorEnv` and :class:`HardGoalVectorEnv`;
- ``render.py``: the top view and episode GIFs.
"""

from pamdp.envs.goal.batched import GoalVectorEnv, HardGoalVectorEnv
from pamdp.envs.goal.env import GoalEnv, HardGoalEnv, hard_goal_shot
from pamdp.envs.goal.render import draw_goal, save_goal_gif

__all__ = [
    "GoalEnv",
    "HardGoalEnv",
    "GoalVectorEnv",
    "HardGoalVectorEnv",
    "hard_goal_shot",
    "draw_goal",
    "save_goal_gif",
]
