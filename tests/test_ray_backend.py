"""The Ray backend: run directories mirrored to the driver as they are written, and a sweep that survives
the loss of a worker node (a real two-node Ray cluster on 127.0.0.1, see :mod:`ray_cluster`)."""

import csv
import json
import os
import re
import sys
import textwrap
from pathlib import Path

import pytest
from ray_cluster import run_on_local_cluster

from pamdp.experiments.ray_backend import _Inbox, _Mirror
from pamdp.experiments.runner import run_lock


class _Rounds:
    """Sends a mirror's changes straight into an inbox, without Ray (the calls Ray would carry)."""

    def __init__(self, inbox: _Inbox, out: Path, run_dir: Path):
        self.inbox, self.out = inbox, str(out)
        attempt, files = inbox.open(self.out)
        run_dir.mkdir()
        assert files == {path.relative_to(out).as_posix(): path.read_bytes() for path in _tree(out)}
        for rel, data in files.items():
            (run_dir / rel).parent.mkdir(parents=True, exist_ok=True)
            (run_dir / rel).write_bytes(data)
        self.mirror = _Mirror(None, self.out, attempt, run_dir)

    def send(self) -> bool:
        self.sent = self.mirror._scan()
        return self.inbox.write(self.out, self.mirror.attempt, self.sent)


def _tree(directory: Path) -> list[Path]:
    """The files, less the lock file and its holder's name, which each side keeps for itself."""
    return sorted(p for p in directory.rglob("*") if p.is_file() and p.name not in (".lock", ".lock-holder"))


def _same_files(a: Path, b: Path) -> None:
    assert {p.relative_to(a).as_posix(): p.read_bytes() for p in _tree(a)} == {
        p.relative_to(b).as_posix(): p.read_bytes() for p in _tree(b)
    }


def test_the_driver_copy_follows_rewrites_and_appends_and_refuses_an_older_attempt(tmp_path):
    out, first, second = tmp_path / "out", tmp_path / "first", tmp_path / "second"
    inbox = _Inbox()
    a = _Rounds(inbox, out, first)
    (first / ".lock-holder").write_text("pamdp process 1 on worker\n")  # hidden: stays on the worker
    (first / "tb").mkdir()
    for epoch in range(1, 4):
        (first / "checkpoint.pt").write_bytes(bytes([epoch]) * (100 - epoch))  # rewritten whole, shorter
        with open(first / "tb" / "events.1", "ab") as f:
            f.write(f"scalar {epoch};".encode())
        with open(first / "stdout.log", "a") as f:
            f.write(f"epoch {epoch}\n")
        assert a.send()
        _same_files(first, out)
        if epoch > 1:  # the logs go as their new tails, the checkpoint whole
            assert sorted(a.sent) == [
                ("checkpoint.pt", 0, bytes([epoch]) * (100 - epoch)),
                ("stdout.log", 8 * (epoch - 1), f"epoch {epoch}\n".encode()),
                ("tb/events.1", 9 * (epoch - 1), f"scalar {epoch};".encode()),
            ]
    holder = (out / ".lock-holder").read_text()
    assert holder.startswith(f"pamdp process {os.getpid()} on"), "the worker's lock file stays on the worker"
    sent = a.mirror._scan()
    assert sent == [], "nothing changed, nothing to send"

    b = _Rounds(inbox, out, second)  # Ray retried the run elsewhere: it starts from the driver's copy
    _same_files(out, second)
    with open(first / "stdout.log", "a") as f:
        f.write("the first attempt still runs\n")
    assert not a.send(), "the older attempt may no longer write"
    with open(second / "stdout.log", "a") as f:
        f.write("resumed\n")
    assert b.send()
    assert (out / "stdout.log").read_text() == "epoch 1\nepoch 2\nepoch 3\nresumed\n"
    _same_files(second, out)
    inbox.close()


def test_the_driver_makes_the_runs_summary_again_from_its_own_copy(tmp_path):
    """A task's summary.json names the task's scratch directory as where the run lies; the driver's names its own."""
    from pamdp.experiments.summary import summarize

    scratch, out = tmp_path / "scratch" / "pamdp-ray-x" / "run", tmp_path / "sweep" / "arm" / "seed0"
    scratch.mkdir(parents=True)
    (scratch / "run.json").write_text(json.dumps({"algo": "patrpo", "env": "pamdp/Platform-v0", "label": "arm"}))
    (scratch / "progress.csv").write_text("time/total_timesteps,eval/mean_return\n100,0.5\n")
    (scratch / "summary.json").write_text(json.dumps(summarize(scratch)))
    inbox = _Inbox()
    attempt, _ = inbox.open(str(out))
    assert inbox.write(str(out), attempt, [(p.name, 0, p.read_bytes()) for p in sorted(scratch.iterdir())])
    inbox.close()
    summary = json.loads((out / "summary.json").read_text())
    assert summary["origin"] == "sweep/arm/seed0" and summary["evaluations"]["mean_return"] == [0.5]
    assert summary == summarize(out)


