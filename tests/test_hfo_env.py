"""The HFO env's interface: spaces, features, reward, outcomes, seeding, reset options, errors, rendering,
baseline."""

from __future__ import annotations

import math

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import pamdp  # noqa: F401  (registers the envs)
import pamdp.envs.hfo.dynamics as dyn
from pamdp.envs.hfo import HalfFieldOffenseEnv, scripted_scorer
from pamdp.envs.rendering import record_episode

TURN0 = (1, (np.zeros(2, np.float32), np.zeros(1, np.float32), np.zeros(2, np.float32)))


def dash(power=100.0, direction=0.0):
    return 0, (np.array([power, direction], np.float32), np.zeros(1, np.float32), np.zeros(2, np.float32))


# HFO's parameters keep the server's units (power 0-100, direction -180-180), which the checker only advises against
@pytest.mark.filterwarnings("ignore:.*symmetric and normalized space")
def test_registered_and_passes_gymnasium_checker():
    env = gymnasium.make("pamdp/HalfFieldOffense-v0")
    assert isinstance(env.unwrapped, HalfFieldOffenseEnv)
    check_env(env.unwrapped, skip_render_check=True)
    space = env.action_space
    assert [s.shape for s in space.spaces[1].spaces] == [(2,), (1,), (2,)]
    assert space.spaces[0].n == 3


@pytest.mark.parametrize("profile, size", [("hfo2016", 58), ("hfo2017", 59), ("hfo2019", 59)])
def test_feature_vector_length_and_range(profile, size):
    env = HalfFieldOffenseEnv(profile=profile)
    env.action_space.seed(0)
    obs, _ = env.reset(seed=0)
    assert obs.shape == (size,) and obs.dtype == np.float32
    for _ in range(300):
        obs, _, terminated, truncated, _ = env.step(env.action_space.sample())
        assert obs.shape == (size,) and np.all(np.abs(obs) <= 1.0)
        if terminated or truncated:
            obs, _ = env.reset()


def test_reward_feature_indices_mean_what_the_reward_assumes():
    env = HalfFieldOffenseEnv(deterministic=True, profile="hfo2017")
    player, ball = (20.0, 10.0), (30.0, 4.0)
    obs, _ = env.reset(options={"player": player, "ball": ball, "body": 90.0})
    dmax = math.hypot(52.5, 34.0)
    d_ball, d_goal = math.dist(player, ball), math.dist(player, (52.5, 0.0))
    assert obs[dyn.BALL_PROXIMITY] == pytest.approx(1 - 2 * d_ball / dmax, abs=1e-6)
    assert obs[dyn.GOAL_PROXIMITY] == pytest.approx(1 - 2 * d_goal / dmax, abs=1e-6)
    ball_bearing = math.degrees(math.atan2(ball[1] - player[1], ball[0] - player[0])) - 90.0
    assert math.degrees(math.atan2(obs[dyn.BALL_SIN], obs[dyn.BALL_COS])) == pytest.approx(ball_bearing, abs=1e-4)
    goal_bearing = math.degrees(math.atan2(-player[1], 52.5 - player[0])) - 90.0
    assert math.degrees(math.atan2(obs[dyn.GOAL_SIN], obs[dyn.GOAL_COS])) == pytest.approx(goal_bearing, abs=1e-4)
    assert obs[dyn.KICKABLE] == -1.0
    assert dyn.ball_to_goal(obs.astype(float)) == pytest.approx(2 * math.dist(ball, (52.5, 0)) / dmax)
    obs, _ = env.reset(options={"player": (29.5, 4.0), "ball": ball})
    assert obs[dyn.KICKABLE] == 1.0


def test_reward_scale_is_2_over_dmax_per_metre():
    for profile, dmax in (("hfo2017", math.hypot(52.5, 34.0)), ("hfo2019", math.hypot(52.5, 68.0))):
        env = HalfFieldOffenseEnv(deterministic=True, profile=profile, first_step_reward=True)
        env.reset(options={"player": (10.0, 0.0), "ball": (30.0, 0.0), "body": 0.0})
        _, reward, *_ = env.step(dash())
        assert reward == pytest.approx(0.6 * 2.0 / dmax, rel=1e-4)  # 0.6 m closer to the ball


def test_first_transition_pays_nothing_by_default():
    env = HalfFieldOffenseEnv(deterministic=True)
    env.reset(options={"player": (10.0, 0.0), "ball": (30.0, 0.0), "body": 0.0})
    _, reward, *_ = env.step(dash())
    assert reward == 0.0
    _, reward, *_ = env.step(dash())
    assert reward == pytest.approx(0.84 * 2 / math.hypot(52.5, 34.0), rel=1e-4)


