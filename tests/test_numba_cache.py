"""The guard of Numba's on-disk cache (``pamdp/envs/_numba_cache.py``): the envs' cache files go when any source
under the package changes, stay while none does, and nothing else is ever deleted; run on small packages written
into a temporary directory."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import threading
from pathlib import Path

import numba
from numba.core import caching

from pamdp.envs import _numba_cache
from pamdp.envs._numba_cache import cache_dir, clear_stale, guard

# What Numba writes for a cached function (index and data) and what Python writes beside it.
NUMBA_FILES = ("step-12.py311.nbi", "step-12.py311.1.nbc")
OTHER_FILES = ("dynamics.cpython-311.pyc", "notes.txt")


def make_package(root: Path) -> Path:
    package = root / "envs"
    (package / "hfo").mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "vector.py").write_text("def step(): return 1\n")
    (package / "hfo" / "__init__.py").write_text("")
    (package / "hfo" / "goalie.py").write_text("def decide(): return 1\n")
    return package


def fill(directory: Path) -> list[Path]:
    directory.mkdir(parents=True, exist_ok=True)
    files = [directory / name for name in (*NUMBA_FILES, *OTHER_FILES)]
    for path in files:
        path.write_bytes(b"x")
    return files


def existing(paths) -> list[str]:
    return sorted(str(path) for path in paths if path.exists())


def test_caches_stay_while_the_sources_do_and_go_after_an_edit_of_any(tmp_path):
    package = make_package(tmp_path)
    top, hfo = fill(package / "__pycache__"), fill(package / "hfo" / "__pycache__")
    # Beside the package, never touched: another package's caches and a stray cache file.
    outside = fill(tmp_path / "__pycache__") + fill(tmp_path / "other" / "__pycache__")
    assert clear_stale(package)  # no stamp yet: what is there may be stale
    fill(package / "__pycache__")
    fill(package / "hfo" / "__pycache__")

    assert not clear_stale(package)
    assert not clear_stale(package)
    assert existing(top + hfo + outside) == sorted(map(str, top + hfo + outside))

    (package / "hfo" / "goalie.py").write_text("def decide(): return 2\n")  # the callee alone, as in the bug
    assert clear_stale(package)
    kept = [path for path in top + hfo if path.name in OTHER_FILES]
    assert existing(top + hfo) == sorted(map(str, kept))
    assert existing(outside) == sorted(map(str, outside))
    assert not clear_stale(package)


def test_a_new_or_renamed_source_file_counts_as_a_change(tmp_path):
    package = make_package(tmp_path)
    clear_stale(package)
    (package / "hfo" / "goalie.py").rename(package / "hfo" / "keeper.py")
    assert clear_stale(package)
    (package / "hfo" / "two_player.py").write_text("")
    assert clear_stale(package)


def test_the_cache_dirs_under_a_root_are_numbas_own(tmp_path, monkeypatch):
    # NUMBA_CACHE_DIR (and the user-wide cache) hold a module's caches in a subdirectory named by Numba's locator.
    package = make_package(tmp_path)
    monkeypatch.setattr(numba.core.config, "CACHE_DIR", str(tmp_path / "cache"))
    py_file = package / "hfo" / "goalie.py"
    locator = caching.UserProvidedCacheLocator(lambda: None, str(py_file))
    assert cache_dir(py_file.parent, tmp_path / "cache") == Path(locator.get_cache_path())
    in_tree = caching.InTreeCacheLocator(lambda: None, str(py_file))
    assert cache_dir(py_file.parent, None) == Path(in_tree.get_cache_path())


def test_with_numba_cache_dir_the_guard_clears_that_location(tmp_path, monkeypatch):
    package = make_package(tmp_path)
    root = tmp_path / "numba-cache"
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(root))
    guard(package)
    mirrored = fill(cache_dir(package, root)) + fill(cache_dir(package / "hfo", root))
    other_project = fill(root / "project_0123")
    in_tree = fill(package / "hfo" / "__pycache__")  # not where Numba reads this process: left alone

    assert not guard(package)
    (package / "vector.py").write_text("def step(): return 2\n")
    assert guard(package)
    assert existing(mirrored) == sorted(str(path) for path in mirrored if path.name in OTHER_FILES)
    assert existing(other_project + in_tree) == sorted(map(str, other_project + in_tree))


def test_an_unwritable_location_is_skipped_silently(tmp_path, monkeypatch):
    package = make_package(tmp_path)
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(blocker / "cache"))  # mkdir fails: NotADirectoryError
    guard(package)  # does not raise
    assert blocker.is_file()
    monkeypatch.delenv("NUMBA_CACHE_DIR")
    # A read-only install: the guard goes where Numba then caches, the user-wide directory.
    monkeypatch.setattr(_numba_cache, "_in_tree_writable", lambda package_dir: False)
    monkeypatch.setattr(_numba_cache, "_user_wide_root", lambda: tmp_path / "user-cache")
    user_wide = fill(cache_dir(package / "hfo", tmp_path / "user-cache"))
    assert guard(package)
    assert existing(user_wide) == sorted(str(path) for path in user_wide if path.name in OTHER_FILES)
    assert not (package / "__pycache__").exists()


def test_processes_clearing_at_once_do_not_fail(tmp_path):
    package = make_package(tmp_path)
    caches = fill(package / "__pycache__") + fill(package / "hfo" / "__pycache__")
    errors = []

    def clear():
        try:
            clear_stale(package)
        except Exception as error:  # noqa: BLE001 - any failure of a racing clearer is the finding
            errors.append(error)

    threads = [threading.Thread(target=clear) for _ in range(8)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert errors == []
    assert existing(caches) == sorted(str(path) for path in caches if path.name in OTHER_FILES)
    assert not clear_stale(package)
    assert [path.name for path in (package / "__pycache__").iterdir() if path.suffix == ".tmp"] == []


def test_the_envs_guard_is_cheap():
    # It runs at every `import pamdp`: ~35 files, ~300 kB; about 1.5 ms measured on a busy shared core.
    import time

    start = time.perf_counter()
    for _ in range(10):
        guard()
    assert (time.perf_counter() - start) / 10 < 0.05


CALLEE = "import numba\n\n\n@numba.njit(cache=True)\ndef value():\n    return {}\n"
CALLER = """
import numba

from fake_envs.callee import value


@numba.njit(cache=True)
def run():
    return value()
"""
INIT = """
import os
from pathlib import Path

from pamdp.envs._numba_cache import guard

if not os.environ.get("SKIP_GUARD"):
    guard(Path(__file__).parent)
"""


def test_end_to_end_an_edit_of_the_inlined_module_alone_is_compiled_in(tmp_path):
    package = tmp_path / "fake_envs"
    package.mkdir()
    (package / "__init__.py").write_text(textwrap.dedent(INIT))
    (package / "caller.py").write_text(textwrap.dedent(CALLER))
    (package / "callee.py").write_text(CALLEE.format(1))
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env["PYTHONPATH"] = os.pathsep.join([str(tmp_path), str(Path(_numba_cache.__file__).parents[2])])

    def run(**extra):
        done = subprocess.run(
            [sys.executable, "-c", "from fake_envs.caller import run; print(run())"],
            env={**env, **extra},
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert done.returncode == 0, done.stderr
        return int(done.stdout)

    assert run() == 1
    assert list((package / "__pycache__").glob("caller*.nbi"))  # cached, in the tree
    (package / "callee.py").write_text(CALLEE.format(2))
    assert run(SKIP_GUARD="1") == 1  # Numba alone replays the caller's cache with the old callee inlined
    assert run() == 2
    assert run() == 2
