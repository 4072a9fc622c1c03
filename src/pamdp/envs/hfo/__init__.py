"""Half Field Offense 1v0, empty goal: ``pamdp/HalfFieldOffense-v0``.

- ``dynamics``: one copy's physics, referee, features and shaped reward, compiled by Numba, and their loops
  over the copies.
- ``env``: the domain contract, :class:`HalfFieldOffense` (its settings are constructor arguments), and its envs
  ``HalfFieldOffenseEnv`` (scalar) and ``HalfFieldOffenseVectorEnv`` (batched).
- ``interface``: the action space, the checks of actions and reset options, the drawing.
- ``scorer``: a hand-written agent that scores almost always, the benchmarks' reference row.
"""

from pamdp.envs.hfo.env import HalfFieldOffense, HalfFieldOffenseEnv, HalfFieldOffenseVectorEnv
from pamdp.envs.hfo.interface import hfo_action_space
from pamdp.envs.hfo.scorer import scripted_scorer, scripted_scorer_batch

__all__ = [
    "HalfFieldOffense",
    "HalfFieldOffenseEnv",
    "HalfFieldOffenseVectorEnv",
    "hfo_action_space",
    "scripted_scorer",
    "scripted_scorer_batch",
]
