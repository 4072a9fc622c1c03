"""A script run beside a local Ray cluster that lives on 127.0.0.1 only, and is gone afterwards.

The script starts its cluster itself (``ray.cluster_utils.Cluster``: a head and worker nodes, each its own
raylet process, which the script may kill). ``RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER=0`` makes Ray take the
loopback address as every node's own, so no traffic leaves 127.0.0.1; ``RAY_TMPDIR`` gives the cluster a
directory of its own, short enough for Ray's socket paths (107 bytes at most). Every process that carries
that directory in its environment is the script's or its cluster's: all of them are killed at the end, however
the script ended.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def _processes_with(variable: str) -> list[int]:
    """The ids of the processes whose environment holds ``variable`` (``NAME=value``) exactly."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit() or int(entry.name) == os.getpid():
            continue
        try:
            environ = (entry / "environ").read_bytes().split(b"\0")
        except OSError:  # gone meanwhile, or not ours to read
            continue
        if variable.encode() in environ:
            found.append(int(entry.name))
    return found


def run_on_local_cluster(script: str, workdir: Path, timeout: float) -> subprocess.CompletedProcess:
    """Run ``script`` with ``workdir`` as its argument and its own Ray directory; kill what it leaves running."""
    ray_tmp = tempfile.mkdtemp(prefix="ray", dir="/tmp")
    env = {
        **os.environ,
        "RAY_TMPDIR": ray_tmp,
        "RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER": "0",
        "RAY_USAGE_STATS_ENABLED": "0",
    }
    path = workdir / "cluster_script.py"
    path.write_text(script)
    try:
        return subprocess.run(
            [sys.executable, str(path), str(workdir)], env=env, capture_output=True, text=True, timeout=timeout
        )
    finally:
        for _ in range(50):  # again until none is left: a raylet may start a worker while the others go
            pids = _processes_with(f"RAY_TMPDIR={ray_tmp}")
            if not pids:
                break
            for pid in pids:
                try:
                    os.kill(pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
            time.sleep(0.1)
        shutil.rmtree(ray_tmp, ignore_errors=True)
