"""What pamdp's scalar envs share: copy 0 of the batched layout, and the checks of one action.

A domain's scalar env is its batched env at N = 1 (``pamdp.envs.vector``): it keeps one state row in
``_states`` (shape ``(1, STATE_SIZE)``) and one :class:`~pamdp.envs.vector.RandomStreams` copy, and steps
them with the same compiled per-copy functions. :class:`ScalarEnv` holds that plumbing; a domain sets
``metadata`` (render modes and fps), ``observe`` (its compiled ``observe(states, out)``) and ``obs_size``,
and implements ``reset``, ``step`` and ``_frame`` (the picture :meth:`~ScalarEnv.render` returns).
"""

from __future__ import annotations

import math
import numbers

import gymnasium
import numpy as np

from pamdp.envs.vector import RandomStreams, check_render_mode

__all__ = ["ScalarEnv", "split_action", "number"]


class ScalarEnv(gymnasium.Env):
    """One copy of a domain's batched state and random stream as a Gymnasium env.

    Args:
        render_mode: ``None`` or one of ``metadata["render_modes"]``.
        action_space, observation_space: the env's spaces.
        states: the initial state rows, shape ``(1, STATE_SIZE)``.
        draw, capacity: the stream's generator method and the numbers it keeps drawn ahead
            (see :class:`~pamdp.envs.vector.RandomStreams`).
    """

    metadata = {"render_modes": ["rgb_array"]}
    obs_size: int
    """Length of the observation vector ``observe`` writes."""

    @staticmethod
    def observe(states: np.ndarray, out: np.ndarray) -> None:
        """The domain's compiled observation of the state rows into ``out`` ``(N, obs_size)``."""
        raise NotImplementedError

    def __init__(self, render_mode, action_space, observation_space, states: np.ndarray, draw: str, capacity: int):
        check_render_mode(render_mode, self.metadata["render_modes"])
        self.render_mode = render_mode
        self.action_space = action_space
        self.observation_space = observation_space
        self._states = states
        self._streams = RandomStreams(1, draw, capacity)

    @property
    def state(self) -> np.ndarray:
        """A copy of the state row (indices in the domain's dynamics module)."""
        return self._states[0].copy()

    def _observation(self) -> np.ndarray:
        out = np.empty((1, self.obs_size))
        self.observe(self._states, out)
        return out[0]

    def _stream(self, need: int) -> RandomStreams:
        """The stream, drawing from ``np_random`` (a replaced generator drops the numbers drawn ahead) and
        holding at least ``need`` numbers: copy 0's are ``buffers[0]`` from ``cursors[0]`` on."""
        self._streams.follow(0, self.np_random)
        self._streams.refill(need)
        return self._streams

    def render(self):
        return self._frame() if self.render_mode == "rgb_array" else None

    def _frame(self) -> np.ndarray:
        raise NotImplementedError

    def _substep_frames(self, draw) -> list[np.ndarray]:
        """``draw(*row)`` for each row of ``_trace`` the last step wrote (``_substeps`` of them)."""
        if self.render_mode != "rgb_array":
            raise ValueError(f"render_substeps needs render_mode='rgb_array', got {self.render_mode!r}")
        return [draw(*row) for row in self._trace[: self._substeps]]


def split_action(action, domain: str, n_actions: int, n_params: int | None, expected: str) -> tuple[int, tuple]:
    """Check the form of one action ``(a, params)``: ``a`` an int (or 0-d int array) in ``0..n_actions - 1``,
    ``params`` a tuple or list of ``n_params`` (None: not checked). Returns ``(int(a), params)``; a bad
    part raises ``ValueError`` naming it and the ``expected`` form."""
    if not isinstance(action, (tuple, list)) or len(action) != 2:
        raise ValueError(f"invalid {domain} action {action!r}; expected {expected}")
    a, params = action
    if not isinstance(a, (int, np.integer)) or isinstance(a, bool):  # the usual types skip the slower ABC test
        if isinstance(a, np.ndarray) and a.shape == ():
            a = a.item()
        if isinstance(a, bool) or not isinstance(a, numbers.Integral):
            raise ValueError(f"invalid discrete action {a!r}; expected {expected}")
    if not 0 <= a < n_actions:
        raise ValueError(f"invalid discrete action {a!r}; expected {expected}")
    if n_params is not None and (not isinstance(params, (tuple, list)) or len(params) != n_params):
        raise ValueError(f"invalid parameters {params!r}; expected {expected}")
    return int(a), params


def number(p, i: int, expected: str, label: str = "parameter ") -> float:
    """Parameter ``i`` given as a number or a shape-``(1,)`` array, as a finite float64; ``ValueError``
    otherwise, naming it ``label`` followed by ``i``."""
    arr = np.asarray(p)
    if arr.shape not in ((), (1,)) or arr.dtype.kind not in "iuf":
        raise ValueError(f"invalid {label}{i} {p!r}; expected {expected}")
    v = float(arr.item())
    if not math.isfinite(v):
        raise ValueError(f"{label}{i} is {v}; expected {expected}")
    return v
