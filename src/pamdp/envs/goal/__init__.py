"""Robot Soccer Goal (Masson, Ranchod & Konidaris, AAAI 2016) and HyAR's Hard Goal: ``pamdp/Goal-v0``,
``pamdp/HardGoal-v0``.

- ``dynamics.py``: the dynamics of one copy, once, compiled by Numba, and their loops over the copies;
- ``env.py``: the domain contract, :class:`Goal` (Hard Goal is its variant ``hard=True``), and its envs
  :class:`GoalEnv`, :class:`HardGoalEnv` (scalar), :class:`GoalVectorEnv`, :class:`HardGoalVectorEnv` (batched);
- ``render.py``: the top view and episode GIFs.

The Gym port ``cycraig/gym-goal`` with MP-DQN's 17 scaled features (Bester et al. 2019). A player starts
beside the ball on the left edge of a half pitch (x in [0, 20], y in [-15, 15]) and must score past a
keeper that guards the goal mouth y in [-7.01, 7.01] on the line x = 20. Actions:

====  ===================  ==============================  =============================================
 a    name                 parameters                      effect
====  ===================  ==============================  =============================================
 0    kick-to              (x, y) in [0, 40] x [-15, 15]   dribble: run to the ball and kick it towards
                                                           (x, x) (y is ignored, a quirk of the port)
                                                           until it is kickable and slow again
 1    shoot-goal-left      y in [-7.01, 7.01]              shoot at (20.4, y) until the episode ends
 2    shoot-goal-right     y in [-7.01, 7.01]              the same as action 1
====  ===================  ==============================  =============================================

Hard Goal (the variant ``hard=True``; HyAR, Li et al. ICLR 2022) keeps action 0 and splits the shot into
2 x 5 actions, each a parameter in [-1, 1] mapped into a fixed part of the goal mouth by HyAR's formula
(:func:`hard_goal_shot`).

A step runs sub-steps of the simulation (``info["substeps"]``) until the action is done. A goal pays 50;
a ball caught by the keeper or out of the field ends the episode with minus its distance to the goal;
the 100th agent step ends it (truncated, without simulating) with the same penalty. Every other step pays
0. ``info["is_success"]`` at the end of an episode says whether it was a goal.
"""

from pamdp.envs.goal.dynamics import hard_goal_shot
from pamdp.envs.goal.env import Goal, GoalEnv, GoalVectorEnv, HardGoalEnv, HardGoalVectorEnv
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
