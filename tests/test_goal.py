"""Robot Soccer Goal and Hard Goal against ``shared/specs/goal.md``: the recordings of the original (copied to
``tests/data/goal_traces.json`` and ``hard_goal_traces.json``), the spec's worked numbers, and the batched
envs against the scalar ones."""

import math
import pathlib

import gymnasium
import numpy as np
import pytest
from domain_replay import assert_refused, assert_same_step, load_cases, params_for, replay
from gymnasium.utils.env_checker import check_env
from gymnasium.vector import SyncVectorEnv

import pamdp  # noqa: F401  (registers the envs)
from pamdp.envs.goal import (
    GoalEnv,
    GoalVectorEnv,
    HardGoalEnv,
    HardGoalVectorEnv,
    dynamics,
    hard_goal_shot,
    save_goal_gif,
)
from pamdp.spaces import HybridActionSpace

CASES = load_cases("goal_traces.json", "hard_goal_traces.json")
ENV_IDS = ["pamdp/Goal-v0", "pamdp/HardGoal-v0"]
LONG_CASES = {910367, 920148}
"""The two 100-step cases: their kicks' directions come from NumPy's arctan2 in the original, which on the
recordings' AVX-512 build differs from libm's ``atan2`` (used here) in the last bit for some inputs."""


def check_goal(rec, env, info, where):
    """Goal's extras: the sub-steps of every record, and success reported at an episode's end (a goal)."""
    assert info["substeps"] == rec["substeps"], where
    if rec.get("terminal") or rec.get("truncated"):  # the Gymnasium way of reporting success
        assert info["is_success"] == (rec["kind"] == "goal"), where
    else:
        assert "is_success" not in info, where


@pytest.mark.parametrize("case", CASES, ids=[f"{c['domain']}-{c['seed']}" for c in CASES])
def test_replays_the_original(case):
    identical, records = replay(case, check_goal)
    assert case["kinds"] == [rec["kind"] for rec in case["trace"] if rec.get("kind")]
    if case["seed"] not in LONG_CASES:
        assert identical == records  # bit for bit
    else:
        assert identical >= records // 20


def test_observation_of_recorded_states_is_bit_exact():
    # The 17 features computed from the original's own internal state, so no dynamics can drift: the
    # norm of f14/f15 must be NumPy's (sqrt(fma(dy, dy, dx*dx)) on the recordings' build), and the
    # scaling the spec's float32 bounds in its order of operations.
    records = [rec for case in CASES for rec in case["trace"] if "raw" in rec]
    states = np.zeros((len(records), dynamics.STATE_SIZE))
    states[:, :14] = [rec["raw"]["state14"] for rec in records]
    out = np.empty((len(records), dynamics.OBS_SIZE))
    dynamics.observe(states, out)
    np.testing.assert_array_equal(out, [rec["obs"] for rec in records])
    assert len(records) == 229


@pytest.mark.parametrize(
    "j, expected",
    [  # spec §4.2: y(p = -1), y(0), y(+1) of each part, then Goal's clip to [-7.01, 7.01]
        (0, (-4.206000137329102, -5.608000183105469, -7.01)),
        (1, (-1.4020000457763677, -2.8040000915527346, -4.206000137329101)),
        (2, (1.4020000457763668, 1.4020000457763668, 1.4020000457763668)),
        (3, (4.206000137329102, 2.8040000915527337, 1.4020000457763668)),
        (4, (7.01, 5.608000183105469, 4.206000137329102)),
    ],
)
def test_hard_goal_shot_matches_the_spec_table(j, expected):
    y = np.clip(hard_goal_shot(j, np.array([-1.0, 0.0, 1.0])), -7.01, 7.01)
    assert y.tolist() == list(expected)


def test_hard_goal_recorded_shots_aim_where_the_original_did():
    shots = [rec for case in CASES if case["domain"] == "hard_goal" for rec in case["trace"] if rec.get("act_index")]
    for rec in shots:
        a = rec["act_index"]
        y = min(max(hard_goal_shot((a - 1) % 5, rec["param"][0]), -7.01), 7.01)
        assert rec["orig_action"] == [1, [y]]
    assert len(shots) > 0


