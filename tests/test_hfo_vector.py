"""The batched HFO env: registration, next-step autoreset, equality with the scalar env, errors."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode

import pamdp  # noqa: F401  (registers the envs)
from pamdp.envs.hfo import HalfFieldOffenseEnv, HalfFieldOffenseVectorEnv
from pamdp.envs.hfo_baseline import scripted_scorer_batch


def mixed_actions(obs, rng, space):
    """The scorer's actions, with a third of the games acting at random (kicks, turns, odd dashes)."""
    a, (dash, turn, kick) = scripted_scorer_batch(obs)
    random = space.sample()
    pick = rng.random(len(a)) < 0.33
    a = np.where(pick, random[0], a)
    return a, tuple(np.where(pick[:, None], r, s) for r, s in zip(random[1], (dash, turn, kick)))


def test_make_vec_returns_the_batched_env():
    env = gymnasium.make_vec("pamdp/HalfFieldOffense-v0", num_envs=3, vectorization_mode="vector_entry_point")
    assert isinstance(env, HalfFieldOffenseVectorEnv)
    assert env.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
    assert env.action_space == gymnasium.vector.utils.batch_space(HalfFieldOffenseEnv().action_space, 3)
    obs, info = env.reset(seed=0)
    assert obs.shape == (3, 59) and list(info["status"]) == ["IN_GAME"] * 3


@pytest.mark.parametrize("body_reset", ["carry", "uniform"])
def test_one_game_equals_the_scalar_env_across_episodes(body_reset):
    kwargs = dict(deterministic=True, body_reset=body_reset)
    scalar, batched = HalfFieldOffenseEnv(**kwargs), HalfFieldOffenseVectorEnv(num_envs=1, **kwargs)
    obs, _ = scalar.reset(seed=7)
    batch_obs, _ = batched.reset(seed=7)
    rng, space = np.random.default_rng(0), batched.action_space
    space.seed(0)
    episodes = 0
    for _ in range(700):
        np.testing.assert_array_equal(batch_obs[0], obs)
        actions = mixed_actions(batch_obs, rng, space)
        obs, reward, terminated, truncated, info = scalar.step((int(actions[0][0]), tuple(p[0] for p in actions[1])))
        batch_obs, b_reward, b_terminated, b_truncated, b_info = batched.step(actions)
        np.testing.assert_array_equal(batch_obs[0], obs)
        assert (b_reward[0], b_terminated[0], b_truncated[0]) == (reward, terminated, truncated)
        assert (b_info["status"][0], b_info["step"][0]) == (info["status"], info["step"])
        if terminated or truncated:
            episodes += 1
            obs, _ = scalar.reset()
            batch_obs, b_reward, b_terminated, b_truncated, b_info = batched.step(actions)  # autoreset step
            assert (b_reward[0], b_terminated[0], b_truncated[0], b_info["step"][0]) == (0.0, False, False, 0)
    assert episodes >= 5


def test_many_games_equal_scalar_envs_placed_alike():
    """As above for 16 games; NumPy's SIMD sin/cos on long arrays may differ from libm in the last bit."""
    n = 16
    batched = HalfFieldOffenseVectorEnv(num_envs=n, deterministic=True)
    scalars = [HalfFieldOffenseEnv(deterministic=True) for _ in range(n)]
    batch_obs, _ = batched.reset(seed=1)

    def place(i):
        options = {"ball": (batched.bx[i], batched.by[i]), "player": (batched.px[i], batched.py[i])}
        scalars[i].game.body = batched.body[i]
        return scalars[i].reset(options=options)[0]

    obs = [place(i) for i in range(n)]
    rng, space = np.random.default_rng(1), batched.action_space
    space.seed(1)
    ended, boundaries = np.zeros(n, dtype=bool), 0
    for _ in range(400):
        actions = mixed_actions(batch_obs, rng, space)
        batch_obs, reward, terminated, truncated, info = batched.step(actions)
        for i in range(n):
            if ended[i]:  # this step reset game i: copy the new placement into its scalar twin
                obs[i] = place(i)
                boundaries += 1
            else:
                obs[i], r, te, tr, inf = scalars[i].step((int(actions[0][i]), tuple(p[i] for p in actions[1])))
                assert (terminated[i], truncated[i], info["status"][i]) == (te, tr, inf["status"])
                assert reward[i] == pytest.approx(r, rel=1e-9, abs=1e-12)
            np.testing.assert_allclose(batch_obs[i], obs[i], atol=1e-6)
        ended = terminated | truncated
    assert boundaries >= 10


def test_reset_options_per_game_and_broadcast():
    env = HalfFieldOffenseVectorEnv(num_envs=2)
    env.reset(seed=0, options={"ball": [(1.0, 2.0), (3.0, 4.0)], "body": 90.0})
    assert env.bx.tolist() == [1.0, 3.0] and env.body.tolist() == [90.0, 90.0]
    with pytest.raises(ValueError, match="outside"):
        env.reset(options={"ball": [(1.0, 2.0), (99.0, 4.0)]})
    with pytest.raises(ValueError, match="body"):
        env.reset(options={"body": "x"})


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
    assert env.px[0] != env.px[1]  # independent actuator noise
    frames = env.render()
    assert len(frames) == 2 and frames[0].dtype == np.uint8
