"""The batched Platform env: copy i is the scalar env seeded with copy i's seed, step for step, noise on."""

import gymnasium
import numpy as np
import pytest
from domain_replay import assert_refused, assert_same_step
from gymnasium.vector import AutoresetMode, SyncVectorEnv

import pamdp  # noqa: F401  (registers pamdp/Platform-v0)
from pamdp.envs.platform import PlatformEnv, PlatformVectorEnv, ZeroNoise
from pamdp.spaces import HybridActionSpace

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


def assert_equals_scalar_envs(n, seed, steps, noise=True, max_episode_steps=200):
    """Step the batched env and Gymnasium's SyncVectorEnv over ``n`` scalar envs (which seeds env i with
    ``seed + i`` and auto-resets in next-step mode too) with the same actions: random ones in odd copies,
    the scripted policy then standing still (to reach the time limit) in even ones. Every output and the
    state must be equal after every step. Returns the numbers of terminations and truncations."""
    venv = gymnasium.make_vec(
        "pamdp/Platform-v0", num_envs=n, vectorization_mode="vector_entry_point", max_episode_steps=max_episode_steps
    )
    ref = SyncVectorEnv(
        [lambda: gymnasium.make("pamdp/Platform-v0", max_episode_steps=max_episode_steps) for _ in range(n)]
    )
    venv.reset(seed=seed)
    ref.reset(seed=seed)
    if not noise:
        venv.np_randoms = [ZeroNoise()] * n
        for env in ref.envs:
            env.unwrapped.np_random = ZeroNoise()
    venv.action_space.seed(1)
    scripted = SCRIPT[:8] + [(0, 0.0)] * 300
    odd = np.arange(n) % 2 == 1
    ended = np.zeros(2, dtype=np.int64)
    for t in range(steps):
        a, params = venv.action_space.sample()
        sa, sp = batch(*np.array(scripted[t % len(scripted)]).reshape(2, 1).repeat(n, axis=1))
        action = (np.where(odd, a, sa), tuple(np.where(odd[:, None], p, q) for p, q in zip(params, sp)))
        got, want = venv.step(action), ref.step(action)
        assert_same_step(got, want, f"N={n}, step {t}", keys=("substeps",))
        state = venv.state
        for i, env in enumerate(ref.envs):
            np.testing.assert_array_equal(state["player"][i], env.unwrapped.state["player"])
            np.testing.assert_array_equal(state["enemies"][i], env.unwrapped.state["enemies"])
        ended += got[2].sum(), got[3].sum()
    return ended


@pytest.mark.parametrize("n, seed", [(1, 0), (2, 11), (7, 3), (40, 100)])
def test_copy_i_equals_a_scalar_env_seeded_with_seed_plus_i_with_noise(n, seed):
    terminated, truncated = assert_equals_scalar_envs(n, seed, steps=220, max_episode_steps=50)
    assert terminated > 0 and truncated > 0  # episodes end both ways, so autoresets are compared too


def test_equals_scalar_envs_without_noise():
    terminated, truncated = assert_equals_scalar_envs(12, 0, steps=205, noise=False)
    assert terminated > 0 and truncated > 0


def test_a_copy_does_not_depend_on_the_others():
    # Copy 2 of a batch of 3 seeded 10 is copy 0 of a batch of 5 seeded [12, ...], whatever the others do.
    small, large = PlatformVectorEnv(num_envs=3), PlatformVectorEnv(num_envs=5)
    small.reset(seed=10)
    large.reset(seed=[12, 0, 1, 2, None])
    rng = np.random.default_rng(0)
    for t in range(60):
        a = rng.integers(0, 3, 5)
        p = rng.uniform(0, 1, 5) * np.array([30.0, 720.0, 430.0])[a]
        got_small = small.step(batch(a[[3, 4, 0]], p[[3, 4, 0]]))
        got_large = large.step(batch(a, p))
        for k in range(1, 4):
            assert got_small[k][2] == got_large[k][0], f"step {t}, output {k}"
        np.testing.assert_array_equal(got_small[0][2], got_large[0][0])
        assert got_small[4]["substeps"][2] == got_large[4]["substeps"][0]


def test_next_step_autoreset():
    venv = PlatformVectorEnv(num_envs=2)
    reset_obs, _ = venv.reset(seed=0)
    venv.np_randoms = [ZeroNoise()] * 2
    obs, reward, terminated, truncated, info = venv.step(batch([2, 0], [430, 30]))  # copy 0 meets enemy 1
    assert terminated.tolist() == [True, False] and reward[0] > 0
    obs, reward, terminated, truncated, info = venv.step(batch([0, 0], [30, 30]))
    np.testing.assert_array_equal(obs[0], reset_obs[0])
    assert reward[0] == 0.0 and not terminated[0] and not truncated[0] and info["substeps"].tolist() == [0, 20]


def test_random_policy_statistics_with_noise():
    # Spec §8: mean return ~0.154 (std ~0.10), ~2.2 steps per episode, ~72 sub-steps per step. Only each
    # copy's first episode counts, so that short episodes are not over-represented.
    n = 3000
    venv = PlatformVectorEnv(num_envs=n)
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


def test_accepts_hybrid_action_space_batches():
    venv = PlatformVectorEnv(num_envs=3)
    venv.reset(seed=0)
    h = HybridActionSpace.from_gym(venv.single_action_space)
    _, _, _, _, info = venv.step(h.to_env_batch([0, 1, 2], np.zeros((3, 1))))
    assert info["substeps"][0] == 20 and (info["substeps"][1:] > 20).all()


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
    assert_refused(venv, action, shown, "expected (a, (p_run, p_hop, p_leap))")


def test_render_returns_one_frame_per_copy():
    venv = PlatformVectorEnv(num_envs=2, render_mode="rgb_array")
    venv.reset(seed=0)
    frames = venv.render()
    assert len(frames) == 2 and frames[0].shape == (120, 633, 3)