@pytest.mark.parametrize("a, p", [(1, -1.0), (2, 0.0), (3, 0.7), (5, 1.0), (8, -0.3), (10, 0.25)])
def test_hard_goal_is_goal_with_the_shot_moved(a, p):
    # Hard Goal's shoot action a with parameter p is Goal's shot at the spec's y for part (a - 1) % 5.
    hard, goal = HardGoalEnv(), GoalEnv()
    hard.reset(seed=5)
    goal.reset(seed=5)
    kick = np.array([6.0, 0.0])
    for env in (hard, goal):
        env.step((0, params_for(env.action_space, 0, kick)))
    y = min(max(hard_goal_shot((a - 1) % 5, p), -7.01), 7.01)
    got = hard.step((a, params_for(hard.action_space, a, p)))
    want = goal.step((1, (np.zeros(2), np.array([y]), np.zeros(1))))
    np.testing.assert_array_equal(got[0], want[0])
    assert got[1:4] == want[1:4] and got[4]["substeps"] == want[4]["substeps"]


def test_hard_goal_part_2_ignores_its_parameter():
    results = []
    for a, p in [(3, -1.0), (3, 0.9), (8, 0.1)]:
        env = HardGoalEnv()
        env.reset(seed=2)
        results.append(env.step((a, params_for(env.action_space, a, p))))
    for r in results[1:]:
        np.testing.assert_array_equal(r[0], results[0][0])


def test_reset_places_ball_and_keeper_as_the_spec_says():
    env = GoalEnv()
    for seed in range(20):
        obs, info = env.reset(seed=seed)
        s = env.state
        px, py, vx, vy, phi = s["player"]
        bx, by = s["ball"][:2]
        kx, ky = s["keeper"][:2]
        assert px == 0.0 and -15 <= py <= 15 and vx == vy == 0.0 and info == {"substeps": 0}
        assert math.hypot(bx - px, by - py) == pytest.approx(1.6 - 1e-12, abs=1e-14)
        assert phi == pytest.approx(math.atan2(-py, 20.0), abs=1e-15)
        # The keeper starts at x = 14.5 on the line from the ball to the goal centre, facing the ball.
        assert kx == 14.5 and ky == pytest.approx(by * (20 - 14.5) / (20 - bx), abs=1e-12)
        assert s["keeper"][4] == pytest.approx(math.atan2(by - ky, bx - kx), abs=1e-15)
        assert obs[0] == -1.0 and s["time"] == 0 and np.all(s["ball"][2:] == 0.0)
        # The first number of the episode is the player's y, uniform(-15, 15) of the generator, bit for bit:
        # Gymnasium's (a numpy Generator) after a seeded reset, an installed RandomState after a plain one.
        assert py == np.random.default_rng(seed).uniform(-15.0, 15.0)
        env.np_random = np.random.RandomState(seed)
        env.reset()
        assert env.state["player"][1] == np.random.RandomState(seed).uniform(-15.0, 15.0)


@pytest.mark.parametrize(
    "bx, by, expected",
    [
        (10.0, 0.0, 10.0),
        (19.0, -9.0, math.hypot(1.0, 1.99)),
        (19.0, 9.0, math.hypot(1.0, 1.99)),
        (21.0, 0.0, 0.0),
        (21.0, 8.0, 0.99),
        (21.0, -8.0, 15.01),  # quirk 5: 7.01 - By, not -7.01 - By
    ],
)
def test_goal_distance(bx, by, expected):
    assert dynamics.goal_distance(bx, by) == pytest.approx(expected, abs=1e-12)


@pytest.mark.parametrize("ky, expected", [(-14.0, 1.0), (14.0, -1.0)])
def test_keeper_projection_is_clipped_to_the_quirky_bounds(ky, expected):
    # Keeper at (10, ky), ball at (12, 0): the line meets x = 20 at y = -4 ky, clipped to 14.02 above
    # (quirk 6: GW, not GW/2) and -7.01 below; both ends scale to +-1 up to float32 bounds.
    state = np.zeros((1, dynamics.STATE_SIZE))
    state[0, [dynamics.KX, dynamics.KY, dynamics.BX]] = 10.0, ky, 12.0
    out = np.empty((1, dynamics.OBS_SIZE))
    dynamics.observe(state, out)
    assert out[0, 16] == pytest.approx(expected, abs=1e-7)


