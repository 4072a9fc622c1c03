"""Hybrid (parameterized) action spaces.

A parameterized action is ``(a, x)``: a discrete action ``a`` out of ``K`` and a continuous parameter
vector ``x`` in the box ``X_a`` of size ``m_a``. Gymnasium spells such a space
``Tuple(Discrete(K), Tuple(Box(m_0), ..., Box(m_{K-1})))``; :class:`HybridActionSpace` describes it for
the agents, which keep every parameter in ``[-1, 1]`` padded to ``m = max_a m_a`` (the paper's
constant-size parameter policy), and map affinely to each action's box at the environment boundary.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from gymnasium import spaces

__all__ = ["HybridActionSpace", "BoxRows"]


class BoxRows(tuple):
    """A batch's parameter boxes as the rows of one ``(K, N, m)`` array, ``block``: a tuple of boxes to any env, and
    to one that knows it (Hard Move, whose 1 024 boxes it then checks in one pass) that one array."""

    def __new__(cls, block: np.ndarray):
        rows = super().__new__(cls, block)
        rows.block = block
        return rows


@dataclass(frozen=True)
class HybridActionSpace:
    """K discrete actions, each with a box of continuous parameters.

    Attributes:
        lows: one float64 array of lower bounds per action (length ``m_a``).
        highs: one float64 array of upper bounds per action.
    """

    lows: tuple[np.ndarray, ...]
    highs: tuple[np.ndarray, ...]

    def __post_init__(self):
        if len(self.lows) == 0 or len(self.lows) != len(self.highs):
            raise ValueError(
                f"lows and highs must be equally long, non-empty sequences; got {len(self.lows)} and {len(self.highs)}"
            )
        for a, (lo, hi) in enumerate(zip(self.lows, self.highs)):
            if lo.shape != hi.shape or lo.ndim != 1:
                raise ValueError(f"action {a}: bounds must be 1-D of equal shape, got {lo.shape}, {hi.shape}")
            if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi)) and np.all(lo < hi)):
                raise ValueError(f"action {a}: need finite bounds with low < high, got low={lo}, high={hi}")

    # -- construction -------------------------------------------------------------------------
    @classmethod
    def from_gym(cls, space: spaces.Space) -> HybridActionSpace:
        """Describe a ``Tuple(Discrete(K), Tuple(Box, ...))`` space; anything else is a ``ValueError``."""
        expected = "Tuple(Discrete(K), Tuple(Box(m_0,), ..., Box(m_{K-1},))) with finite bounds"
        if not (
            isinstance(space, spaces.Tuple)
            and len(space.spaces) == 2
            and isinstance(space.spaces[0], spaces.Discrete)
            and isinstance(space.spaces[1], spaces.Tuple)
        ):
            raise ValueError(f"unsupported action space {space!r}; expected {expected}")
        disc, params = space.spaces
        if disc.start != 0 or int(disc.n) != len(params.spaces):
            raise ValueError(
                f"action space {space!r}: Discrete({disc.n}, start={disc.start}) needs start 0 and one "
                f"parameter box per action ({len(params.spaces)} given); expected {expected}"
            )
        lows, highs = [], []
        for a, box in enumerate(params.spaces):
            if not isinstance(box, spaces.Box) or len(box.shape) != 1:
                raise ValueError(f"parameter space of action {a} is {box!r}; expected a 1-D Box")
            lows.append(np.asarray(box.low, dtype=np.float64))
            highs.append(np.asarray(box.high, dtype=np.float64))
        return cls(tuple(lows), tuple(highs))

    # -- shape --------------------------------------------------------------------------------
    @property
    def n_actions(self) -> int:
        """K, the number of discrete actions."""
        return len(self.lows)

    @property
    def param_sizes(self) -> tuple[int, ...]:
        """``m_a`` for every action."""
        return tuple(int(lo.shape[0]) for lo in self.lows)

    @property
    def max_param_size(self) -> int:
        """``m = max_a m_a``, the parameter policy's output size."""
        return max(self.param_sizes)

    @property
    def total_param_size(self) -> int:
        """``sum_a m_a``, the size of PADDPG's all-parameters output."""
        return sum(self.param_sizes)

    @cached_property
    def param_offsets(self) -> np.ndarray:
        """``o_a = m_0 + ... + m_{a-1}``: where action ``a``'s parameters start in the all-parameters vector."""
        return _frozen(np.concatenate([[0], np.cumsum(self.param_sizes)[:-1]]).astype(np.int64))

    @cached_property
    def param_mask(self) -> np.ndarray:
        """Boolean ``(K, m)``: entry ``[a, i]`` is true where action ``a`` uses padded parameter ``i``."""
        mask = np.zeros((self.n_actions, self.max_param_size), dtype=bool)
        for a, m in enumerate(self.param_sizes):
            mask[a, :m] = True
        return _frozen(mask)

    @cached_property
    def param_index(self) -> np.ndarray:
        """Integer ``(K, m)``: entry ``[a, i]`` is where action ``a``'s padded parameter ``i`` sits in the
        all-parameters vector, ``o_a + i`` (0 where :attr:`param_mask` is false)."""
        return _frozen(np.where(self.param_mask, self.param_offsets[:, None] + np.arange(self.max_param_size), 0))

    @cached_property
    def param_blocks(self) -> np.ndarray:
        """Boolean ``(K, sum_a m_a)``: row ``a`` marks action ``a``'s block of the all-parameters vector."""
        column, start = np.arange(self.total_param_size), self.param_offsets[:, None]
        return _frozen((column >= start) & (column < start + np.array(self.param_sizes)[:, None]))

    @cached_property
    def padded_low(self) -> np.ndarray:
        """``(K, m)`` lower bounds, padded with -1 (unused entries map identically)."""
        return self._padded(self.lows, -1.0)

    @cached_property
    def padded_high(self) -> np.ndarray:
        """``(K, m)`` upper bounds, padded with +1."""
        return self._padded(self.highs, 1.0)

    def _padded(self, bounds, fill):
        out = np.full((self.n_actions, self.max_param_size), fill, dtype=np.float64)
        for a, b in enumerate(bounds):
            out[a, : b.shape[0]] = b
        return _frozen(out)

    @cached_property
    def _mid32(self) -> np.ndarray:
        """``(K, m)`` float32 centres of the boxes (what the actions not taken are given)."""
        return _frozen((0.5 * (self.padded_low + self.padded_high)).astype(np.float32))

    # -- scaling ------------------------------------------------------------------------------
    def scale(self, a, x_unit) -> np.ndarray:
        """Map padded parameters from ``[-1, 1]`` to action ``a``'s box (batched over leading axes).

        ``a`` has shape ``B`` and ``x_unit`` shape ``B + (m,)``; values outside ``[-1, 1]`` are clipped.
        """
        a = np.asarray(a, dtype=np.int64)
        x = np.clip(np.asarray(x_unit, dtype=np.float64), -1.0, 1.0)
        lo, hi = self.padded_low[a], self.padded_high[a]
        return lo + (x + 1.0) * 0.5 * (hi - lo)

    def unscale(self, a, x_env) -> np.ndarray:
        """Inverse of :meth:`scale`: padded parameters in the domain's units to ``[-1, 1]``."""
        a = np.asarray(a, dtype=np.int64)
        lo, hi = self.padded_low[a], self.padded_high[a]
        return np.clip(2.0 * (np.asarray(x_env, dtype=np.float64) - lo) / (hi - lo) - 1.0, -1.0, 1.0)

    # -- conversion to and from the env's action format ---------------------------------------
    def to_env(self, a: int, x_unit) -> tuple:
        """One agent action ``(a, x in [-1,1]^m)`` as the env's tuple, in the domain's units.

        Actions other than ``a`` get the centre of their box (the env reads only action ``a``'s).
        """
        a = int(a)
        if not 0 <= a < self.n_actions:
            raise ValueError(f"discrete action {a} out of range; expected 0..{self.n_actions - 1}")
        x = self.scale(a, x_unit)
        params = []
        for b, (lo, hi) in enumerate(zip(self.lows, self.highs)):
            p = x[: lo.shape[0]] if b == a else 0.5 * (lo + hi)
            params.append(np.asarray(p, dtype=np.float32))
        return (a, tuple(params))

    def to_env_batch(self, a, x_unit) -> tuple:
        """A batch of agent actions as a vector env's action: ``(a[N], (p_0[N, m_0], ...))``."""
        a = np.asarray(a, dtype=np.int64)
        x = self.scale(a, x_unit)
        sizes = set(self.param_sizes)
        if len(sizes) == 1 and self.n_actions > 8:  # one (K, N, m) block instead of K passes over the batch
            m = sizes.pop()
            block = np.empty((self.n_actions, len(a), m), dtype=np.float32)
            block[:] = self._mid32[:, None, :]
            block[a, np.arange(len(a))] = x[:, :m]
            return (a, BoxRows(block))
        params = []
        for b, (lo, hi) in enumerate(zip(self.lows, self.highs)):
            p = np.where((a == b)[:, None], x[:, : lo.shape[0]], 0.5 * (lo + hi))
            params.append(p.astype(np.float32))
        return (a, tuple(params))

    def from_env(self, action) -> tuple[int, np.ndarray]:
        """An env action tuple as ``(a, x in [-1,1]^m)``, padding with zeros."""
        a = int(action[0])
        if not 0 <= a < self.n_actions:
            raise ValueError(f"discrete action {a} out of range; expected 0..{self.n_actions - 1}")
        x = np.zeros(self.max_param_size)
        m = self.param_sizes[a]
        x[:m] = np.asarray(action[1][a], dtype=np.float64).reshape(m)
        return a, self.unscale(a, x) * self.param_mask[a]

    def to_gym(self) -> spaces.Tuple:
        """The equivalent Gymnasium space (float32 boxes)."""
        return spaces.Tuple(
            (
                spaces.Discrete(self.n_actions),
                spaces.Tuple(
                    tuple(
                        spaces.Box(lo.astype(np.float32), hi.astype(np.float32))
                        for lo, hi in zip(self.lows, self.highs)
                    )
                ),
            )
        )


def _frozen(array: np.ndarray) -> np.ndarray:
    """``array`` made read-only: the space's cached tables are shared by every caller."""
    array.setflags(write=False)
    return array
