"""Keeping Numba's on-disk cache of a kernel module in step with the modules whose constants it compiles in.

Numba keys a cached kernel on its own source file's modification time and size only. The kernels of
``hfo_kernel.py`` and ``platform_kernel.py`` also fold in constants of other modules, so each module calls
:func:`refresh_cache` at import, before its first kernel is compiled or loaded: it keeps a digest of those
modules next to the cache and drops the cached kernels when the digest changes.
"""

from __future__ import annotations

import hashlib
import importlib
from collections.abc import Sequence
from pathlib import Path

__all__ = ["refresh_cache", "KernelPickling"]


def refresh_cache(kernel_file: str | Path, dependencies: Sequence[str], directory: Path | None = None) -> bool:
    """Drop ``kernel_file``'s cached kernels if the ``dependencies`` (file names next to it) changed; True if it did.

    The digest is kept in ``__pycache__/<kernel module>.deps`` (or in ``directory``). A read-only install is
    left alone: its files do not change, and an upgrade rewrites the kernel module too, which Numba notices.
    """
    here = Path(kernel_file)
    cache = directory if directory is not None else here.parent / "__pycache__"
    digest = hashlib.sha256(b"".join(here.with_name(name).read_bytes() for name in dependencies)).hexdigest()
    stamp = cache / f"{here.stem}.deps"
    try:
        if stamp.read_text() == digest:
            return False
    except OSError:
        pass
    try:
        cache.mkdir(exist_ok=True)
        for stale in [*cache.glob(f"{here.stem}.*.nbi"), *cache.glob(f"{here.stem}.*.nbc")]:
            stale.unlink()
        stamp.write_text(digest)
    except OSError:
        return False
    return True


class KernelPickling:
    """Lets a batched env that keeps its kernel module in ``self._kernel`` be pickled and deep-copied (a module
    object is neither): the module travels by name and is imported again on the other side."""

    def __getstate__(self) -> dict:
        state = self.__dict__.copy()
        if state.get("_kernel") is not None:
            state["_kernel"] = state["_kernel"].__name__
        return state

    def __setstate__(self, state: dict) -> None:
        if isinstance(state.get("_kernel"), str):
            state["_kernel"] = importlib.import_module(state["_kernel"])
        self.__dict__.update(state)
