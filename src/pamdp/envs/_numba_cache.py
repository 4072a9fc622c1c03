"""Keeps Numba's on-disk cache of the envs' compiled functions in step with their whole source.

Numba keys a cached function by the content of the one file that defines it, not by the modules whose functions
it calls and inlines: after an edit (or a ``git pull``) that changes ``hfo/goalie.py`` but not ``hfo/defense.py``,
the cached 1v1 loop would keep running the old goalie, with results that look fine. So before any domain module
is imported, :func:`guard` hashes every ``*.py`` file under ``pamdp/envs/`` and compares the digest with a stamp
kept beside the caches; when it differs (or is missing) it deletes the envs' ``*.nbi`` and ``*.nbc`` files and
writes the new stamp, and the next use recompiles.

Where the caches are (Numba's ``CacheImpl._locator_classes``, for a module in directory ``D``):

1. ``NUMBA_CACHE_DIR`` set: ``$NUMBA_CACHE_DIR/<name of D>_<sha1 of D's absolute path>``;
2. otherwise ``D/__pycache__``, when it is writable;
3. otherwise (a read-only install) the user-wide cache, ``numba``'s ``AppDirs`` user cache directory (on Linux
   ``$XDG_CACHE_HOME/numba`` or ``~/.cache/numba``), with the subpath of 1.

:func:`guard` looks after the one location this process's Numba will use, so a location is checked each time a
process is about to read it. Only ``*.nbi`` and ``*.nbc`` files in the cache directories of ``pamdp/envs/`` and
its subpackages are ever deleted. Failing file operations are skipped: a location it cannot write is one Numba
cannot write either, and a file another process deleted first is gone as wanted. The stamp is written by an
atomic rename after the deletions, so processes importing at once (a worker pool) at worst recompile once more.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import tempfile
from pathlib import Path

STAMP = "pamdp_numba_sources.sha256"
CACHE_SUFFIXES = (".nbi", ".nbc")


def source_digest(package_dir: Path) -> str:
    """SHA-256 of the relative path and bytes of every ``*.py`` file under ``package_dir``, in sorted order."""
    digest = hashlib.sha256()
    for path in sorted(package_dir.rglob("*.py")):
        digest.update(path.relative_to(package_dir).as_posix().encode() + b"\0")
        digest.update(path.read_bytes() + b"\0")
    return digest.hexdigest()


def cache_dir(source_dir: Path, cache_root: Path | None) -> Path:
    """Where Numba caches the functions of the modules in ``source_dir``: its ``__pycache__`` (``cache_root`` None)
    or, under ``cache_root``, the subdirectory Numba's ``_CacheLocator.get_suitable_cache_subpath`` names."""
    if cache_root is None:
        return source_dir / "__pycache__"
    absolute = os.path.abspath(source_dir)
    return cache_root / f"{os.path.basename(absolute)}_{hashlib.sha1(absolute.encode()).hexdigest()}"


def clear_stale(package_dir: Path, cache_root: Path | None = None) -> bool:
    """Delete the Numba cache files of ``package_dir``'s modules if its sources changed since the last call;
    return whether it did. ``cache_root`` as in :func:`cache_dir`."""
    package_dir = Path(package_dir)
    digest = source_digest(package_dir)
    stamp = cache_dir(package_dir, cache_root) / STAMP
    with contextlib.suppress(OSError):
        if stamp.read_text() == digest:
            return False
    source_dirs = sorted({path.parent for path in package_dir.rglob("*.py")})
    for directory in (cache_dir(source_dir, cache_root) for source_dir in source_dirs):
        with contextlib.suppress(OSError):
            for entry in os.scandir(directory):
                if entry.name.endswith(CACHE_SUFFIXES) and entry.is_file(follow_symlinks=False):
                    with contextlib.suppress(FileNotFoundError):
                        os.unlink(entry.path)
    _write_atomically(stamp, digest)
    return True


def _write_atomically(path: Path, text: str) -> None:
    with contextlib.suppress(OSError):
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, temporary = tempfile.mkstemp(dir=path.parent, prefix=path.name, suffix=".tmp")
        try:
            with os.fdopen(fd, "w") as file:
                file.write(text)
            os.replace(temporary, path)
        except OSError:
            with contextlib.suppress(OSError):
                os.unlink(temporary)
            raise


def _in_tree_writable(package_dir: Path) -> bool:
    pycache = package_dir / "__pycache__"
    return os.access(pycache if pycache.is_dir() else package_dir, os.W_OK)


def _user_wide_root() -> Path | None:
    # Numba's own choice of directory (it differs by platform); numba is imported here only for a read-only install.
    try:
        from numba.misc.appdirs import AppDirs
    except ImportError:
        return None
    return Path(AppDirs(appname="numba", appauthor=False).user_cache_dir)


def guard(package_dir: Path | None = None) -> bool:
    """:func:`clear_stale` for ``pamdp/envs/`` (or ``package_dir``) at the location Numba will cache it this
    process; return whether it cleared anything. Never raises an ``OSError``."""
    package_dir = Path(__file__).parent if package_dir is None else Path(package_dir)
    try:
        if os.environ.get("NUMBA_CACHE_DIR"):
            return clear_stale(package_dir, Path(os.environ["NUMBA_CACHE_DIR"]))
        if _in_tree_writable(package_dir):
            return clear_stale(package_dir)
        root = _user_wide_root()
        return root is not None and clear_stale(package_dir, root)
    except OSError:
        return False
