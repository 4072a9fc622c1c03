"""Catch Point against the recordings of HyAR's original and ``shared/specs/catch_point.md``; the batched env
against the scalar one. ``check_particle`` serves ``test_hard_move.py`` too (the same particle world)."""

import math

import gymnasium
import numpy as np
import pytest
from domain_replay import assert_same_step, load_cases, replay
from gymnasium.utils.env_checker import check_env
from gymnasium.vector import SyncVectorEnv

import pamdp  # noqa: F401  (registers the envs)
import pamdp.envs.particle as particle
from pamdp.envs.catch_point import CatchPointEnv, CatchPointVectorEnv
from pamdp.spaces import HybridActionSpace

CASES = load_cases("catch_point_traces.json")
# The spec's observation box is (-inf, inf); Gymnasium's checker warns about any unbounded box.
# (and about boxes other than [-1, 1]: the angle's is [-pi, pi]).
checker_warnings_ok = pytest.mark.filterwarnings(
    "ignore:.*observation space (minimum|maximum) value", "ignore:.*symmetric and normalized space"
)


def move(theta):
    return 0, (np.array([theta], np.float32), np.zeros(0, np.float32))


CATCH = (1, (np.array([0.5], np.float32), np.zeros(0, np.float32)))


def check_particle(rec, env, info, where):
    """The particle world's extras: ``is_success`` on every step, the raw state on every record."""
    if rec.get("event") != "reset":
        assert info["is_success"] == (rec["kind"] in ("caught", "reached")), where
    raw = rec["raw"]
    expected = [*raw["agent_pos"], *raw["agent_vel"], *raw["landmark_pos"], raw.get("failed_catches", 0)]
    np.testing.assert_allclose(env.state, expected, rtol=0, atol=1e-12, err_msg=where)


def policy(i, obs, rng):
    """Copy ``i``'s action: every third copy homes in on the target (the angle is measured from +y towards
    +x) and catches within 0.15, the others act at random, catching 80 % (so spending the budget) or 20 %
    of the time (so reaching the time limit)."""
    dx, dy = obs[2], obs[3]
    if i % 3 == 0:
        return CATCH if dx * dx + dy * dy < 0.15**2 else move(math.atan2(dx, dy))
    return CATCH if rng.random() < (0.8 if i % 3 == 1 else 0.2) else move(rng.uniform(-4.0, 4.0))


# --- the original, replayed -------------------------------------------------------------------------
@pytest.mark.parametrize("case", CASES, ids=[f"{c['seed']}-{c['kinds'][0]}" for c in CASES])
def test_replays_the_recordings_of_the_original(case):
    identical, records = replay(case, check_particle)
    print(f"catch point {case['seed']}: {identical} of {records} records bit-identical")
    assert records == len(case["trace"]) - 1


def test_the_specs_worked_reset():
    env = gymnasium.make("pamdp/CatchPoint-v0")
    env.reset(seed=0)
    env.unwrapped.np_random = np.random.RandomState(0)
    obs, info = env.reset()
    assert obs.tolist() == [0.0, 0.0, 0.10789974428863824, -0.3406123667510452]
    state = env.unwrapped.state
    assert state[[particle.AX, particle.AY]].tolist() == [0.0976270078546495, 0.43037873274483895]
    assert state[[particle.GX, particle.GY]].tolist() == [0.20552675214328775, 0.08976636599379373]
    assert info == {"failed_catches": 0}


@pytest.mark.parametrize("make_rng", [np.random.RandomState, np.random.default_rng])
def test_resets_draw_uniform_pairs_agent_first_and_nothing_ahead(make_rng):
    # uniform(-1, 1, 2) is -1 + 2 * random(), bit for bit, for both kinds of generator; resets consume
    # exactly four numbers each, so the generator is where the original's would be after them.
    env = CatchPointEnv()
    env.reset(seed=0)
    env.np_random, ref = make_rng(7), make_rng(7)
    for _ in range(3):
        env.reset()
        agent, target = ref.uniform(-1.0, 1.0, 2), ref.uniform(-1.0, 1.0, 2)
        np.testing.assert_array_equal(
            env.state[[particle.AX, particle.AY, particle.GX, particle.GY]], [*agent, *target]
        )
        env.step(move(1.0))
    assert env.np_random.random() == ref.random()


