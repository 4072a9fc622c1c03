"""N copies of Hard Move stepped at once: ``gymnasium.make_vec("pamdp/HardMove-v0", num_envs=N, n=...)``.

The copies run ``particle.hard_move_step``, the scalar env's dynamics, in one compiled loop
(``particle.hard_move_copies``); each copy draws its resets from its own generator
(``pamdp.envs.vector``), so copy i follows a scalar env reset with copy i's seed step for step.
"""

from __future__ import annotations

from operator import attrgetter

import numpy as np

import pamdp.envs.particle as particle
from pamdp.envs.hard_move.env import HardMoveEnv
from pamdp.envs.hard_move.render import draw_hard_move
from pamdp.envs.vector import BatchedVectorEnv, split_actions

__all__ = ["HardMoveVectorEnv", "parse_actions"]

RESETS_BUFFERED = 256
"""Episodes' worth of uniforms drawn at a time per copy."""
STACK_AT_MOST = 256
"""Up to this many boxes (n = 4, 6, 8) stacking all the parameters costs less than taking each copy's own;
at n = 10 (1024 boxes) taking each copy's own costs less (docs/environments.md gives the speeds)."""


class HardMoveVectorEnv(BatchedVectorEnv):
    """``num_envs`` independent Hard Move episodes with ``n`` actuators, stepped together.

    Actions are batched like ``batch_space`` of the scalar action space: ``(a, (p_0, ..., p_{K-1}))``
    with ``K = 2 ** n``, ``a`` an integer array of shape ``(N,)`` and each ``p`` of shape ``(N, 1)``
    (``(N,)`` is accepted too); :meth:`pamdp.spaces.HybridActionSpace.to_env_batch` produces this format.
    The ``K`` parameter arrays may also come stacked, as one array of shape ``(K, N, 1)`` or ``(K, N)``,
    which is faster to read at n = 10. Only each copy's own ``p_a`` is read and checked. Observations are
    ``(N, 4)`` float64; ``info["is_success"]`` (this step reached the target) is an ``(N,)`` array,
    reported (``info["_is_success"]``) by every copy that stepped rather than reset.

    Episodes auto-reset in Gymnasium's default *next-step* mode: the step that ends an episode returns its
    last observation with ``terminated`` or ``truncated`` set; the next ``step`` ignores that copy's
    action, resets it, and returns the reset observation with reward 0 and both flags false.

    Copy i draws its resets from its own generator, ``np_randoms[i]``; ``reset(seed=s)`` seeds copy i
    with ``s + i`` (or ``reset(seed=[...])`` with one seed each).

    Args:
        num_envs: number of copies N.
        n: number of actuators, 4, 6, 8 or 10.
        max_episode_steps: episodes are truncated after this many agent steps (the registration's 30;
            ``make_vec`` passes it in). ``None`` never truncates.
        render_mode: ``None`` or ``"rgb_array"``; :meth:`render` then returns one frame per copy.
    """

    draw = "random"
    draws_per_step = particle.RESET_DRAWS
    buffer_size = particle.RESET_DRAWS * RESETS_BUFFERED

    def __init__(
        self, num_envs: int = 1, n: int = 4, max_episode_steps: int | None = 30, render_mode: str | None = None
    ):
        single = HardMoveEnv(n)
        super().__init__(num_envs, single, max_episode_steps, render_mode)
        self.n = single.n
        self.motions = single.motions
        self._states = np.zeros((self.num_envs, particle.STATE_SIZE))
        self._last_actions = np.full(self.num_envs, -1, dtype=np.int64)
        self._last_params = np.zeros(self.num_envs)

    @property
    def states(self) -> np.ndarray:
        """A copy of the copies' state rows ``(N, STATE_SIZE)`` (indices in ``pamdp.envs.particle``)."""
        return self._states.copy()

    def _frames(self) -> tuple:
        return tuple(
            draw_hard_move(s, self.n, None if a < 0 else int(a), float(p))
            for s, a, p in zip(self._states, self._last_actions, self._last_params)
        )

    # -- the shell's hooks ------------------------------------------------------------------------
    def _reset_copies(self, mask, options):
        particle.reset_copies(self._states, mask, self.streams.buffers, self.streams.cursors)
        self._last_actions[mask] = -1
        obs = np.empty((self.num_envs, particle.OBS_SIZE))
        particle.observe(self._states, obs)
        return obs, {}

    def _step_copies(self, actions, resetting):
        n, streams = self.num_envs, self.streams
        a, p = parse_actions(actions, n, len(self.motions))
        obs, rewards, terminated = np.empty((n, particle.OBS_SIZE)), np.zeros(n), np.zeros(n, dtype=bool)
        bad = particle.hard_move_copies(
            self._states, a, p, self.motions, resetting, streams.buffers, streams.cursors, obs, rewards, terminated
        )
        if bad >= 0:
            raise ValueError(f"copy {bad}: parameter {p[bad]} of action {a[bad]}; expected a finite number")
        if self.render_mode is not None:
            self._last_actions[:] = np.where(resetting, -1, a)
            self._last_params[:] = p
        return obs, rewards, terminated, np.zeros(n, dtype=bool), _info(terminated.copy(), ~resetting)


def _info(success: np.ndarray, stepped: np.ndarray) -> dict:
    # As Gymnasium's vector envs merge the scalar envs' infos: a copy that was reset reports nothing.
    return {"is_success": success, "_is_success": stepped}


def parse_actions(actions, n: int, n_actions: int) -> tuple[np.ndarray, np.ndarray]:
    """Check a batch of ``n`` Hard Move actions with ``n_actions`` discrete actions; return ``a`` (n,)
    int64 and each copy's own parameter ``p[i] = p_{a[i]}[i]`` (n,) float64 (the compiled step checks
    that it is finite).

    The parameters are gathered without a Python loop over the ``n_actions`` boxes or the copies: a
    sequence of at most :data:`STACK_AT_MOST` boxes is stacked (in C) and read by fancy indexing, as a
    stacked array is; from a longer one, ``map`` takes each copy's own box and value (C-level iteration;
    only those boxes are checked).
    """
    expected = (
        f"(a, (p_0, ..., p_{n_actions - 1})) with a an int array of shape ({n},) in 0..{n_actions - 1} and "
        f"each p an array of shape ({n}, 1) or ({n},), or all of them stacked in one array of shape "
        f"({n_actions}, {n}, 1) or ({n_actions}, {n})"
    )
    a, params = split_actions(actions, "Hard Move", n, expected, n_actions)
    a = a.astype(np.int64, copy=False)
    if not isinstance(params, np.ndarray):
        if not isinstance(params, (tuple, list)) or len(params) != n_actions:
            given = f"{len(params)} boxes" if isinstance(params, (tuple, list)) else f"a {type(params).__name__}"
            raise ValueError(f"invalid parameters ({given}); expected {expected}")
        if n_actions > STACK_AT_MOST:
            return a, _gather(params, a, n, expected)
        try:
            params = np.asarray(params)
        except ValueError:
            raise ValueError(f"the parameter boxes differ in shape; expected {expected}") from None
    if params.shape not in ((n_actions, n, 1), (n_actions, n)) or params.dtype.kind not in "iuf":
        raise ValueError(f"parameters stacked to shape {params.shape}, dtype {params.dtype}; expected {expected}")
    return a, params.reshape(n_actions, n)[a, np.arange(n)].astype(np.float64, copy=False)


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
