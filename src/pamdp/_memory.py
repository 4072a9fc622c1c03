"""Keep freed tensor memory in the process instead of returning it to the system after every use.

glibc's ``malloc`` serves allocations above a threshold (dynamic, at most 32 MiB on 64-bit Linux) with
their own ``mmap`` and unmaps them on ``free``. A PATRPO update on a large batch allocates such tensors
hundreds of times (50 000 samples x 400 hidden units in float32 is 80 MB), and every new mapping costs a
page fault per 4 KiB page: on Half Field Offense with the paper's soccer settings the faults took a
quarter of the process's CPU time (``ru_stime`` 13 s of 55 s for a 20 000-sample epoch; 1.2 s of 42 s
with this setting). Raising the threshold keeps those blocks on the heap, where they are reused.

The training entry points (``pamdp train``, ``pamdp reproduce`` and their worker processes) call
:func:`keep_freed_memory`; importing pamdp does not, as it changes the allocator of the whole process.
"""

from __future__ import annotations

import ctypes
import sys

_M_TRIM_THRESHOLD = -1
_M_MMAP_THRESHOLD = -3
_applied = False


def keep_freed_memory(threshold: int = 1 << 30) -> bool:
    """Serve allocations up to ``threshold`` bytes from the heap and keep up to that much free memory
    there (glibc's ``mallopt``). Returns whether it applied: ``False`` off Linux or without glibc."""
    global _applied
    if _applied:
        return True
    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL("libc.so.6")
        mallopt = libc.mallopt
    except (OSError, AttributeError):  # musl and other C libraries
        return False
    mallopt.argtypes, mallopt.restype = (ctypes.c_int, ctypes.c_int), ctypes.c_int
    _applied = bool(mallopt(_M_MMAP_THRESHOLD, threshold)) and bool(mallopt(_M_TRIM_THRESHOLD, threshold))
    return _applied
