"""Runs on a Ray cluster (``pamdp reproduce NAME --backend ray --address HOST:PORT``).

Each run is one Ray task (one CPU, one torch thread). The cluster's machines need not share a filesystem:
the run directories stay on the driver's machine, where one writer, an actor pinned to the driver's node,
keeps them. A task fetches its run directory from it as it stands (so an interrupted run resumes from its
checkpoint), trains in a scratch directory on whichever node Ray chose, and sends back what changed after
every epoch (the new checkpoint, ``progress.csv``, ``run.json``, the new tails of the logs) and once more at
the end, when the driver makes the run's ``summary.json`` again from its own copy (the task's names the scratch
directory as where the run lies). A task whose node or worker process dies is retried (``retries`` times) and
resumes from the last checkpoint that reached the driver; the resumed run drops the rows of ``progress.csv`` logged
after it, so no epoch is counted twice. Needs the ``ray`` extra: ``pip install pamdp[ray]``.
"""

from __future__ import annotations

import contextlib
import os
import sys
import tempfile
import time
import traceback
from pathlib import Path

from pamdp.atomic import atomic_write
from pamdp.experiments.runner import RunOutcome, RunSpec, _describe, _worker, run_lock
from pamdp.experiments.summary import SUMMARY, write_summary

__all__ = ["run_all_ray", "RETRIES"]

RETRIES = 3
"""How many times a run is started again after its node or worker process died (Ray's ``max_retries``)."""

_LAST = "checkpoint.pt"  # written last of a batch: a torn batch leaves a log newer than the checkpoint


def _appended(rel: str) -> bool:
    """Whether a run directory's file grows only by appending (TensorBoard's event files, the run's log): after
    its first send, only the tail appended since goes. Every other file is replaced whole (atomically) on each
    write, so it goes whole when it changed."""
    return rel.startswith("tb/") or rel == "stdout.log"


def _files(directory: Path) -> list[tuple[str, Path]]:
    """A run directory's files by relative path, less hidden ones (a lock file, a write's temporary file)."""
    found = []
    for path in sorted(directory.rglob("*")):
        rel = path.relative_to(directory)
        if path.is_file() and not any(part.startswith(".") for part in rel.parts):
            found.append((rel.as_posix(), path))
    return found


def _pack(directory: Path) -> dict[str, bytes]:
    return {rel: path.read_bytes() for rel, path in _files(directory)}


def _write(target: Path, offset: int, data: bytes) -> None:
    """Put ``data`` at ``offset`` of ``target``: a whole new file (atomically) at 0, an appended tail past it."""
    if offset == 0:
        atomic_write(target, lambda f: f.write(data), target.name)
        return
    size = target.stat().st_size if target.exists() else 0
    if size < offset:
        raise ValueError(f"{target} holds {size} bytes; expected at least {offset} to append at that offset")
    with open(target, "r+b") as f:
        f.seek(offset)
        f.write(data)
        f.truncate()


class _Inbox:
    """The one writer of the run directories, an actor on the driver's node.

    It holds each run directory's lock (:func:`pamdp.experiments.runner.run_lock`) from the run's first attempt
    until the sweep ends, so no other pamdp process writes into it meanwhile. Each attempt at a run opens it
    and gets a token; a write with an older attempt's token (from a worker that Ray gave up on but that still
    runs) is refused, so a run directory has one writer at a time.
    """

    def __init__(self):
        self.attempts: dict[str, int] = {}
        self.locks = contextlib.ExitStack()

    def open(self, out: str) -> tuple[int, dict[str, bytes]]:
        if out not in self.attempts:
            self.locks.enter_context(run_lock(out))  # refused with the holder's name if another process has it
        self.attempts[out] = self.attempts.get(out, 0) + 1
        return self.attempts[out], _pack(Path(out))

    def write(self, out: str, attempt: int, changes: list[tuple[str, int, bytes]]) -> bool:
        if self.attempts.get(out) != attempt:
            return False
        for rel, offset, data in sorted(changes, key=lambda c: c[0] == _LAST):
            _write(Path(out) / rel, offset, data)
        if any(rel == SUMMARY for rel, _, _ in changes):  # made again here: it names where the run lies
            write_summary(out)
        return True

    def close(self) -> None:
        """Let the run directories go (the sweep is over): no attempt writes any more."""
        self.attempts.clear()
        self.locks.close()