def test_kick_bonus_once_and_goal_bonus_alone_on_the_terminal_step():
    env = HalfFieldOffenseEnv(deterministic=True)
    obs, _ = env.reset(options={"player": (44.0, 0.0), "ball": (46.0, 0.0), "body": 0.0})
    rewards, statuses = [], []
    for _ in range(40):
        obs, reward, terminated, truncated, info = env.step(scripted_scorer(obs))
        rewards.append(reward)
        statuses.append(info["status"])
        if terminated or truncated:
            break
    assert statuses[-1] == "GOAL" and terminated
    assert rewards[-1] == 5.0
    assert sum(r > 0.9 for r in rewards[:-1]) == 1  # the +1 for first reaching the ball


def test_terminal_observation_is_the_true_terminal_state():
    env = HalfFieldOffenseEnv(deterministic=True)
    obs, _ = env.reset(options={"player": (44.0, 0.0), "ball": (46.0, 0.0), "body": 0.0})
    while True:
        obs, _, terminated, truncated, info = env.step(scripted_scorer(obs))
        if terminated or truncated:
            break
    s = env.state
    assert s[dyn.BX] > 52.5  # the ball is in the goal in the state returned with GOAL
    distance = math.dist((s[dyn.PX], s[dyn.PY]), (s[dyn.BX], s[dyn.BY]))
    assert obs[dyn.BALL_PROXIMITY] == pytest.approx(1 - 2 * distance / math.hypot(52.5, 34), abs=1e-5)


def test_seeded_episodes_are_reproducible_with_noise():
    def run(seed):
        env = HalfFieldOffenseEnv()
        env.action_space.seed(seed)
        obs, _ = env.reset(seed=seed)
        trajectory = [obs]
        for _ in range(150):
            obs, reward, terminated, truncated, _ = env.step(env.action_space.sample())
            trajectory.append(np.append(obs, reward))
            if terminated or truncated:
                trajectory.append(env.reset()[0])
        return trajectory

    a, b, c = run(3), run(3), run(4)
    assert all(np.array_equal(x, y) for x, y in zip(a, b))
    assert not all(np.array_equal(x, y) for x, y in zip(a, c))


def test_noise_is_on_unless_deterministic():
    results = []
    for deterministic in (True, False):
        env = HalfFieldOffenseEnv(deterministic=deterministic)
        env.reset(seed=0, options={"player": (10.0, 0.0), "ball": (30.0, 0.0), "body": 0.0})
        env.step(dash())
        results.append(env.state[dyn.PX])
    assert results[0] == pytest.approx(10.6) and results[1] != pytest.approx(10.6, abs=1e-6)


def test_reset_distribution_and_body_carry_over():
    env = HalfFieldOffenseEnv()
    s = env.state
    env.reset(seed=0)
    assert s[dyn.BODY] == 0.0  # the first episode faces the goal
    distances = []
    for _ in range(300):
        env.step(TURN0 if s[dyn.CYCLES] % 2 else (1, (np.zeros(2), np.array([37.0]), np.zeros(2))))
        body = s[dyn.BODY]
        env.reset()
        assert s[dyn.BODY] == body  # carried over
        bx, by, px, py = s[dyn.BX], s[dyn.BY], s[dyn.PX], s[dyn.PY]
        m = dyn.TOUCH_DISTANCE / 2 + 1e-6  # a player placed on the ball is pushed off it, each by at most m
        assert -m <= bx <= 10.5 + m and abs(by) <= 27.2 + m and -0.1 - m <= px <= 52.5 + m and abs(py) <= 27.2 + m
        distances.append(math.dist((px, py), (bx, by)))
    assert 15.0 < np.mean(distances) < 24.0  # spec 2.7: mean 19.5 m
    env = HalfFieldOffenseEnv(body_reset="uniform")
    bodies = {env.reset(seed=seed)[1]["step"] or env.state[dyn.BODY] for seed in range(20)}
    assert len(bodies) == 20


def test_reset_options_place_ball_player_and_body():
    env = HalfFieldOffenseEnv()
    env.reset(seed=0, options={"ball": (40.0, -5.0), "player": (35.0, 3.0), "body": 270.0})
    s = env.state
    assert tuple(s[[dyn.BX, dyn.BY, dyn.PX, dyn.PY, dyn.BODY]]) == (40.0, -5.0, 35.0, 3.0, -90.0)
    assert tuple(s[[dyn.PVX, dyn.BVX, dyn.STAMINA]]) == (0.0, 0.0, 8000.0)
    env.reset(seed=0, options={"ball": (1.0, 2.0)})
    assert tuple(s[[dyn.BX, dyn.BY]]) == (1.0, 2.0)