def test_the_100th_step_ends_the_episode_without_moving():
    env = GoalEnv()
    env.reset(seed=1)
    stay = (0, (np.array([0.0, 0.0]), np.zeros(1), np.zeros(1)))  # kick-to (0, 0): the ball stays by the player
    for _ in range(99):
        obs, reward, terminated, truncated, info = env.step(stay)
        assert not (terminated or truncated) and info["substeps"] > 0
    assert env.state["time"] == 99
    before = env.state
    obs, reward, terminated, truncated, info = env.step(stay)
    assert truncated and not terminated and info == {"substeps": 0, "is_success": False}
    for k in ("player", "keeper", "ball"):
        np.testing.assert_array_equal(env.state[k], before[k])
    bx, by = before["ball"][:2]
    assert reward == -dynamics.goal_distance(bx, by) and reward < 0


@pytest.mark.filterwarnings("ignore:.*(infinity|symmetric and normalized)")  # the spec's spaces
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_check_env(env_id):
    check_env(gymnasium.make(env_id, render_mode="rgb_array").unwrapped, skip_render_check=False)


def test_spaces():
    goal, hard = GoalEnv(), HardGoalEnv()
    assert goal.observation_space.shape == (17,) and goal.observation_space.dtype == np.float64
    boxes = [(b.low.tolist(), b.high.tolist(), b.dtype) for b in goal.action_space[1]]
    shoot = ([np.float32(-7.01)], [np.float32(7.01)], np.float32)
    assert goal.action_space[0].n == 3 and boxes == [([0.0, -15.0], [40.0, 15.0], np.float32), shoot, shoot]
    assert hard.action_space[0].n == 11 and len(hard.action_space[1]) == 11
    assert all(b.low.tolist() == [-1.0] and b.high.tolist() == [1.0] for b in hard.action_space[1][1:])
    for env_id in ENV_IDS:
        assert gymnasium.spec(env_id).max_episode_steps is None  # the env's own 100-step rule


def assert_batched_equals_scalar(env_id, n, seed, steps, buffer_size=None):
    """The batched env against Gymnasium's SyncVectorEnv over scalar envs (env i seeded ``seed + i``,
    next-step autoreset too): even copies dribble towards the corner flag (long episodes, to the time
    limit), odd ones act at random (mostly shots). Returns the numbers of terminations and truncations."""
    venv = gymnasium.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point")
    if buffer_size is not None:
        venv.streams = type(venv.streams)(n, "random", buffer_size)
    ref = SyncVectorEnv([lambda: gymnasium.make(env_id) for _ in range(n)])
    venv.reset(seed=seed)
    ref.reset(seed=seed)
    venv.action_space.seed(seed)
    even = np.arange(n) % 2 == 0
    ended = np.zeros(2, dtype=np.int64)
    for t in range(steps):
        a, params = venv.action_space.sample()
        a = np.where(even, 0, a)
        params = (np.where(even[:, None], np.float32([0.3, 0.0]), params[0]),) + params[1:]
        got, want = venv.step((a, params)), ref.step((a, params))
        assert_same_step(got, want, f"{env_id} N={n}, step {t}", keys=("substeps",))
        reported = got[4]["_is_success"]
        np.testing.assert_array_equal(reported, got[2] | got[3])
        if reported.any():
            np.testing.assert_array_equal(got[4]["is_success"][reported], want[4]["is_success"][reported])
        state = venv.state
        for i, env in enumerate(ref.envs):
            for key in ("player", "keeper", "ball", "time"):
                np.testing.assert_array_equal(state[key][i], env.unwrapped.state[key])
        ended += got[2].sum(), got[3].sum()
    return ended


@pytest.mark.parametrize("env_id, n, seed", [("pamdp/Goal-v0", 6, 0), ("pamdp/HardGoal-v0", 5, 40)])
def test_copy_i_equals_a_scalar_env_seeded_with_seed_plus_i(env_id, n, seed):
    terminated, truncated = assert_batched_equals_scalar(env_id, n, seed, steps=210)
    assert terminated > 20 and truncated > 0  # episodes end both ways, so autoresets are compared too


def test_steps_longer_than_the_buffer_resume_where_they_stopped():
    # With 16 numbers per copy every step of more than two sub-steps stops, refills and resumes.
    terminated, _ = assert_batched_equals_scalar("pamdp/Goal-v0", 3, 7, steps=40, buffer_size=16)
    assert terminated > 5


