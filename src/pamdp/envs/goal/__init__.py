"""Robot Soccer Goal (Masson, Ranchod & Konidaris, AAAI 2016) and HyAR's Hard Goal: ``pamdp/Goal-v0``,
``pamdp/HardGoal-v0``.

- ``dynamics.py``: the dynamics of one copy, once, compiled by Numba, and their loops over the copies;
- ``env.py``: the domain contract, :class:`Goal` (Hard Goal is its variant ``hard=True``), and its envs
  :class:`GoalEnv`, :class:`HardGoalEnv` (scalar), :class:`GoalVectorEnv`, :class:`HardGoalVectorEnv` (batched);
- ``render.py``: the top view and episode GIFs.
"""

from pamdp.envs.goal.env import Goal, GoalEnv, GoalVectorEnv, HardGoalEnv, HardGoalVectorEnv, hard_goal_shot
from pamdp.envs.goal.render import draw_goal, save_goal_gif

__all__ = [
    "Goal",
    "GoalEnv",
    "HardGoalEnv",
    "GoalVectorEnv",
    "HardGoalVectorEnv",
    "hard_goal_shot",
    "draw_goal",
    "save_goal_gif",
]