def test_a_sweep_holds_its_run_directories_against_other_writers_until_it_ends(tmp_path):
    out = tmp_path / "run"
    with run_lock(out):  # a local `pamdp train` writing there
        with pytest.raises(ValueError, match=r"is in use: pamdp process \d+ on "):
            _Inbox().open(str(out))
    inbox = _Inbox()
    attempt, _ = inbox.open(str(out))
    with pytest.raises(ValueError, match="is in use"), run_lock(out):
        pass
    inbox.close()
    assert not inbox.write(str(out), attempt, [("progress.csv", 0, b"late\n")]), "the sweep is over"
    assert not (out / "progress.csv").exists()
    with run_lock(out):  # free again
        pass


def _rows(path: Path) -> list[dict]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


STEPS, EPOCH_STEPS = 1200, 200

NODE_LOSS = textwrap.dedent(
    f"""
    import json, shutil, sys, threading, time
    from pathlib import Path

    from ray.cluster_utils import Cluster

    from pamdp.experiments.ray_backend import run_all_ray
    from pamdp.experiments.runner import RunSpec

    t0 = time.time()
    out = Path(sys.argv[1])
    local = dict(node_ip_address="127.0.0.1", num_cpus=1)
    cluster = Cluster(initialize_head=True, head_node_args=dict(include_dashboard=False, **local))
    worker = cluster.add_node(**local)
    tiny = (("batch_size", {EPOCH_STEPS}), ("hidden_sizes", [16]), ("num_envs", 4), ("vf_hidden_sizes", [16]))
    spec = lambda seed: RunSpec("patrpo", "pamdp/Platform-v0", {STEPS}, seed, "paper", tiny, 5)
    jobs = [(spec(seed), str(out / f"seed{{seed}}")) for seed in (0, 1)]

    def kill_the_worker_node_after_its_first_checkpoint():
        while True:
            for seed in (0, 1):
                run = out / f"seed{{seed}}"
                if (run / "checkpoint.pt").exists() and worker.node_id in (run / "stdout.log").read_text():
                    shutil.copy(run / "progress.csv", out / "before_kill.csv")
                    cluster.remove_node(worker, allow_graceful=False)
                    (out / "killed.json").write_text(json.dumps(dict(seed=seed, head=cluster.head_node.node_id)))
                    return
            time.sleep(0.05)

    killer = threading.Thread(target=kill_the_worker_node_after_its_first_checkpoint, daemon=True)
    killer.start()
    print(f"cluster up in {{time.time() - t0:.1f}} s", flush=True)
    outcomes = run_all_ray(jobs, address=cluster.address, log=print)
    print(f"sweep over in {{time.time() - t0:.1f}} s", flush=True)
    killer.join(timeout=1)
    (out / "errors.json").write_text(json.dumps([o.error for o in outcomes]))
    cluster.shutdown()
    print(f"cluster down in {{time.time() - t0:.1f}} s", flush=True)
    """
)


@pytest.mark.skipif(sys.platform != "linux", reason="Ray runs multi-node clusters on Linux only")
def test_a_sweep_survives_the_loss_of_a_worker_node_and_its_run_resumes_from_its_checkpoint(tmp_path):
    pytest.importorskip("ray")
    done = run_on_local_cluster(NODE_LOSS, tmp_path, timeout=240)
    assert done.returncode == 0, done.stdout + done.stderr
    assert json.loads((tmp_path / "errors.json").read_text()) == [None, None]
    assert (tmp_path / "killed.json").exists(), "the worker node's run ended before its node could be killed"
    killed = json.loads((tmp_path / "killed.json").read_text())
    for seed in (0, 1):
        run = tmp_path / f"seed{seed}"
        for name in ("run.json", "final_model.pt", "evaluation.json"):
            assert (run / name).exists(), run / name
        assert json.loads((run / "run.json").read_text())["command"] == [
            str(tmp_path / "cluster_script.py"),
            str(tmp_path),
        ]
        rows = _rows(run / "progress.csv")
        steps = [float(r["time/total_timesteps"]) for r in rows]
        assert [float(r["time/epoch"]) for r in rows] == list(range(1, len(rows) + 1)), "each epoch exactly once"
        assert steps == sorted(set(steps)) and steps[-2] < STEPS <= steps[-1], steps
        log = (run / "stdout.log").read_text()
        resumed = [int(s.replace(",", "")) for s in re.findall(r"resuming \S+ at step ([\d,]+) of", log)]
        if seed != killed["seed"]:
            assert resumed == [], log
            continue
        assert f"attempt 2 on Ray node {killed['head']}" in log, log
        assert len(resumed) == 1 and EPOCH_STEPS <= resumed[0] < STEPS, log  # from a checkpoint, not from 0
        kept = min(steps.index(resumed[0]) + 1, len(before := _rows(tmp_path / "before_kill.csv")))
        # the epochs trained before the kill are kept (their wall-clock columns included), not trained again
        assert kept >= 1 and rows[:kept] == before[:kept]
