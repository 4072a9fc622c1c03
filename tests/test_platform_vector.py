"""The batched Platform env: equal to the scalar env step for step without noise, same statistics with."""

import gymnasium
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode, SyncVectorEnv

import pamdp  # noqa: F401  (registers pamdp/Platform-v0)
from pamdp.envs.platform import PlatformEnv, PlatformVectorEnv, ZeroNoise
from pamdp.spaces import HybridActionSpace

try:
    import numba  # noqa: F401

    HAVE_NUMBA = True
except ImportError:
    HAVE_NUMBA = False

SCRIPT = [(1, 480), (0, 30), (0, 0), (1, 720), (1, 480), (0, 5), (0, 5), (1, 720), (0, 5), (0, 30)]


def batch(a, p):
    """Batched actions ``a[i]`` with parameters ``p[i]`` (other parameters: arbitrary in-range values)."""
    a = np.asarray(a, dtype=np.int64)
    p = np.asarray(p, dtype=np.float32)
    params = [np.full((a.size, 1), v, dtype=np.float32) for v in (15.0, 360.0, 215.0)]
    for k in range(3):
        params[k][a == k, 0] = p[a == k]
    return a, tuple(params)


def test_make_vec_returns_the_batched_env():
    venv = gymnasium.make_vec("pamdp/Platform-v0", num_envs=4, vectorization_mode="vector_entry_point")
    assert isinstance(venv, PlatformVectorEnv)
    assert venv.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
    assert venv.max_episode_steps == 200
    assert venv.action_space == gymnasium.vector.utils.batch_space(PlatformEnv().action_space, 4)
    obs, info = venv.reset(seed=0)
    assert obs.shape == (4, 9) and obs in venv.observation_space
    np.testing.assert_array_equal(obs, np.tile(PlatformEnv().reset()[0], (4, 1)))
    np.testing.assert_array_equal(info["substeps"], 0)


BACKENDS = ["numpy", pytest.param("numba", marks=pytest.mark.skipif(not HAVE_NUMBA, reason="needs numba"))]


@pytest.mark.parametrize("backend", BACKENDS)
def test_equals_scalar_envs_without_noise(backend):
    """Random actions in odd copies; the scripted policy then standing still (to reach the time limit) in
    even ones. Compared with Gymnasium's SyncVectorEnv over scalar envs, so autoreset is compared too."""
    n = 12
    venv = gymnasium.make_vec("pamdp/Platform-v0", num_envs=n, vectorization_mode="vector_entry_point", backend=backend)
    assert venv.backend == backend
    ref = SyncVectorEnv([lambda: gymnasium.make("pamdp/Platform-v0") for _ in range(n)])
    venv.reset(seed=0)
    ref.reset(seed=0)
    venv.np_random = ZeroNoise()
    for env in ref.envs:
        env.unwrapped.np_random = ZeroNoise()
    venv.action_space.seed(1)
    scripted = SCRIPT[:8] + [(0, 0.0)] * 300
    odd = np.arange(n) % 2 == 1
    saw = {"terminated": False, "truncated": False}
    for t in range(205):
        a, params = venv.action_space.sample()
        sa, sp = batch(*np.array(scripted[t]).reshape(2, 1).repeat(n, axis=1))
        action = (np.where(odd, a, sa), tuple(np.where(odd[:, None], p, q) for p, q in zip(params, sp)))
        got, want = venv.step(action), ref.step(action)
        for k in range(4):
            np.testing.assert_array_equal(got[k], want[k], err_msg=f"step {t}, output {k}")
        np.testing.assert_array_equal(got[4]["substeps"], want[4]["substeps"], err_msg=f"step {t}")
        state = venv.state
        for i, env in enumerate(ref.envs):
            np.testing.assert_array_equal(state["player"][i], env.unwrapped.state["player"])
            np.testing.assert_array_equal(state["enemies"][i], env.unwrapped.state["enemies"])
        saw["terminated"] |= got[2].any()
        saw["truncated"] |= got[3].any()
    assert saw == {"terminated": True, "truncated": True}