@pytest.mark.parametrize(
    "options, words",
    [
        ({"ball": (60.0, 0.0)}, ["ball", "60.0", "outside"]),
        ({"ball": (-1.0, 0.0)}, ["ball", "outside"]),
        ({"player": (0.0, 40.0)}, ["player", "40.0"]),
        ({"ball": (1.0,)}, ["ball", "pair"]),
        ({"ball": "middle"}, ["ball", "pair"]),
        ({"player": (np.nan, 1.0)}, ["player", "finite"]),
        ({"body": "north"}, ["body", "angle"]),
        ({"ball_pos": (1.0, 1.0)}, ["ball_pos", "expected"]),
        ([1, 2], ["dict"]),
    ],
)
def test_bad_reset_options_raise_clear_errors(options, words):
    env = HalfFieldOffenseEnv()
    with pytest.raises(ValueError) as error:
        env.reset(seed=0, options=options)
    assert all(w in str(error.value) for w in words), str(error.value)


@pytest.mark.parametrize(
    "action, words",
    [
        (3, ["malformed", "expected"]),
        ((5, (np.zeros(2), np.zeros(1), np.zeros(2))), ["5", "DASH"]),
        ((1.5, (np.zeros(2), np.zeros(1), np.zeros(2))), ["1.5"]),
        ((0, (np.zeros(2), np.zeros(1))), ["malformed", "dash"]),  # one action is checked as a batch of one
        ((0, (np.zeros(3), np.zeros(1), np.zeros(2))), ["(1, 3)", "dash[1, 2]"]),
        ((2, (np.zeros(2), np.zeros(1), np.array([np.nan, 0.0]))), ["KICK", "finite"]),
        ((1, (np.zeros(2), np.array([np.inf]), np.zeros(2))), ["TURN", "finite"]),
    ],
)
def test_bad_actions_raise_clear_errors(action, words):
    env = HalfFieldOffenseEnv()
    env.reset(seed=0)
    with pytest.raises(ValueError) as error:
        env.step(action)
    assert all(w in str(error.value) for w in words), str(error.value)


def test_out_of_box_parameters_are_clamped_as_hfo_does():
    env = HalfFieldOffenseEnv(deterministic=True)
    env.reset(options={"player": (10.0, 0.0), "ball": (30.0, 0.0), "body": 0.0})
    env.step(dash(power=500.0, direction=10.0))
    assert env.state[dyn.PX] == pytest.approx(10.6)


def test_bad_constructor_arguments():
    with pytest.raises(ValueError, match="hfo2020"):
        HalfFieldOffenseEnv(profile="hfo2020")
    with pytest.raises(ValueError, match="random"):
        HalfFieldOffenseEnv(body_reset="random")


def test_render_and_gif(tmp_path):
    env = HalfFieldOffenseEnv(render_mode="rgb_array")
    env.reset(seed=0)
    frame = env.render()
    assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3
    assert len(np.unique(frame.reshape(-1, 3), axis=0)) >= 4  # grass, lines, ball, player
    path, _ = record_episode(env, scripted_scorer, tmp_path / "hfo.gif", seed=0, max_steps=60)
    assert (tmp_path / "hfo.gif").stat().st_size > 0 and str(path).endswith("hfo.gif")


def test_a_masked_policy_is_recorded_with_the_envs_masks(tmp_path):
    """``record_episode(..., action_mask=True)`` hands the policy each step's ``info["action_mask"]`` (what
    ``pamdp render`` does for a model trained with masks): the same masks as stepping the env by hand."""
    env = HalfFieldOffenseEnv(render_mode="rgb_array")
    given = []
    record_episode(
        env,
        lambda obs, action_mask: given.append(action_mask) or scripted_scorer(obs),
        tmp_path / "m.gif",
        seed=3,
        action_mask=True,
    )
    obs, info = env.reset(seed=3)
    expected = [info["action_mask"]]
    while True:
        obs, _, terminated, truncated, info = env.step(scripted_scorer(obs))
        if terminated or truncated:
            break
        expected.append(info["action_mask"])
    assert len(given) == len(expected) > 10
    np.testing.assert_array_equal(np.array(given), np.array(expected))
    assert {tuple(m) for m in given} == {(True, True, False), (True, True, True)}  # KICK masked until kickable


def test_record_episode_rejects_a_path_that_is_not_a_gif_before_playing(tmp_path):
    env = HalfFieldOffenseEnv(render_mode="rgb_array")
    played = []
    with pytest.raises(ValueError, match=r"'.*episode.mp4'; expected a file name ending in .gif"):
        record_episode(env, lambda obs: played.append(obs) or scripted_scorer(obs), tmp_path / "episode.mp4")
    assert played == [] and not (tmp_path / "episode.mp4").exists()


def test_scripted_scorer_scores_usually():
    env = HalfFieldOffenseEnv()
    goals = 0
    for seed in range(10):
        obs, _ = env.reset(seed=seed)
        while True:
            obs, _, terminated, truncated, info = env.step(scripted_scorer(obs))
            if terminated or truncated:
                assert info["is_success"] == (info["status"] == "GOAL")
                goals += info["is_success"]
                break
            assert "is_success" not in info  # only at the end of an episode
    assert goals >= 8