# --- the rules, computed by hand ---------------------------------------------------------------------
def test_a_move_pushes_along_sine_and_cosine_of_the_unwrapped_angle():
    env = CatchPointEnv()
    env.reset(seed=3)
    start = env.state
    theta = np.float32(7.5)  # beyond pi: used as given
    obs, reward, terminated, truncated, info = env.step(move(theta))
    fx, fy = 0.0 + math.sin(float(theta)) * 2.0, 0.0 + math.cos(float(theta)) * 2.0
    v = np.array([(fx / 1.0) * 0.1, (fy / 1.0) * 0.1])
    a = start[[particle.AX, particle.AY]] + v * 0.1
    g = start[[particle.GX, particle.GY]]
    assert obs.tolist() == [*v, *(g - a)]
    d = a - g
    assert reward == -(d[0] * d[0] + d[1] * d[1])
    # the velocity decays by 0.75 when nothing pushes; a catch does not push
    obs2, *_ = env.step(CATCH)
    assert obs2[:2].tolist() == (v * 0.75).tolist()
    assert (terminated, truncated, info) == (False, False, {"failed_catches": 0, "is_success": False})


def test_eleven_failed_catches_then_the_next_step_rewards_zero_and_ends():
    env = CatchPointEnv()
    seed = next(s for s in range(100) if np.hypot(*env.reset(seed=s)[0][2:]) > 0.5)
    env.reset(seed=seed)
    d2 = float(np.sum(env.reset(seed=seed)[0][2:] ** 2))
    for k in range(1, 12):  # at rest, a catch does not move the agent
        obs, reward, terminated, _, info = env.step(CATCH)
        assert (reward, terminated, info["failed_catches"]) == (-d2, False, k)
    obs, reward, terminated, _, info = env.step(move(0.0))  # any action
    assert (reward, terminated, info) == (0.0, True, {"failed_catches": 11, "is_success": False})


def test_a_catch_within_the_radius_after_the_move_succeeds():
    env = CatchPointEnv()
    env.reset(seed=0)
    # Put the agent 0.2 from the target, drifting away: the catch is tested after this step's move.
    for vy, caught in ((0.0, True), (0.001, False)):
        env._states[0, [particle.AX, particle.AY, particle.VX, particle.VY]] = [0.3, 0.2, 0.0, vy]
        env._states[0, [particle.GX, particle.GY, particle.FAILS]] = [0.3, 0.0, 0.0]
        obs, reward, terminated, _, info = env.step(CATCH)
        d2 = (0.2 + vy * 0.75 * 0.1) ** 2
        assert d2 <= 0.2**2 if caught else d2 > 0.2**2
        assert (terminated, info["is_success"], info["failed_catches"]) == (caught, caught, 1 - caught)
        assert reward == pytest.approx(20.0 - d2 if caught else -d2, abs=1e-15)


def test_the_time_limit_truncates_at_25_steps():
    env = gymnasium.make("pamdp/CatchPoint-v0")
    env.reset(seed=0)
    flags = [env.step(move(0.0))[2:4] for _ in range(25)]
    assert flags == [(False, False)] * 24 + [(False, True)]


# --- the Gymnasium API ----------------------------------------------------------------------------------
@checker_warnings_ok
def test_passes_gymnasiums_env_checker_and_its_spaces_are_the_specs():
    env = CatchPointEnv()
    check_env(env, skip_render_check=True)
    theta, catch = env.action_space[1]
    assert env.action_space[0].n == 2 and catch.shape == (0,)
    assert theta.shape == (1,) and theta.low[0] == -3.1415927410125732 and theta.high[0] == 3.1415927410125732
    assert env.observation_space == gymnasium.spaces.Box(-np.inf, np.inf, (4,), np.float64)
    space = HybridActionSpace.from_gym(env.action_space)
    assert space.param_sizes == (1, 0) and space.scale(0, [1.0])[0] == 3.1415927410125732


