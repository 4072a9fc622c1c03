"""The Ray backend: a local Ray head on 127.0.0.1 runs two tiny runs into the usual result layout.

Ray registers a node under the machine's outward address whatever ``--node-ip-address`` says, so the head,
its workers and the driver run inside a fresh network namespace whose only interface is loopback: no
traffic can leave 127.0.0.1.
"""

import shutil
import subprocess
import sys
import tempfile
import textwrap
from pathlib import Path

import pytest

pytest.importorskip("ray")

DRIVER = textwrap.dedent(
    """
    import json, sys
    from pamdp.experiments.ray_backend import run_all_ray
    from pamdp.experiments.runner import RunSpec

    out = sys.argv[1]
    tiny = (("batch_size", 200), ("hidden_sizes", [16]), ("num_envs", 4), ("vf_hidden_sizes", [16]))
    spec = lambda s: RunSpec("patrpo", "pamdp/Platform-v0", 400, s, "paper", tiny, 5, "tiny")
    jobs = [(spec(s), f"{out}/seed{s}") for s in (0, 1)]
    outcomes = run_all_ray(jobs, address="127.0.0.1:6379", log=print)
    json.dump([o.error for o in outcomes], open(f"{out}/errors.json", "w"))
    """
)


def loopback_namespace_available():
    if shutil.which("unshare") is None or shutil.which("ip") is None:
        return False
    probe = subprocess.run(["unshare", "-n", "--", "ip", "link", "set", "lo", "up"], capture_output=True)
    return probe.returncode == 0


@pytest.mark.skipif(not loopback_namespace_available(), reason="needs unshare -n (root) for a loopback-only network")
def test_two_tiny_runs_through_a_local_ray_head(tmp_path):
    bindir = Path(sys.executable).parent
    driver = tmp_path / "driver.py"
    driver.write_text(DRIVER)
    ray_tmp = tempfile.mkdtemp(prefix="ray", dir="/tmp")  # short: Ray's socket paths must fit in 107 bytes
    script = (
        "set -e; ip link set lo up; "
        f"{bindir}/ray start --head --node-ip-address=127.0.0.1 --port=6379 --num-cpus=2 "
        f"--include-dashboard=false --disable-usage-stats --temp-dir={ray_tmp} > {tmp_path}/ray_start.log 2>&1; "
        f"rc=0; {sys.executable} {driver} {tmp_path} || rc=$?; "
        f"{bindir}/ray stop --force > /dev/null 2>&1; exit $rc"
    )
    try:
        done = subprocess.run(["unshare", "-n", "--", "sh", "-c", script], capture_output=True, text=True, timeout=400)
    finally:
        shutil.rmtree(ray_tmp, ignore_errors=True)
    assert done.returncode == 0, done.stdout + done.stderr
    assert (tmp_path / "errors.json").read_text() == "[null, null]"
    for seed in (0, 1):
        run = tmp_path / f"seed{seed}"
        for name in ("run.json", "progress.csv", "final_model.pt", "evaluation.json"):
            assert (run / name).exists(), run / name
