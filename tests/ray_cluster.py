"""A script run beside a local Ray cluster that lives on 127.0.0.1 only, and is gone afterwards.

The script starts its cluster itself (``ray.cluster_utils.Cluster``: a head and worker nodes, each its own
raylet process, which the script may kill). ``RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER=0`` makes Ray take the
loopback address as every node's own, so no traffic leaves 127.0.0.1; ``RAY_TMPDIR`` gives the cluster a
directory of its own, short enough for Ray's socket paths (107 bytes at most). Every process that holds a
file of that directory open (or names it in its environment), or that is still in the script's process group,
is the script's or its cluster's: all of them are killed at the end, however the script ended.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def _processes_using(directory: str) -> list[int]:
    """The ids of the processes that hold a file under ``directory`` open or have it in their environment.

    Ray's processes keep their logs there open; the environment alone is not enough, since a process that
    renames itself (``ray::DashboardAgent``) may overwrite it.
    """
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit() or int(entry.name) == os.getpid():
            continue
        try:
            marks = [os.readlink(fd) for fd in (entry / "fd").iterdir()]
            marks += (entry / "environ").read_bytes().decode(errors="replace").split("\0")
        except OSError:  # gone meanwhile, or not ours to read
            continue
        if any(directory in mark for mark in marks):
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
    with subprocess.Popen(
        [sys.executable, str(path), str(workdir)],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,  # its own process group, which Ray's processes stay in
    ) as script_process:
        try:
            stdout, stderr = script_process.communicate(timeout=timeout)
        finally:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(script_process.pid, signal.SIGKILL)
            for _ in range(50):  # again until none is left: a raylet may start a worker while the others go
                pids = _processes_using(ray_tmp)
                if not pids:
                    break
                for pid in pids:
                    with contextlib.suppress(ProcessLookupError):
                        os.kill(pid, signal.SIGKILL)
                time.sleep(0.1)
            shutil.rmtree(ray_tmp, ignore_errors=True)
    return subprocess.CompletedProcess(script_process.args, script_process.returncode, stdout, stderr)
