"""Half Field Offense 1v0, empty goal: ``pamdp/HalfFieldOffense-v0``.

- ``dynamics``: one copy's physics, referee, features and shaped reward, compiled by Numba (the one
  writing of ``shared/specs/hfo.md`` section 2).
- ``env``: the scalar ``HalfFieldOffenseEnv``; ``batched``: ``HalfFieldOffenseVectorEnv``, N copies in
  one compiled loop, each with its own random stream.
- ``interface``: the action space, the checks of actions and reset options, the drawing.
- ``scorer``: a hand-written agent that scores almost always, the benchmarks' reference row.
"""

from pamdp.envs.hfo.batched import HalfFieldOffenseVectorEnv
from pamdp.envs.hfo.env import HalfFieldOffenseEnv
from pamdp.envs.hfo.interface import hfo_action_space
from pamdp.envs.hfo.scorer import scripted_scorer, scripted_scorer_batch

__all__ = [
    "HalfFieldOffenseEnv",
    "HalfFieldOffenseVectorEnv",
    "hfo_action_space",
    "scripted_scorer",
    "scripted_scorer_batch",
]
