"""``pamdp._memory.keep_freed_memory``: large tensors allocated again and again stop page-faulting."""

from __future__ import annotations

import subprocess
import sys

import pytest

PROBE = """
import resource, sys
import torch
from pamdp._memory import keep_freed_memory
applied = keep_freed_memory() if sys.argv[1] == "on" else False
x = torch.zeros(1)
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for _ in range(20):
    x = torch.ones(64 << 18)  # 64 MiB, above glibc's largest dynamic mmap threshold
    del x
print(applied, resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
"""


def _faults(mode: str) -> tuple[bool, int]:
    out = subprocess.run([sys.executable, "-c", PROBE, mode], capture_output=True, text=True, check=True).stdout
    applied, faults = out.split()
    return applied == "True", int(faults)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's mallopt")
def test_freed_large_tensors_are_reused_instead_of_faulted_in_again():
    applied, faults_on = _faults("on")
    if not applied:
        pytest.skip("not glibc")
    _, faults_off = _faults("off")
    pages = 20 * (64 << 20) // 4096
    assert faults_off > 0.5 * pages  # each allocation maps fresh pages and touches them all
    # The first allocations' pages, reused afterwards (2 to 7 allocations' worth, with the heap's layout).
    assert faults_on < 0.4 * pages
