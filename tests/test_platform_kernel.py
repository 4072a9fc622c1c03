"""The batched Platform env's Numba backend (``platform_kernel.py``) against its NumPy backend, the reference."""

import numpy as np
import pytest

import pamdp  # noqa: F401  (registers pamdp/Platform-v0)
from pamdp.envs.platform import PARAM_MAX, ZeroNoise
from pamdp.envs.platform_vector import PlatformVectorEnv


def _actions(n, rng):
    """Random actions whose parameters are, in equal shares, inside the box, exactly 0, exactly the bound,
    below 0 or beyond the bound (the last two clipped to the edges)."""
    a = rng.integers(0, 3, n)
    params = []
    for high in PARAM_MAX:
        choices = np.stack(
            [
                rng.uniform(0.0, high, n),
                np.zeros(n),
                np.full(n, high),
                -rng.uniform(0.0, 10.0, n),
                1.5 * np.full(n, high),
            ]
        )
        params.append(choices[rng.integers(0, 5, n), np.arange(n)].astype(np.float32)[:, None])
    return a, tuple(params)


def _bits(x):
    """The bit pattern of an array: equal bits, not merely equal values (0.0 and -0.0 differ)."""
    x = np.ascontiguousarray(x)
    return x.view(np.uint8)


def _assert_backends_agree(noise, n, steps, max_episode_steps=200):
    """Step both backends with the same actions; compare everything they return, their state and the noise
    generator's state after every step. Returns the counts of terminations and truncations."""
    envs = [PlatformVectorEnv(n, max_episode_steps, backend=b) for b in ("numpy", "numba")]
    for env in envs:
        env.reset(seed=5)
        if noise is not None:
            env.np_random = noise()
    rng = np.random.default_rng(0)
    ended = np.zeros(2, dtype=np.int64)
    for t in range(steps):
        actions = _actions(n, rng)
        (obs, reward, terminated, truncated, info), got = (env.step(actions) for env in envs)
        for k, want in enumerate((obs, reward, terminated, truncated)):
            assert _bits(got[k]).tobytes() == _bits(want).tobytes(), f"step {t}, output {k}"
        np.testing.assert_array_equal(got[4]["substeps"], info["substeps"], err_msg=f"step {t}")
        np.testing.assert_array_equal(got[4]["_substeps"], info["_substeps"], err_msg=f"step {t}")
        assert _bits(envs[1]._state).tobytes() == _bits(envs[0]._state).tobytes(), f"step {t}"
        ended += terminated.sum(), truncated.sum()
    return envs, ended


def test_numba_backend_equals_numpy_with_noise():
    pytest.importorskip("numba")
    n = 256
    envs, (terminated, truncated) = _assert_backends_agree(None, n, 160, max_episode_steps=6)
    # the same draws from the same generator: the streams end in the same state
    assert envs[1].np_random.bit_generator.state == envs[0].np_random.bit_generator.state
    assert terminated > 3 * n and truncated > 0  # many episodes per copy, hence autoresets


def test_numba_backend_equals_numpy_without_noise():
    pytest.importorskip("numba")
    _, (terminated, truncated) = _assert_backends_agree(ZeroNoise, 256, 100, max_episode_steps=6)
    assert terminated > 0 and truncated > 0


def test_numba_backend_reads_a_random_state_stream():
    pytest.importorskip("numba")
    envs, _ = _assert_backends_agree(lambda: np.random.RandomState(3), 64, 20)
    assert str(envs[1].np_random.get_state()) == str(envs[0].np_random.get_state())


def test_numba_backend_runs_the_numpy_loop_for_other_noise_sources():
    pytest.importorskip("numba")

    class Halved:
        """A noise source the kernel cannot read: half of a generator's Gaussians."""

        def __init__(self):
            self.rng = np.random.default_rng(4)

        def normal(self, loc=0.0, scale=1.0, size=None):
            return 0.5 * self.rng.normal(loc, scale, size)

    envs, _ = _assert_backends_agree(Halved, 16, 10)
    assert envs[1].np_random.rng.bit_generator.state == envs[0].np_random.rng.bit_generator.state
