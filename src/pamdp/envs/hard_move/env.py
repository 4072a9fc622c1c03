"""Hard Move as a pamdp domain: its contract and its two envs (the task: ``pamdp.envs.hard_move``). Actions (also
stacked in one array, faster at n = 10), observations, ``state`` and the resets' draws: ``docs/environments.md``,
"Catch Point and Hard Move" and "Each domain's batched actions, ``state`` and ``info``"."""

from __future__ import annotations

from operator import attrgetter

import numpy as np
from gymnasium import spaces

import pamdp.envs.particle as particle
from pamdp.envs.hard_move.motions import check_size, motion_table
from pamdp.envs.hard_move.render import draw_hard_move
from pamdp.envs.scalar import env_classes
from pamdp.envs.vector import hybrid_space, split_actions

__all__ = ["HardMove", "HardMoveEnv", "HardMoveVectorEnv", "hard_move_action_space"]

STACK_AT_MOST = 256  # up to 256 boxes (n = 4, 6, 8) stacking a batch's costs less than taking each copy's own


def hard_move_action_space(n: int) -> spaces.Tuple:
    """``Tuple(Discrete(2 ** n), Tuple(Box(-1, 1, (1,)) x 2 ** n))``, float32."""
    return hybrid_space(*[(-1.0, 1.0, 1)] * 2 ** check_size(n))


class HardMove(particle.ParticleDomain):
    name = "Hard Move"
    max_episode_steps = 30
    option_hints = {"n": "n is a constructor argument: gymnasium.make('pamdp/HardMove-v0', n=...)"}

    def __init__(self, n: int = 4):
        super().__init__()
        self.n = check_size(n)
        self.motions = motion_table(self.n)
        self.action_space = hard_move_action_space(self.n)

    def parse(self, actions, n):
        """``a`` (n,) int64 and each copy's own parameter ``p[i] = p_{a[i]}[i]`` (n,) float64, every parameter of
        every box checked finite, with no Python loop over the boxes or the copies: up to :data:`STACK_AT_MOST` boxes
        (for several copies) are stacked in C; more, or one copy's, are read by :func:`_gather` and
        :func:`_check_finite`."""
        k = len(self.motions)
        expected = (
            f"(a, (p_0, ..., p_{k - 1})) with a an int array of shape ({n},) in 0..{k - 1} and each p a finite array "
            f"of shape ({n}, 1) or ({n},), or all of them stacked in one array of shape ({k}, {n}, 1) or ({k}, {n})"
        )
        a, params = split_actions(actions, self.name, n, expected, k)
        a, params = a.astype(np.int64, copy=False), getattr(params, "block", params)  # BoxRows: their one array
        if not isinstance(params, np.ndarray):
            if not isinstance(params, (tuple, list)) or len(params) != k:
                given = f"{len(params)} boxes" if isinstance(params, (tuple, list)) else f"a {type(params).__name__}"
                raise ValueError(f"invalid parameters ({given}); expected {expected}")
            if k > STACK_AT_MOST or n == 1:
                chosen = _gather(params, a, n, expected)
                _check_finite(params, expected)
                return a, chosen
            try:
                params = np.asarray(params)
            except ValueError:
                raise ValueError(f"the parameter boxes differ in shape; expected {expected}") from None
        if params.shape not in ((k, n, 1), (k, n)) or params.dtype.kind not in "iuf":
            raise ValueError(f"parameters stacked to shape {params.shape}, dtype {params.dtype}; expected {expected}")
        params = params.reshape(k, n)
        finite = np.isfinite(params)
        if not finite.all():
            j = np.flatnonzero(~finite.all(axis=1))[0]
            raise ValueError(f"parameter {j} contains {params[j][~finite[j]]}; expected {expected}")
        return a, params[a, np.arange(n)].astype(np.float64, copy=False)

    def step(self, env, parsed, resetting, obs, rewards, terminated, truncated):
        (a, p), streams = parsed, env.streams
        particle.hard_move_copies(
            env._states, a, p, self.motions, resetting, streams.buffers, streams.cursors, obs, rewards, terminated
        )
        return self.stepped(env, resetting, a, p, terminated.copy())

    def frame(self, env, i):
        return draw_hard_move(env._states[i], self.n, self.shown_action(i), float(self.last_params[i]))


def _gather(params, a, n: int, expected: str) -> np.ndarray:
    """``params[a[i]][i]`` for every copy ``i``, by C-level iteration over the chosen boxes (checked)."""
    chosen = list(map(params.__getitem__, a.tolist()))  # copy i's box
    try:
        shapes = set(map(attrgetter("shape"), chosen))
        kinds = {dtype.kind for dtype in set(map(attrgetter("dtype"), chosen))}
    except AttributeError:
        raise ValueError(f"the chosen parameters are not all arrays; expected {expected}") from None
    if not shapes <= {(n,), (n, 1)} or not kinds <= set("iuf"):
        found = f"shapes {sorted(shapes)} and dtype kinds {sorted(kinds)}"
        raise ValueError(f"the chosen parameters have {found}; expected {expected}")
    return np.fromiter(map(np.ndarray.item, chosen, range(n)), np.float64, n)  # p_{a[i]}[i]


def _check_finite(params, expected: str) -> None:
    """Refuse a NaN or an infinity in any box, chosen or not: contiguous boxes of one dtype in C-level passes (their
    bytes joined, one ``isfinite``; a Python loop over 1 024 boxes cost 1.7 ms a step), others one by one."""
    boxes = list(tuple.__iter__(params) if isinstance(params, tuple) else params)  # the scalar env's own boxes
    try:
        dtype = boxes[0].dtype
        if list(map(attrgetter("dtype"), boxes)).count(dtype) != len(boxes):  # (a set would hash every dtype)
            raise TypeError
        values = np.frombuffer(b"".join(boxes), dtype)
    except (AttributeError, TypeError, ValueError):
        values = np.concatenate([np.ravel(p) for p in boxes])
    try:
        if np.isfinite(values).all():
            return
    except TypeError:
        raise ValueError(f"parameters that are not all numbers; expected {expected}") from None
    j, p = next((j, p) for j, p in enumerate(map(np.ravel, boxes)) if not np.isfinite(p).all())
    raise ValueError(f"parameter {j} contains {p[~np.isfinite(p)]}; expected {expected}")


HardMoveEnv, HardMoveVectorEnv = env_classes(HardMove, __name__, "HardMoveEnv", "HardMoveVectorEnv")