def test_next_step_autoreset():
    venv = PlatformVectorEnv(num_envs=2)
    reset_obs, _ = venv.reset(seed=0)
    venv.np_random = ZeroNoise()
    obs, reward, terminated, truncated, info = venv.step(batch([2, 0], [430, 30]))  # copy 0 meets enemy 1
    assert terminated.tolist() == [True, False] and reward[0] > 0
    obs, reward, terminated, truncated, info = venv.step(batch([0, 0], [30, 30]))
    np.testing.assert_array_equal(obs[0], reset_obs[0])
    assert reward[0] == 0.0 and not terminated[0] and not truncated[0] and info["substeps"].tolist() == [0, 20]


@pytest.mark.parametrize("backend", BACKENDS)
def test_random_policy_statistics_with_noise(backend):
    # Spec §8: mean return ~0.154 (std ~0.10), ~2.2 steps per episode, ~72 sub-steps per step. Only each
    # copy's first episode counts, so that short episodes are not over-represented.
    n = 3000
    venv = PlatformVectorEnv(num_envs=n, backend=backend)
    venv.reset(seed=0)
    venv.action_space.seed(0)
    returns, first_done = np.zeros(n), np.zeros(n, dtype=bool)
    lengths, substeps = np.zeros(n), []
    while not first_done.all():
        _, r, terminated, truncated, info = venv.step(venv.action_space.sample())
        live = ~first_done
        returns[live] += r[live]
        lengths[live] += 1
        substeps.extend(info["substeps"][live])
        first_done |= terminated | truncated
    assert returns.mean() == pytest.approx(0.154, abs=0.008)
    assert lengths.mean() == pytest.approx(2.2, abs=0.1)
    assert np.mean(substeps) == pytest.approx(72, abs=3)


def test_seeding_is_reproducible():
    def run(seed):
        venv = PlatformVectorEnv(num_envs=8)
        venv.reset(seed=seed)
        venv.action_space.seed(0)
        return [venv.step(venv.action_space.sample())[0] for _ in range(5)]

    np.testing.assert_array_equal(run(3), run(3))
    assert not np.array_equal(run(3), run(4))


def test_accepts_hybrid_action_space_batches():
    venv = PlatformVectorEnv(num_envs=3)
    venv.reset(seed=0)
    h = HybridActionSpace.from_gym(venv.single_action_space)
    _, _, _, _, info = venv.step(h.to_env_batch([0, 1, 2], np.zeros((3, 1))))
    assert info["substeps"][0] == 20 and (info["substeps"][1:] > 20).all()


def test_reset_mask():
    venv = PlatformVectorEnv(num_envs=2)
    reset_obs, _ = venv.reset(seed=0)
    moved, *_ = venv.step(batch([0, 0], [30, 30]))
    obs, _ = venv.reset(options={"reset_mask": np.array([False, True])})
    np.testing.assert_array_equal(obs, [moved[0], reset_obs[1]])


@pytest.mark.parametrize(
    "action, shown",
    [
        ((np.array([0, 3]), (np.zeros((2, 1)),) * 3), "[3]"),
        ((np.array([0, 1, 2]), (np.zeros((2, 1)),) * 3), "array([0, 1, 2])"),
        ((np.array([0.0, 1.0]), (np.zeros((2, 1)),) * 3), "array([0., 1.])"),
        ((np.array([0, 1]), (np.zeros((2, 1)),) * 2), "array"),
        ((np.array([0, 1]), (np.zeros((2, 2)), np.zeros((2, 1)), np.zeros((2, 1)))), "(2, 2)"),
        ((np.array([0, 1]), (np.array([[np.nan], [0.0]]), np.zeros((2, 1)), np.zeros((2, 1)))), "nan"),
        (np.array([0, 1]), "array([0, 1])"),
    ],
)
def test_bad_actions_raise(action, shown):
    venv = PlatformVectorEnv(num_envs=2)
    venv.reset(seed=0)
    with pytest.raises(ValueError) as err:
        venv.step(action)
    assert shown in str(err.value) and "expected (a, (p_run, p_hop, p_leap))" in str(err.value)


@pytest.mark.parametrize("kwargs", [dict(num_envs=0), dict(num_envs=2.5), dict(max_episode_steps=0)])
def test_bad_constructor_arguments_raise(kwargs):
    with pytest.raises(ValueError, match="must be a positive integer"):
        PlatformVectorEnv(**kwargs)


def test_render_returns_one_frame_per_copy():
    venv = PlatformVectorEnv(num_envs=2, render_mode="rgb_array")
    venv.reset(seed=0)
    frames = venv.render()
    assert len(frames) == 2 and frames[0].shape == (120, 633, 3)