@pytest.mark.parametrize(
    "action, match",
    [
        ((2, (np.zeros(1), np.zeros(0))), "copy 0: action 2 with angle 0.0"),
        ((True, (np.zeros(1), np.zeros(0))), r"invalid discrete actions array\(\[ True\]\)"),
        ((0, (np.array([np.nan]), np.zeros(0))), "copy 0: action 0 with angle nan"),
        ((1, (np.array([np.inf]), np.zeros(0))), "copy 0: action 1 with angle inf"),
        ((0, (np.zeros(2), np.zeros(0))), "invalid angle"),
        ((1, (np.zeros(1), np.zeros(3))), "invalid catch parameter"),
        ((0, (np.zeros(1),)), "invalid parameters"),
        (0, "invalid batch of Catch Point actions 0"),
    ],
)
def test_bad_actions_are_refused(action, match):
    env = CatchPointEnv()
    env.reset(seed=0)
    with pytest.raises(ValueError, match=match):
        env.step(action)


# --- the batched env ------------------------------------------------------------------------------------
@pytest.mark.parametrize("n, seed", [(1, 0), (6, 40)])
def test_copy_i_equals_a_scalar_env_seeded_with_seed_plus_i(n, seed):
    venv = gymnasium.make_vec("pamdp/CatchPoint-v0", num_envs=n, vectorization_mode="vector_entry_point")
    assert isinstance(venv, CatchPointVectorEnv) and venv.max_episode_steps == 25
    ref = SyncVectorEnv([lambda: gymnasium.make("pamdp/CatchPoint-v0") for _ in range(n)])
    got, want = venv.reset(seed=seed), ref.reset(seed=seed)
    np.testing.assert_array_equal(got[0], want[0])
    rng = np.random.default_rng(seed)
    endings = set()
    for t in range(300):
        actions = [policy(i, o, rng) for i, o in enumerate(got[0])]
        batch = (
            np.array([a for a, _ in actions]),
            (np.stack([p[0] for _, p in actions]), np.zeros((n, 0), np.float32)),
        )
        got, want = venv.step(batch), ref.step(batch)
        assert_same_step(got, want, f"step {t}")
        np.testing.assert_array_equal(venv.unwrapped.states, [e.unwrapped.state for e in ref.envs])
        ended = got[2] | got[3]
        endings |= {("caught" if r > 4 else "budget" if r == 0 else "time") for r in got[1][ended]}
    if n > 1:
        assert endings == {"caught", "budget", "time"}  # autoresets after each kind of ending compared


def test_batched_actions_are_checked():
    venv = CatchPointVectorEnv(num_envs=2)
    venv.reset(seed=0)
    theta = np.zeros((2, 1), np.float32)
    with pytest.raises(ValueError, match=r"copy 1: action 3 with angle 0.0; expected"):
        venv.step((np.array([0, 3]), (theta, np.zeros((2, 0)))))
    before = venv.states
    with pytest.raises(ValueError, match=r"copy 0: action 1 with angle nan; expected"):
        venv.step((np.array([1, 0]), (np.array([np.nan, 0.0]), np.zeros((2, 0)))))
    np.testing.assert_array_equal(venv.states, before)  # checked before any copy moves
    with pytest.raises(ValueError, match="invalid angles of shape"):
        venv.step((np.array([1, 0]), (np.zeros((2, 2)), np.zeros((2, 0)))))


# --- pictures -------------------------------------------------------------------------------------------
def test_frames_show_the_target_and_the_agent_where_they_are():
    env = CatchPointEnv(render_mode="rgb_array")
    env.reset(seed=5)
    env.step(CATCH)
    frame = env.render()
    assert frame.shape == (particle.RENDER_SIZE, particle.RENDER_SIZE, 3) and frame.dtype == np.uint8
    s = env.state
    for (x, y), colour in (((s[particle.GX], s[particle.GY]), (40, 160, 60)), ((s[0], s[1]), (40, 80, 220))):
        px, py = particle.to_pixels(x, y)
        assert tuple(frame[int(py), int(px)]) == colour
    assert tuple(frame[12, 12]) == (210, 50, 50)  # the first of 11 failed catches spent
    venv = CatchPointVectorEnv(num_envs=2, render_mode="rgb_array")
    venv.reset(seed=5)
    venv.step((np.array([1, 0]), (np.zeros((2, 1), np.float32), np.zeros((2, 0), np.float32))))
    np.testing.assert_array_equal(venv.render()[0], frame)
