"""The batched HFO env: registration, per-copy random streams (copy i is the scalar env with copy i's seed,
noise on), next-step autoreset, reset options and masks, errors, rendering. Copies of the env:
``tests/test_vector.py``."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode

import pamdp  # noqa: F401  (registers the envs)
import pamdp.envs.hfo.dynamics as dyn
from pamdp.envs.hfo import HalfFieldOffenseEnv, HalfFieldOffenseVectorEnv, scripted_scorer_batch


def mixed_actions(obs, rng):
    """The scripted scorer's actions (kicks, goals, hence autoresets) with a third of the copies replaced by
    random actions whose parameters overshoot the action space (backward dashes, clipped turns and kicks)."""
    a, params = scripted_scorer_batch(obs)
    a = np.array(a)
    dash, turn, kick = (np.array(p, dtype=np.float64) for p in params)
    i = np.flatnonzero(rng.random(a.shape[0]) < 1 / 3)
    a[i] = rng.integers(0, 3, i.size)
    dash[i] = rng.uniform(-150.0, 150.0, (i.size, 2))
    turn[i] = rng.uniform(-200.0, 200.0, (i.size, 1))
    kick[i] = rng.uniform(-20.0, 150.0, (i.size, 2))
    return a, (dash, turn, kick)


def test_make_vec_returns_the_batched_env():
    env = gymnasium.make_vec("pamdp/HalfFieldOffense-v0", num_envs=3, vectorization_mode="vector_entry_point")
    assert isinstance(env, HalfFieldOffenseVectorEnv)
    assert env.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
    assert env.action_space == gymnasium.vector.utils.batch_space(HalfFieldOffenseEnv().action_space, 3)
    obs, info = env.reset(seed=0)
    assert obs.shape == (3, 59) and list(info["status"]) == ["IN_GAME"] * 3


@pytest.mark.parametrize(
    "kwargs, seed, options",
    [
        ({}, 7, None),
        ({"body_reset": "uniform"}, [40, 3, 17, 3, 8, 100], None),
        ({"profile": "hfo2016", "deterministic": True}, 5, {"body": np.linspace(-170.0, 170.0, 6)}),
        (
            {"profile": "hfo2019", "timeout_terminal": True, "first_step_reward": True, "terminal_deltas": True},
            2,
            {"ball": (30.0, 5.0), "player": np.tile((29.8, 5.0), (6, 1)), "body": 45.0},
        ),
    ],
)
def test_copy_i_equals_the_scalar_env_with_its_seed(kwargs, seed, options):
    """Per-copy random streams: each copy of a batch of 6 follows a scalar env reset with that copy's seed
    (``seed + i``, or the list's entry) and options, step for step, with the actuator noise on, across
    autoresets: observations, rewards, flags, statuses and outcomes are equal, not close."""
    n, steps = 6, 400
    batched = HalfFieldOffenseVectorEnv(num_envs=n, **kwargs)
    scalars = [HalfFieldOffenseEnv(**kwargs) for _ in range(n)]
    seeds = seed if isinstance(seed, list) else [seed + i for i in range(n)]

    def copy_options(i):
        if options is None:
            return None
        return {k: (v[i] if np.ndim(v) == (1 if k == "body" else 2) else v) for k, v in options.items()}

    batch_obs, _ = batched.reset(seed=seed, options=options)
    obs = [scalars[i].reset(seed=seeds[i], options=copy_options(i))[0] for i in range(n)]
    rng = np.random.default_rng(0)
    ended, endings, goals = np.zeros(n, dtype=bool), 0, 0
    for t in range(steps):
        for i in range(n):
            np.testing.assert_array_equal(batch_obs[i], obs[i], err_msg=f"step {t}, copy {i}")
        actions = mixed_actions(batch_obs, rng)
        batch_obs, reward, terminated, truncated, info = batched.step(actions)
        for i in range(n):
            if ended[i]:  # the next-step autoreset: the scalar env is reset by hand
                obs[i], _ = scalars[i].reset()
                assert (reward[i], terminated[i], truncated[i], info["step"][i]) == (0.0, False, False, 0)
                assert not info["_is_success"][i]
                continue
            obs[i], r, te, tr, inf = scalars[i].step((int(actions[0][i]), tuple(p[i] for p in actions[1])))
            assert (reward[i], terminated[i], truncated[i]) == (r, te, tr), f"step {t}, copy {i}"
            assert (info["status"][i], info["step"][i]) == (inf["status"], inf["step"])
            assert info["_is_success"][i] == ("is_success" in inf)
            if te or tr:
                assert info["is_success"][i] == inf["is_success"] == (inf["status"] == "GOAL")
                endings += 1
                goals += inf["is_success"]
        ended = terminated | truncated
    np.testing.assert_array_equal(batch_obs, np.stack(obs))
    assert endings >= 2 * n and goals >= n  # several episodes per copy, goals among them


def test_a_copy_does_not_depend_on_the_number_of_copies():
    small, large = HalfFieldOffenseVectorEnv(num_envs=2), HalfFieldOffenseVectorEnv(num_envs=9)
    obs_small, _ = small.reset(seed=3)
    obs_large, _ = large.reset(seed=3)
    rng = np.random.default_rng(1)
    for _ in range(150):
        a, params = mixed_actions(obs_large, rng)
        obs_large, reward_large, *_ = large.step((a, params))
        obs_small, reward_small, *_ = small.step((a[:2], tuple(p[:2] for p in params)))
        np.testing.assert_array_equal(obs_small, obs_large[:2])
        np.testing.assert_array_equal(reward_small, reward_large[:2])


def test_reset_mask_resets_only_the_masked_copies():
    env = HalfFieldOffenseVectorEnv(num_envs=3)
    env.reset(seed=0)
    turn = (np.ones(3, int), (np.zeros((3, 2)), np.full((3, 1), 30.0), np.zeros((3, 2))))
    for _ in range(5):
        env.step(turn)
    before = env.states.copy()
    obs, info = env.reset(options={"reset_mask": np.array([False, True, False]), "ball": (20.0, 1.0)})
    np.testing.assert_array_equal(env.states[[0, 2]], before[[0, 2]])
    assert (env.states[1, dyn.BX], env.states[1, dyn.BY], env.states[1, dyn.STEPS]) == (20.0, 1.0, 0.0)
    assert env.states[1, dyn.BODY] == before[1, dyn.BODY]  # no seed: the body angle carries over
    assert obs.shape == (3, 59) and list(info["step"]) == [5, 0, 5]


def test_reset_options_per_copy_and_broadcast():
    env = HalfFieldOffenseVectorEnv(num_envs=2)
    env.reset(seed=0, options={"ball": [(1.0, 2.0), (3.0, 4.0)], "body": 90.0})
    assert env.states[:, dyn.BX].tolist() == [1.0, 3.0] and env.states[:, dyn.BODY].tolist() == [90.0, 90.0]
    with pytest.raises(ValueError, match=r"ball=\(99.0, 4.0\) is outside"):
        env.reset(options={"ball": [(1.0, 2.0), (99.0, 4.0)]})
    with pytest.raises(ValueError, match="body"):
        env.reset(options={"body": "x"})
    with pytest.raises(ValueError, match="seed=2.5"):
        env.reset(seed=2.5)


@pytest.mark.parametrize(
    "make, words",
    [
        (lambda n: (np.zeros(n + 1, int), (np.zeros((n, 2)), np.zeros((n, 1)), np.zeros((n, 2)))), ["shapes"]),
        (lambda n: (np.zeros(n, int), (np.zeros((n, 2)), np.zeros((n, 1)))), ["shapes"]),
        (lambda n: (np.full(n, 4), (np.zeros((n, 2)), np.zeros((n, 1)), np.zeros((n, 2)))), ["[4, 4]", "KICK"]),
        (lambda n: (np.ones(n, int), (np.zeros((n, 2)), np.full((n, 1), np.nan), np.zeros((n, 2)))), ["finite"]),
        (lambda n: 7, ["malformed"]),
    ],
)
def test_bad_batched_actions_raise_clear_errors(make, words):
    env = HalfFieldOffenseVectorEnv(num_envs=2)
    env.reset(seed=0)
    with pytest.raises(ValueError) as error:
        env.step(make(2))
    assert all(w in str(error.value) for w in words), str(error.value)


def test_noise_and_render():
    env = HalfFieldOffenseVectorEnv(num_envs=2, render_mode="rgb_array")
    env.reset(seed=0, options={"player": (10.0, 0.0), "ball": (30.0, 0.0), "body": 0.0})
    env.step((np.zeros(2, int), (np.tile([100.0, 0.0], (2, 1)), np.zeros((2, 1)), np.zeros((2, 2)))))
    assert env.states[0, dyn.PX] != env.states[1, dyn.PX]  # independent actuator noise
    frames = env.render()
    assert len(frames) == 2 and frames[0].dtype == np.uint8


def _xoshiro256pp_reference(state, count):
    """xoshiro256++ (https://prng.di.unimi.it/xoshiro256plusplus.c) in Python integers."""
    mask = (1 << 64) - 1
    s = list(state)

    def rotl(x, k):
        return ((x << k) | (x >> (64 - k))) & mask

    out = []
    for _ in range(count):
        out.append((rotl((s[0] + s[3]) & mask, 23) + s[0]) & mask)
        t = (s[1] << 17) & mask
        s[2] ^= s[0]
        s[3] ^= s[1]
        s[1] ^= s[2]
        s[0] ^= s[3]
        s[2] ^= t
        s[3] = rotl(s[3], 45)
    return out


def test_each_copys_stream_is_xoshiro256pp():
    state = [1, 2, 3, 4]
    expected = _xoshiro256pp_reference(state, 1000)
    assert expected[0] == (5 << 23) + 1  # rotl(1 + 4, 23) + 1, by hand
    assert expected[1:4] == [58720359, 3588806011781223, 3591011842654386]  # the rand_xoshiro crate's test vector
    r = np.array(state, dtype=np.uint64)
    draws = [dyn.next_double(r) for _ in range(1000)]
    assert draws == [(x >> 11) / 2.0**53 for x in expected]
    # seeded from a generator: uniform in [0, 1) (Monte-Carlo mean and variance, 5 standard errors)
    dyn.seed_stream(r, np.random.default_rng(0).random(4))
    u = np.array([dyn.next_double(r) for _ in range(100_000)])
    assert u.min() >= 0.0 and u.max() < 1.0
    assert abs(u.mean() - 0.5) < 5 * (1 / 12) ** 0.5 / 100_000**0.5
    assert abs(u.var() - 1 / 12) < 5 * (1 / 180) ** 0.5 / 100_000**0.5


def test_assigned_generators_seed_the_copies_streams():
    seeded, assigned = HalfFieldOffenseVectorEnv(num_envs=3), HalfFieldOffenseVectorEnv(num_envs=3)
    obs, _ = seeded.reset(seed=4)
    assigned.np_randoms = [np.random.default_rng(np.random.SeedSequence(4 + i)) for i in range(3)]
    obs2, _ = assigned.reset()
    np.testing.assert_array_equal(obs2, obs)
    turn = (np.ones(3, int), (np.zeros((3, 2)), np.full((3, 1), 20.0), np.zeros((3, 2))))
    for _ in range(20):
        np.testing.assert_array_equal(assigned.step(turn)[0], seeded.step(turn)[0])
