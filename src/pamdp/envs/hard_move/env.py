"""Hard Move as a pamdp domain: its contract and its two envs (the task: ``pamdp.envs.hard_move``).

Action ``(a, (p_0, ..., p_{K-1}))`` with ``K = 2 ** n``, batched ``a`` of shape ``(N,)`` and each ``p``
``(N, 1)`` or ``(N,)``, or all ``K`` stacked in one array ``(K, N, 1)`` or ``(K, N)``, which is faster to
read at n = 10. Every parameter must be finite, used or not; only each copy's own ``p_a`` is read, as given, not
clipped: ``|p| > 1`` pushes harder, ``p < 0`` backwards. Observation ``[vx, vy, gx - ax, gy - ay]`` (float64).

Random numbers: a reset draws the agent's then the target's position, ``uniform(-1, 1, 2)`` each, four
``random()`` numbers of the copy's generator (the scalar env draws none ahead), so assigning
``numpy.random.RandomState(S)`` to the scalar env's ``np_random`` replays the original driven by
``np.random.seed(S)``. ``state`` holds copies of the state rows (indices in ``pamdp.envs.particle``),
``motions`` the table of :func:`~pamdp.envs.hard_move.motions.motion_table`.
"""

from __future__ import annotations

from operator import attrgetter

import numpy as np
from gymnasium import spaces

import pamdp.envs.particle as particle
from pamdp.envs.hard_move.motions import check_size, motion_table
from pamdp.envs.hard_move.render import draw_hard_move
from pamdp.envs.scalar import env_classes
from pamdp.envs.vector import split_actions

__all__ = ["HardMove", "HardMoveEnv", "HardMoveVectorEnv", "hard_move_action_space"]

STACK_AT_MOST = 256
"""Up to this many boxes (n = 4, 6, 8) stacking all the parameters of a batch costs less than taking each
copy's own; at n = 10 (1024 boxes) taking each copy's own costs less (docs/environments.md gives the speeds)."""


def hard_move_action_space(n: int) -> spaces.Tuple:
    """``Tuple(Discrete(2 ** n), Tuple(Box(-1, 1, (1,)) x 2 ** n))``, float32."""
    box = {"low": np.float32(-1.0), "high": np.float32(1.0), "shape": (1,), "dtype": np.float32}
    k = 2 ** check_size(n)
    return spaces.Tuple((spaces.Discrete(k), spaces.Tuple(tuple(spaces.Box(**box) for _ in range(k)))))


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
        """``a`` (n,) int64 and each copy's own parameter ``p[i] = p_{a[i]}[i]`` (n,) float64, once every parameter
        of every box is known to be finite.

        The parameters are gathered without a Python loop over the ``K`` boxes or the copies: a sequence of at
        most :data:`STACK_AT_MOST` boxes for several copies is stacked (in C) and read by fancy indexing, as a
        stacked array is; from a longer one, or for one copy, ``map`` takes each copy's own box and value
        (C-level iteration) and :func:`_check_finite` reads all the boxes at once.
        """
        k = len(self.motions)
        expected = (
            f"(a, (p_0, ..., p_{k - 1})) with a an int array of shape ({n},) in 0..{k - 1} and each p a finite array "
            f"of shape ({n}, 1) or ({n},), or all of them stacked in one array of shape ({k}, {n}, 1) or ({k}, {n})"
        )
        a, params = split_actions(actions, self.name, n, expected, k)
        a = a.astype(np.int64, copy=False)
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

    def step(self, env, parsed, resetting):
        (a, p), n, streams = parsed, env.num_envs, env.streams
        obs, rewards, terminated = np.empty((n, particle.OBS_SIZE)), np.zeros(n), np.zeros(n, dtype=bool)
        particle.hard_move_copies(
            env._states, a, p, self.motions, resetting, streams.buffers, streams.cursors, obs, rewards, terminated
        )
        if env.render_mode is not None:
            self.last_actions[:] = np.where(resetting, -1, a)
            self.last_params[:] = p
        # As Gymnasium's vector envs merge the scalar envs' infos: a copy that was reset reports nothing.
        return obs, rewards, terminated, np.zeros(n, dtype=bool), self.infos(env, ~resetting, terminated.copy())

    def frame(self, env, i):
        a = int(self.last_actions[i])
        return draw_hard_move(env._states[i], self.n, None if a < 0 else a, float(self.last_params[i]))


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
    """Refuse a NaN or an infinity in any box, chosen or not. Contiguous boxes of one dtype are read in two C-level
    passes (their bytes joined, then one ``isfinite``: ~80 µs for 1 024 boxes, where a Python loop over the boxes
    cost 1.7 ms a step); other boxes (Python floats, mixed dtypes) are flattened one by one."""
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
