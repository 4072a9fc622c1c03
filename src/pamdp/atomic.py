"""Atomic file writes: a temporary file beside the target, fsync, then a rename over it, so that a reader (or a run
killed mid-write) sees the old file or the new one, never a part. Checkpoints (:mod:`pamdp.algos.checkpoints`), a
run's ``run.json``, ``summary.json`` and ``evaluation.json``, and the files a Ray worker sends back are all written
so."""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import IO

__all__ = ["atomic_write", "atomic_write_text"]


def _umask() -> int:
    mask = os.umask(0)  # the only way to read it is to set it
    os.umask(mask)
    return mask


def atomic_write(path: str | os.PathLike, write: Callable[[IO[bytes]], object], example: str) -> None:
    """``write`` into a temporary file beside ``path``, fsync, then rename it over ``path``: a reader (or a run
    killed mid-write) sees the old file or the new one, never a part. ``example``: a file name that the error for a
    ``path`` that is a directory suggests."""
    path = Path(path)
    if path.is_dir():
        raise ValueError(f"cannot save to {path}: it is a directory; expected a file path such as {path / example}")
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp's file is private (0600); the file gets what open() would give
        with os.fdopen(fd, "wb") as f:
            write(f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


def atomic_write_text(path: str | os.PathLike, text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    atomic_write(path, lambda f: f.write(text.encode()), "run.json")