class _Mirror:
    """A task's side of its run directory: sends the driver what changed in ``run_dir`` since the last send."""

    def __init__(self, inbox, out: str, attempt: int, run_dir: Path):
        self.inbox, self.out, self.attempt, self.run_dir = inbox, out, attempt, run_dir
        self.sent: dict[str, tuple[tuple[int, int, int], int]] = {}  # file: (its stat when sent, bytes sent)
        self._scan()  # run_dir holds what the driver holds: marked as sent

    def _scan(self) -> list[tuple[str, int, bytes]]:
        changes = []
        for rel, path in _files(self.run_dir):
            st = path.stat()
            key = (st.st_ino, st.st_size, st.st_mtime_ns)
            previous_key, sent = self.sent.get(rel, (None, 0))
            if key == previous_key:
                continue
            offset = sent if _appended(rel) and st.st_size >= sent else 0
            with open(path, "rb") as f:
                f.seek(offset)
                data = f.read()
            changes.append((rel, offset, data))
            self.sent[rel] = (key, offset + len(data))
        return changes

    def send(self, *_epoch) -> None:
        """Send the changes and wait until the driver holds them (also a ``learn`` callback: after each epoch)."""
        import ray

        changes = self._scan()
        if changes and not ray.get(self.inbox.write.remote(self.out, self.attempt, changes)):
            raise RuntimeError(
                f"{self.out} takes no more writes from this attempt (a later one took over, or the sweep ended)"
            )


def _remote_run(spec: RunSpec, out: str, inbox, command: list[str]) -> tuple[dict | None, str | None]:
    import ray

    attempt, files = ray.get(inbox.open.remote(out))
    with tempfile.TemporaryDirectory(prefix="pamdp-ray-") as scratch:
        run_dir = Path(scratch) / "run"
        run_dir.mkdir()
        for rel, data in files.items():
            _write(run_dir / rel, 0, data)
        mirror = _Mirror(inbox, out, attempt, run_dir)
        with open(run_dir / "stdout.log", "a") as f:
            node = ray.get_runtime_context().get_node_id()
            print(f"attempt {attempt} on Ray node {node} ({ray.util.get_node_ip_address()})", file=f)
        worker_argv, sys.argv = sys.argv, command  # run.json records the command that started the sweep
        try:
            result, error = _worker(spec, str(run_dir), callback=mirror.send), None
        except Exception:
            result, error = None, traceback.format_exc()
        finally:
            sys.argv = worker_argv
        mirror.send()
        return result, error


def run_all_ray(
    jobs: list[tuple[RunSpec, str]], address: str | None = None, log=print, retries: int = RETRIES
) -> list[RunOutcome]:
    """Run ``(spec, out_dir)`` jobs as Ray tasks on the cluster at ``address`` (``None``: a local Ray).

    ``retries``: how many times a run whose node or worker process died starts again, from the last
    checkpoint it sent.
    """
    try:
        import ray
        from ray.util.scheduling_strategies import NodeAffinitySchedulingStrategy
    except ModuleNotFoundError as exc:
        raise ValueError("the Ray backend needs Ray: pip install 'pamdp[ray]'") from exc
    if isinstance(retries, bool) or not isinstance(retries, int) or retries < 0:
        raise ValueError(f"retries = {retries!r}; expected an integer >= 0")
    started_here = not ray.is_initialized()
    if started_here:
        extra = {} if address else {"include_dashboard": False}
        ray.init(address=address, log_to_driver=False, **extra)
    try:
        here = NodeAffinitySchedulingStrategy(ray.get_runtime_context().get_node_id(), soft=False)
        inbox = ray.remote(_Inbox).options(num_cpus=0, scheduling_strategy=here).remote()
        task = ray.remote(num_cpus=1, max_retries=retries)(_remote_run)
        pending = {}
        for spec, out in jobs:
            pending[task.remote(spec, os.path.abspath(out), inbox, sys.argv)] = (spec, out, time.time())
        outcomes: list[RunOutcome] = []
        try:
            while pending:
                (ref,), _ = ray.wait(list(pending), num_returns=1)
                spec, out, t0 = pending.pop(ref)
                try:
                    result, error = ray.get(ref)
                except Exception:
                    result, error = None, traceback.format_exc()
                outcomes.append(RunOutcome(spec, out, result, error, time.time() - t0))
                log(_describe(outcomes[-1]))
        finally:  # interrupted: the runs still going stop, and their directories are let go
            for ref in pending:
                ray.cancel(ref, force=True)
            ray.get(inbox.close.remote())
        return outcomes
    finally:
        if started_here:
            ray.shutdown()
