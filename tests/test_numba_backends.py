"""What the batched envs' Numba backends share: the choice of backend, and the kernels' on-disk cache following
the modules whose constants they compile in (``numba_cache.py``). Each backend's numbers against its NumPy
reference: ``test_hfo_kernel.py``. (Platform has one backend, compiled: ``test_platform_vector.py``.)"""

import builtins

import gymnasium
import pytest

import pamdp  # noqa: F401  (registers the envs)
from pamdp.envs.hfo_vector import HalfFieldOffenseVectorEnv


@pytest.mark.parametrize("env_id, cls", [("pamdp/HalfFieldOffense-v0", HalfFieldOffenseVectorEnv)])
def test_backend_choice_and_errors(monkeypatch, env_id, cls):
    assert cls(backend="numpy").backend == "numpy"
    venv = gymnasium.make_vec(env_id, num_envs=2, vectorization_mode="vector_entry_point", backend="numpy")
    assert isinstance(venv, cls) and venv.backend == "numpy"
    with pytest.raises(ValueError, match="backend='jax'; expected 'auto', 'numpy' or 'numba'"):
        cls(backend="jax")
    real_import = builtins.__import__

    def no_numba(name, *args, **kwargs):
        if name == "numba" or name.startswith("numba."):
            raise ImportError("No module named 'numba'")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_numba)
    with pytest.raises(ImportError, match=r"backend='numba' needs Numba: pip install pamdp\[fast\]"):
        cls(backend="numba")
    assert cls(backend="auto").backend == "numpy"


@pytest.mark.parametrize(
    "module, cached, other",
    [
        (
            "hfo_kernel",
            ["hfo_kernel._dash-145.py311.nbi", "hfo_kernel._dash-145.py311.1.nbc"],
            "hfo_vector.cpython-311.pyc",
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


@pytest.mark.parametrize("backend", ["numpy", "numba"])
@pytest.mark.parametrize("env_id", ["pamdp/HalfFieldOffense-v0"])
def test_a_copied_batched_env_goes_on_as_the_original(env_id, backend):
    # A copy keeps the kernel (by module name) and the views of its state (HFO's rows of one matrix): it steps
    # on exactly as the original does.
    import copy
    import pickle

    import numpy as np

    env = gymnasium.make_vec(env_id, num_envs=3, vectorization_mode="vector_entry_point", backend=backend)
    env.reset(seed=1)
    env.action_space.seed(0)
    for _ in range(5):
        env.step(env.action_space.sample())
    copies = [copy.deepcopy(env), pickle.loads(pickle.dumps(env))]
    for _ in range(60):
        action = env.action_space.sample()
        obs, reward, *_ = env.step(action)
        for other in copies:
            obs2, reward2, *_ = other.step(action)
            np.testing.assert_array_equal(obs2, obs)
            np.testing.assert_array_equal(reward2, reward)