def test_random_scripted_episodes_rarely_score():
    # Spec §8: 7 goals in 1500 episodes of "kick-to x ~ U[0, 20] up to 3 times, then shoot".
    n = 1500
    venv = GoalVectorEnv(num_envs=n)
    venv.reset(seed=0)
    rng = np.random.default_rng(0)
    done, goals = np.zeros(n, dtype=bool), 0
    for t in range(4):
        a = np.full(n, 0 if t < 3 else 1)
        kick = np.stack([rng.uniform(0, 20, n), rng.uniform(-15, 15, n)], axis=1).astype(np.float32)
        shot = rng.uniform(-7.01, 7.01, (n, 1)).astype(np.float32)
        _, reward, terminated, truncated, info = venv.step((a, (kick, shot, shot)))
        goals += int(info["is_success"][~done & terminated].sum())
        done |= terminated | truncated
    assert done.all() and 1 <= goals <= 25


def test_accepts_hybrid_action_space_batches():
    venv = HardGoalVectorEnv(num_envs=3)
    venv.reset(seed=0)
    h = HybridActionSpace.from_gym(venv.single_action_space)
    _, _, terminated, _, info = venv.step(h.to_env_batch([0, 3, 10], np.zeros((3, 2))))
    assert terminated[1:].all() and (info["substeps"] > 0).all()


@pytest.mark.parametrize(
    "action, shown",
    [
        (5, "5"),
        ((3, (np.zeros(2), np.zeros(1), np.zeros(1))), "3"),
        ((True, (np.zeros(2), np.zeros(1), np.zeros(1))), "True"),
        ((0, (np.zeros(2), np.zeros(1))), "array"),
        ((0, (np.zeros(1), np.zeros(1), np.zeros(1))), "parameter 0"),
        ((1, (np.zeros(2), np.array([np.nan]), np.zeros(1))), "nan"),
        ((0, (np.array([np.inf, 0.0]), np.zeros(1), np.zeros(1))), "inf"),
        ((1, (np.zeros(2), "far", np.zeros(1))), "'far'"),
    ],
)
def test_bad_actions_raise(action, shown):
    env = GoalEnv()
    env.reset(seed=0)
    assert_refused(env, action, shown, "expected (a, (p_0, ..., p_2))")


@pytest.mark.parametrize(
    "action, shown",
    [
        ((np.array([0, 11]), (np.zeros((2, 2)),) + (np.zeros((2, 1)),) * 10), "[11]"),
        ((np.array([0.0, 1.0]), (np.zeros((2, 2)),) + (np.zeros((2, 1)),) * 10), "array([0., 1.])"),
        ((np.array([0, 1]), (np.zeros((2, 1)),) * 11), "(2, 1)"),
        ((np.array([0, 1]), (np.zeros((2, 2)),) + (np.full((2, 1), np.nan),) * 10), "nan"),
    ],
)
def test_bad_batched_actions_raise(action, shown):
    venv = HardGoalVectorEnv(num_envs=2)
    venv.reset(seed=0)
    assert_refused(venv, action, shown, "expected (a, (p_0, ..., p_10))")


def test_render_draws_every_substep(tmp_path):
    env = GoalEnv(render_mode="rgb_array")
    env.reset(seed=0)
    assert env.render_substeps() == []

    def ball_centre(frame):  # the ball is the only white disc (the lines are thinner than it)
        white = (frame == 255).all(axis=-1)
        rows, cols = np.nonzero(white)
        return np.median(rows), np.median(cols)

    first = env.render()
    _, _, terminated, _, info = env.step((1, (np.zeros(2), np.array([0.0]), np.zeros(1))))  # a shot
    frames = env.render_substeps()
    assert terminated and len(frames) == info["substeps"] > 5
    assert first.shape == frames[0].shape and first.dtype == np.uint8
    np.testing.assert_array_equal(frames[-1], env.render())
    assert ball_centre(frames[5])[1] > ball_centre(first)[1]  # shot towards the goal, on the right
    venv = GoalVectorEnv(num_envs=2, render_mode="rgb_array")
    venv.reset(seed=0)
    assert len(venv.render()) == 2


def test_episode_gif(tmp_path):
    path, total = save_goal_gif(tmp_path / "hard_goal.gif", seed=1, env_id="pamdp/HardGoal-v0")
    assert pathlib.Path(path).stat().st_size > 1000 and total <= 50
