"""Runs on a Ray cluster (``pamdp reproduce NAME --backend ray --address HOST:PORT``).

Each run is one Ray task (one CPU, one torch thread). The cluster's machines need not share a filesystem:
the task receives the run directory as it stands locally (so an interrupted run resumes from its
checkpoint), trains in a scratch directory on whichever node Ray chose, and returns the directory's files,
which are written back into the same layout as local runs. Needs the ``ray`` extra: ``pip install pamdp[ray]``.
"""

from __future__ import annotations

import tempfile
import time
import traceback
from pathlib import Path

from pamdp.experiments.runner import RunOutcome, RunSpec, _describe, _worker

__all__ = ["run_all_ray"]


def _pack(directory: Path) -> dict[str, bytes]:
    if not directory.exists():
        return {}
    return {str(p.relative_to(directory)): p.read_bytes() for p in directory.rglob("*") if p.is_file()}


def _unpack(files: dict[str, bytes], directory: Path) -> None:
    for rel, data in files.items():
        target = directory / rel
        target.parent.mkdir(parents=True, exist_ok=True)
        tmp = target.with_name(f".{target.name}.tmp")
        tmp.write_bytes(data)
        tmp.replace(target)


def _remote_run(spec: RunSpec, files: dict[str, bytes]) -> tuple[dict | None, str | None, dict[str, bytes]]:
    with tempfile.TemporaryDirectory(prefix="pamdp-ray-") as scratch:
        run_dir = Path(scratch) / "run"
        _unpack(files, run_dir)
        try:
            result, error = _worker(spec, str(run_dir)), None
        except Exception:
            result, error = None, traceback.format_exc()
        return result, error, _pack(run_dir)


def run_all_ray(jobs: list[tuple[RunSpec, str]], address: str | None = None, log=print) -> list[RunOutcome]:
    """Run ``(spec, out_dir)`` jobs as Ray tasks on the cluster at ``address`` (``None``: a local Ray)."""
    try:
        import ray
    except ModuleNotFoundError as exc:
        raise ValueError("the Ray backend needs Ray: pip install 'pamdp[ray]'") from exc
    started_here = not ray.is_initialized()
    if started_here:
        extra = {} if address else {"include_dashboard": False}
        ray.init(address=address, log_to_driver=False, **extra)
    try:
        task = ray.remote(num_cpus=1, max_retries=0)(_remote_run)
        pending = {}
        for spec, out in jobs:
            pending[task.remote(spec, _pack(Path(out)))] = (spec, out, time.time())
        outcomes: list[RunOutcome] = []
        while pending:
            (ref,), _ = ray.wait(list(pending), num_returns=1)
            spec, out, t0 = pending.pop(ref)
            try:
                result, error, files = ray.get(ref)
                _unpack(files, Path(out))
            except Exception:
                result, error = None, traceback.format_exc()
            outcomes.append(RunOutcome(spec, out, result, error, time.time() - t0))
            log(_describe(outcomes[-1]))
        return outcomes
    finally:
        if started_here:
            ray.shutdown()
