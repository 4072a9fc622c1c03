"""Checkpoints and atomic writes.

A checkpoint is one file written atomically (a temporary file, fsync, rename) holding tensors and plain data
only; it is read back with ``torch.load(weights_only=True)``, so loading never executes code. Loading a model whichever
algorithm wrote it is the registry's :func:`pamdp.algos.load_model`.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import IO

import torch

__all__ = ["FINAL_MODEL", "CHECKPOINT", "FORMAT", "atomic_save", "atomic_write_text", "read_checkpoint"]

FINAL_MODEL = "final_model.pt"
CHECKPOINT = "checkpoint.pt"
FORMAT = "pamdp-checkpoint"
"""The ``format`` entry of every checkpoint, which tells a pamdp checkpoint from any other torch file."""


def _umask() -> int:
    mask = os.umask(0)  # the only way to read it is to set it
    os.umask(mask)
    return mask


def _atomic_write(path: str | os.PathLike, write: Callable[[IO[bytes]], object], example: str) -> None:
    """``write`` into a temporary file beside ``path``, fsync, then rename it over ``path``: a reader (or a run
    killed mid-write) sees the old file or the new one, never a part."""
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


def atomic_save(payload: dict, path: str | os.PathLike) -> None:
    """``torch.save`` to a temporary file beside ``path``, fsync, then rename over it."""
    _atomic_write(path, lambda f: torch.save(payload, f), "model.pt")


def atomic_write_text(path: str | os.PathLike, text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically, as :func:`atomic_save` does a checkpoint."""
    _atomic_write(path, lambda f: f.write(text.encode()), "run.json")


def _resolve_model_path(path: str | os.PathLike) -> Path:
    path = Path(path)
    if path.is_dir():
        for name in (FINAL_MODEL, CHECKPOINT):
            if (path / name).is_file():
                return path / name
        raise FileNotFoundError(f"run directory {path} holds neither {FINAL_MODEL} nor {CHECKPOINT}")
    if not path.is_file():
        raise FileNotFoundError(f"no pamdp model at {path}: expected a checkpoint file or a run directory")
    return path


def _load_failure(exc: Exception) -> str:
    """What ``torch.load`` found wrong, without its advice to retry with ``weights_only=False``: that would run
    whatever code the file holds."""
    advice = ("weights_only", "Weights only", "file an issue", "documentation of torch.load")
    lines = [line.strip() for line in str(exc).splitlines()]
    found = [line for line in lines if line and not any(a in line for a in advice)]
    return f"{type(exc).__name__}: {found[0].split('. ')[0]}" if found else type(exc).__name__


def read_checkpoint(path: str | os.PathLike) -> dict:
    """Read a checkpoint with ``weights_only=True``, its tensors on the CPU (whatever device saved them, so a model
    trained on a GPU reads where there is none); a file that is not one raises a clear ``ValueError``."""
    path = _resolve_model_path(path)
    try:
        payload = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as exc:
        raise ValueError(
            f"{path} is not a readable pamdp checkpoint ({_load_failure(exc)}); expected a file written by pamdp's "
            "save, which holds tensors and plain data only"
        ) from exc
    if not isinstance(payload, dict) or payload.get("format") != FORMAT:
        raise ValueError(f"{path} is not a pamdp checkpoint (no '{FORMAT}' header)")
    return payload
