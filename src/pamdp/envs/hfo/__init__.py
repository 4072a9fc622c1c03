"""Half Field Offense 1v0, empty goal (Hausknecht & Stone, ICLR 2016; ``LARG/HFO``): ``pamdp/HalfFieldOffense-v0``;
and 1v1 against HFO's goalie (``defense_npcs=1``): ``pamdp/HalfFieldOffenseGoalie-v0``.

- ``dynamics``: one copy's physics, referee, features and shaped reward, compiled by Numba, and their loops
  over the copies.
- ``env``: the domain contract, :class:`HalfFieldOffense` (its settings are constructor arguments), and its envs
  ``HalfFieldOffenseEnv`` (scalar) and ``HalfFieldOffenseVectorEnv`` (batched).
- ``defense``, ``goalie``, ``two_player``: the 1v1 cycle, the goalie's decision (agent2d's goalie, written from
  a description of its rules) and the server rules a second player brings (catch, tackle, collisions).
- ``interface``: the action space, the checks of actions and reset options, the drawing.
- ``scorer``: a hand-written agent that scores almost always, the benchmarks' reference row.
- ``multiagent``: the offense as a PettingZoo ``ParallelEnv`` (``parallel_env()``, PettingZoo's convention), read
  from here on first use, so that importing pamdp never imports the optional PettingZoo.

Score on an empty goal from a random start, with HFO's low-level actions and features: a simulation of
rcssserver 15.2.2 and of HFO's agent and referee (``dynamics``). Actions in HFO's units: DASH(power in
[0, 100], direction in [-180, 180] degrees off the body, rounded to a multiple of 45), TURN(direction in
[-180, 180], compensated for the player's speed as HFO's agent does), KICK(power in [0, 100], direction in
[-180, 180], silently dropped when the ball is not kickable). Finite parameters outside those boxes are
handled as HFO handles them: dash power is clamped to [-100, 100] (negative power dashes backwards at twice
the stamina cost), kick power to [0, 100], and directions to [-180, 180]. Batched:
``(a[N], (dash[N, 2], turn[N, 1], kick[N, 2]))``; malformed or non-finite actions raise ``ValueError``.
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

_MULTIAGENT = ("HalfFieldOffenseParallelEnv", "parallel_env")


def __getattr__(name: str):
    if name in _MULTIAGENT:
        from pamdp.envs.hfo import multiagent

        return getattr(multiagent, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
