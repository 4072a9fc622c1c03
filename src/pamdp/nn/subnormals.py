"""Subnormal floats flushed to zero in the gradient updates (the ``flush_denormal`` setting).

x86 arithmetic on subnormal floats is many times slower than on normal ones, and Adam's decaying moments can
reach them; the env steps never flush, since the Half Field Offense simulation needs IEEE subnormals.
"""

from __future__ import annotations

import contextlib

import torch

__all__ = ["subnormals_flushed"]


@contextlib.contextmanager
def subnormals_flushed(enabled: bool = True):
    """Flush subnormal floats to zero (x86 FTZ/DAZ, ``torch.set_flush_denormal``) in this thread's CPU arithmetic
    inside the block, and restore IEEE subnormals after it. Yields whether flushing is on: ``False`` when not
    ``enabled`` or where the CPU cannot flush."""
    flush = enabled and torch.set_flush_denormal(True)
    try:
        yield flush
    finally:
        if flush:
            torch.set_flush_denormal(False)
