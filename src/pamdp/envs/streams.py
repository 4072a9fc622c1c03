"""Per-copy random streams: how a copy's random numbers reach compiled code, one buffer of draws per copy.

Every copy draws only from its own generator, seeded as Gymnasium seeds the copies of its vector envs:
``reset(seed=s)`` gives copy i ``seed + i``, ``reset(seed=[s0, s1, ...])`` one seed each (:func:`copy_seeds`).

Random numbers reach compiled code through :class:`RandomStreams`: each copy keeps a buffer of standard
draws (``standard_normal`` or ``random``, one kind per domain) taken in blocks from its own generator, and
a cursor. Drawing a block of ``k`` numbers gives the same numbers as ``k`` single draws, for NumPy's
``Generator`` and ``RandomState`` alike, and a draw ``normal(0, s)`` is ``0.0 + s * z`` with ``z`` the
next standard normal (``uniform(a, b)`` is ``a + (b - a) * u``), so a domain's step reads its numbers
from the buffer in the order it needs them and consumes exactly its generator's stream. Before a step
(or a reset that draws) the shell tops up the buffers of the copies with fewer numbers left than one step
can take; the compiled step never calls back.
"""

from __future__ import annotations

import numba
import numpy as np
from gymnasium.utils import seeding

__all__ = ["RandomStreams", "check_seed", "copy_seeds"]

DRAWS = ("standard_normal", "random")
"""The generator methods a stream can draw with (both exist on ``Generator`` and ``RandomState``)."""


def is_seed(seed) -> bool:
    """Whether ``seed`` is one seed Gymnasium takes: an int >= 0 (not a bool)."""
    return isinstance(seed, (int, np.integer)) and not isinstance(seed, (bool, np.bool_)) and seed >= 0


def check_seed(seed) -> None:
    """The scalar envs' ``reset(seed=...)``: None or an int >= 0, else a ``ValueError`` naming it (before the
    generator is touched)."""
    if seed is not None and not is_seed(seed):
        raise ValueError(f"seed={seed!r}; expected None or an int >= 0")


def copy_seeds(seed, num_copies: int) -> list:
    """The seed of each copy for ``reset(seed=seed)``: ``seed + i`` for an int, the list itself for a
    list of ``num_copies`` ints (or None), ``num_copies`` Nones for None; every entry is checked before any is
    used, so that a refused seed reseeds no copy."""
    if seed is None:
        return [None] * num_copies
    if is_seed(seed):
        return [int(seed) + i for i in range(num_copies)]
    if isinstance(seed, (list, tuple, np.ndarray)) and len(seed) == num_copies:
        if all(s is None or is_seed(s) for s in seed):
            return [None if s is None else int(s) for s in seed]
    raise ValueError(
        f"seed={seed!r}; expected None, an int, or a list of {num_copies} ints (or None), one per copy; ints >= 0"
    )


class RandomStreams:
    """Per-copy buffers of standard draws, each taken in blocks from its copy's own generator.

    ``buffers`` is ``(num_copies, capacity)`` float64 and ``cursors`` ``(num_copies,)`` int64: copy i's
    next number is ``buffers[i, cursors[i]]``. Code that consumes numbers advances ``cursors[i]``; it must
    never read past ``capacity``, which :meth:`refill` ensures for up to ``need`` numbers.

    Args:
        num_copies: number of copies.
        draw: the generator method that yields the numbers, ``"standard_normal"`` or ``"random"``.
        capacity: numbers kept per copy; a copy is topped up when fewer than ``need`` are left, so a larger
            capacity means fewer (but larger) draws.
    """

    def __init__(self, num_copies: int, draw: str, capacity: int):
        if draw not in DRAWS:
            raise ValueError(f"draw={draw!r}; expected one of {DRAWS}")
        if not isinstance(capacity, (int, np.integer)) or capacity < 1:
            raise ValueError(f"capacity={capacity!r}; expected a positive integer")
        self.draw = draw
        self.capacity = int(capacity)
        self.buffers = np.zeros((num_copies, self.capacity))
        self.cursors = np.full(num_copies, self.capacity, dtype=np.int64)  # empty
        self._generators: list = [None] * num_copies
        self.replacements = 0
        """How many times a copy's generator was replaced: a domain with streams of its own (HFO) reseeds them
        only when this changed."""

    @property
    def generators(self) -> tuple:
        """Each copy's generator (None until it is seeded or first drawn from)."""
        return tuple(self._generators)

    def set(self, i: int, rng) -> None:
        """Make ``rng`` copy ``i``'s generator and drop the numbers drawn from the previous one."""
        if not callable(getattr(rng, self.draw, None)):
            raise ValueError(f"{rng!r} has no {self.draw}() method; expected a numpy Generator or RandomState")
        self._generators[i] = rng
        self.cursors[i] = self.capacity
        self.replacements += 1

    def follow(self, i: int, rng) -> None:
        """:meth:`set` copy ``i``'s generator to ``rng`` unless it is that object already (the scalar envs'
        ``np_random`` may be replaced at any time; the next step must then draw from the new one)."""
        if rng is not self._generators[i]:
            self.set(i, rng)

    def seed(self, seed) -> None:
        """Seed every copy as :func:`copy_seeds` says; a copy whose seed is None keeps its generator (or
        gets one from fresh entropy if it has none), as a Gymnasium env does on ``reset(seed=None)``."""
        for i, s in enumerate(copy_seeds(seed, len(self._generators))):
            if s is not None or self._generators[i] is None:
                self.set(i, seeding.np_random(s)[0])

    def refill(self, need: int) -> None:
        """Top up every copy that has fewer than ``need`` numbers left: the rest moves to the front and the
        buffer is filled from the copy's generator, in the generator's order."""
        if need > self.capacity:
            raise ValueError(f"need={need} numbers exceed the capacity {self.capacity}")
        if not _any_above(self.cursors, self.capacity - need):  # most steps: a compiled test, no index array
            return
        for i in np.flatnonzero(self.cursors > self.capacity - need):
            if self._generators[i] is None:
                self.set(i, seeding.np_random(None)[0])
            left = self.capacity - int(self.cursors[i])
            row = self.buffers[i]
            row[:left] = row[self.capacity - left :]
            row[left:] = getattr(self._generators[i], self.draw)(self.capacity - left)
            self.cursors[i] = 0


@numba.njit(cache=True, nogil=True)
def _any_above(values, limit) -> bool:
    """Whether any of ``values`` exceeds ``limit``."""
    for i in range(values.shape[0]):
        if values[i] > limit:
            return True
    return False
