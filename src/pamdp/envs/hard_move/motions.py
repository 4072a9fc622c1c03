"""Hard Move's actuators and the motion of each of its ``2 ** n`` discrete actions (hard_move.md §2)."""

from __future__ import annotations

import numbers

import numpy as np

__all__ = ["SIZES", "check_size", "actuators", "action_bits", "motion_table"]

SIZES = (4, 6, 8, 10)
"""The actuator counts of the benchmark (16 to 1024 discrete actions)."""


def check_size(n) -> int:
    """``n`` as an int, or ``ValueError`` unless it is one of :data:`SIZES`."""
    if isinstance(n, bool) or not isinstance(n, numbers.Integral) or int(n) not in SIZES:
        raise ValueError(f"n={n!r}; expected one of {SIZES} actuators")
    return int(n)


def actuators(n: int) -> np.ndarray:
    """``(n, 2)``: actuator k pushes along ``(cos α_k, sin α_k)`` rounded to 3 decimals, with ``α_k =
    linspace(0, 2π, n + 1)[k]`` (hard_move.md §2)."""
    alpha = np.linspace(0, 2 * np.pi, check_size(n) + 1)[:n]
    return np.stack([np.around(np.cos(alpha), 3), np.around(np.sin(alpha), 3)], axis=1)


def action_bits(n: int) -> np.ndarray:
    """``(2 ** n, n)`` float64: entry ``[a, k]`` is 1 where action ``a`` switches actuator ``k`` on, bit
    ``n - 1 - k`` of ``a`` (the most significant bit is actuator 0)."""
    shifts = n - 1 - np.arange(n)
    return ((np.arange(2**n)[:, None] >> shifts) & 1).astype(np.float64)


def motion_table(n: int) -> np.ndarray:
    """``(2 ** n, 2)``: the motion ``m_a = S_a / D`` of every action: ``S_a`` the sum of its actuators'
    pushes, ``D`` the largest ``|S_a|`` (hard_move.md §2).

    The original computes ``S = np.dot(bits, pushes)``, so the last bit of a sum depends on the order in
    which the BLAS kernel adds; under NumPy 2.4.6 (OpenBLAS, the recording's build) it adds actuators 0 to
    7 on two accumulators (even and odd k), the others apart, then the three. That order is written out
    here, so the table equals the recorded one (``hard_move_motions.json``) on any build.
    """
    pushes, bits = actuators(n), action_bits(n)
    even, odd, rest = (np.zeros((2**n, 2)) for _ in range(3))
    for k in range(n):
        acc = rest if k >= 8 else odd if k % 2 else even
        acc += bits[:, k : k + 1] * pushes[k]
    sums = (even + odd) + rest
    return sums / np.max(np.linalg.norm(sums, axis=1))
