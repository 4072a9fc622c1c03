"""The Numba kernels' on-disk cache follows the modules whose constants they compile in (``numba_cache.py``)."""

import pytest


@pytest.mark.parametrize(
    "module, cached, other",
    [
        (
            "hfo_kernel",
            ["hfo_kernel._dash-145.py311.nbi", "hfo_kernel._dash-145.py311.1.nbc"],
            "hfo_vector.cpython-311.pyc",
        ),
        (
            "platform_kernel",
            ["platform_kernel.run_substeps-170.py311.nbi", "platform_kernel._clip-1.py311.1.nbc"],
            "platform_vector.cpython-311.pyc",
        ),
    ],
)
def test_cached_kernels_are_dropped_when_a_module_they_compile_in_changes(tmp_path, module, cached, other):
    kernel = pytest.importorskip(f"pamdp.envs.{module}")
    cached, other = [tmp_path / name for name in cached], tmp_path / other
    for f in (*cached, other):
        f.write_bytes(b"x")
    (tmp_path / f"{module}.deps").write_text("the digest of older modules")
    assert kernel.refresh_cache(tmp_path) is True
    assert not any(f.exists() for f in cached) and other.exists()
    # The digest now matches the modules as they are: a second call leaves a fresh cache alone.
    for f in cached:
        f.write_bytes(b"x")
    assert kernel.refresh_cache(tmp_path) is False
    assert all(f.exists() for f in cached)
    # A change of a dependency (here: a digest written for other contents) drops them again.
    (tmp_path / f"{module}.deps").write_text("another digest")
    assert kernel.refresh_cache(tmp_path) is True and not any(f.exists() for f in cached)
