"""gym-hybrid's Moving and Sliding against recordings of the original and ``shared/specs/gym_hybrid.md``."""

import math

import gymnasium
import numpy as np
import pytest
from domain_replay import assert_refused, assert_same_step, load_cases, replay
from gymnasium.utils.env_checker import check_env
from gymnasium.vector import SyncVectorEnv

import pamdp  # noqa: F401  (registers the envs)
from pamdp.envs.gym_hybrid import MovingEnv, MovingVectorEnv, SlidingEnv, SlidingVectorEnv
from pamdp.envs.gym_hybrid import dynamics as dyn
from pamdp.envs.gym_hybrid.env import check_settings

CASES = load_cases("moving.json", "sliding.json")
IDS = ["pamdp/Moving-v0", "pamdp/Sliding-v0"]
# The spec's observation box is (-inf, inf); Gymnasium's checker warns about any unbounded box.
unbounded_ok = pytest.mark.filterwarnings("ignore:.*observation space (minimum|maximum) value")

BIT_IDENTICAL = {960002: 23}
"""Records (resets and steps) of a case not bit-identical to the recording: all of them but these. At Sliding
960002's step 23 the recording's cos(φ - θ) is one unit in the last place above the correctly rounded value
that the C library gives (and NumPy here): the recording machine's NumPy used its AVX-512 cosine. From there
the speed and direction differ in the last bits, within the tolerance."""


def act(a, p=0.0):
    """Action ``a`` with parameter ``p`` (float32, as the space holds it); the other parameter is off-range
    and ignored."""
    params = [np.array([5.0], np.float32), np.array([-5.0], np.float32), np.zeros(0, np.float32)]
    if a < 2:
        params[a] = np.array([p], np.float32)
    return a, tuple(params)


def homing(obs):
    """A scripted policy from the observation: turn (at rest) towards the target, accelerate, break near it."""
    x, y, s, c, sn, tx, ty, d = obs[:8]
    diff = (math.atan2(ty - y, tx - x) - math.atan2(sn, c) + math.pi) % (2 * math.pi) - math.pi
    if d < 0.07 or (abs(diff) > 0.05 and s > 0) or s > 8 * d:
        return 2, 0.0
    if abs(diff) > 0.05:
        return 1, diff / (math.pi / 2)
    return 0, 0.4


# --- the original, replayed -------------------------------------------------------------------------
@pytest.mark.parametrize("case", CASES, ids=[f"{c['domain']}-{c['seed']}" for c in CASES])
def test_replays_the_recordings_of_the_original(case):
    def check(rec, env, info, where):
        assert info.get("is_success") == (rec["kind"] == "goal" if rec.get("terminal") else None), where
        assert env.state[dyn.THETA] == pytest.approx(rec["raw"]["theta"], rel=0, abs=1e-12), where
        # The recorder carried one Sliding env from case to case, so phi starts where the previous case left
        # it: unobservable, since a moving slider's phi is set by its first acceleration from rest.
        if rec["raw"]["phi"] is not None and env.state[dyn.SPEED] > 0:
            assert env.state[dyn.PHI] == pytest.approx(rec["raw"]["phi"], rel=0, abs=1e-12), where

    identical, records = replay(case, check)
    assert identical == BIT_IDENTICAL.get(case["seed"], records)


def test_reset_from_random_state_0_gives_the_spec_numbers():
    env = gymnasium.make("pamdp/Moving-v0")
    env.reset(seed=0)
    env.unwrapped.np_random = np.random.RandomState(0)
    obs, info = env.reset()
    spec = [
        0.08976636599379373, -0.15269040132219058, 0.0, -0.6084584106582767, -0.7935857625355963,
        0.08786430706918458, 0.387340859470355, 0.5400346104291271, 0.0, 0.0,
    ]  # fmt: skip
    assert obs.tolist() == spec and info == {}


@pytest.mark.parametrize("make_rng", [np.random.RandomState, np.random.default_rng], ids=["RandomState", "Generator"])
def test_reset_draws_the_originals_two_uniforms_and_nothing_ahead(make_rng):
    # The original calls uniform([-0.9, -0.9, 0.1], [0.9, 0.9, 0.1]), then uniform([-1, -1, 0], [1, 1, 2 pi]).
    env = SlidingEnv()
    env.reset(seed=0)
    env.np_random, ref = make_rng(5), make_rng(5)
    for _ in range(3):
        obs, _ = env.reset()
        tx, ty, radius = ref.uniform([-0.9, -0.9, 0.1], [0.9, 0.9, 0.1])
        x, y, theta = ref.uniform([-1.0, -1.0, 0.0], [1.0, 1.0, 2 * np.pi])
        assert obs[[0, 1, 5, 6]].tolist() == [x, y, tx, ty] and radius == 0.1
        assert env.state[dyn.THETA] == theta and obs[3] == np.cos(theta) and obs[2] == obs[9] == 0.0
        assert env.np_random.random() == ref.random()  # the generator is left where the original leaves it


def test_squares_are_c_pow_not_products():
    # The original's ``** 2`` is C's pow, which differs from v * v in the last bit for a few inputs; pow2
    # finds it without calling pow for most of them. The hard inputs below are each nearest a halfway case.
    rng = np.random.default_rng(0)
    v = np.concatenate(
        [rng.uniform(-2.0, 2.0, 100_000), rng.uniform(-1e-3, 1e-3, 10_000), [0.0, -0.0, 2.0**-60, 1e120]]
    )
    pow2 = np.array([dyn.pow2(x) for x in v])
    assert pow2.tolist() == [math.pow(x, 2) for x in v]
    assert (pow2 != v * v).sum() > 50
    assert [dyn.c_pow2(x) for x in v[:2000]] == [math.pow(x, 2) for x in v[:2000]]


def test_wrap_angle_is_pythons_floor_mod():
    rng = np.random.default_rng(1)
    tiny = [0.0, -0.0, -1e-300, -1e-17, 2 * np.pi, np.nextafter(2 * np.pi, 0), 4 * np.pi, -2 * np.pi, 1e5, -1e5]
    a = np.concatenate([rng.uniform(-np.pi / 2, 2.5 * np.pi, 50_000), rng.uniform(-50.0, 50.0, 5_000), tiny])
    got = [dyn.wrap_angle(x) for x in a]
    want = [float(x) % (2 * np.pi) for x in a]
    assert got == want and [math.copysign(1, g) for g in got] == [math.copysign(1, w) for w in want]


# --- the rules, from the spec's formulas --------------------------------------------------------------
def start(x=0.0, y=0.0, theta=0.0, tx=0.5, ty=0.5):
    """One copy's states array (one row), at rest."""
    state = dyn.INITIAL_STATE[None].copy()
    state[0, [dyn.X, dyn.Y, dyn.THETA, dyn.TX, dyn.TY]] = x, y, theta, tx, ty
    dyn.refresh(state, 0)
    return state


def step(state, a, p, sliding):
    return dyn.step(state, 0, a, p, dyn.DEFAULTS, sliding)


def observe(state):
    out = np.empty((1, dyn.OBS_SIZE))
    dyn.observe(state, 0, dyn.DEFAULTS, out)
    return out[0]


def test_moving_goes_along_its_heading_and_sliding_keeps_its_velocity():
    moving, sliding = start(), start()
    for state, is_sliding in ((moving, False), (sliding, True)):
        step(state, 0, 1.0, is_sliding)  # speed 0.5, one move of 0.005 * 0.5 along x
        step(state, 1, 1.0, is_sliding)  # heading pi/2, then a move
    assert moving[0, [dyn.X, dyn.Y, dyn.SPEED]].tolist() == pytest.approx([0.0025, 0.0025, 0.5], abs=1e-15)
    assert sliding[0, [dyn.X, dyn.Y, dyn.SPEED]].tolist() == pytest.approx([0.005, 0.0, 0.5], abs=1e-15)
    assert sliding[0, dyn.THETA] == moving[0, dyn.THETA] == np.pi / 2
    # Thrust 0.5 along y added to velocity 0.5 along x: speed sqrt(0.5) at 45 degrees, as vectors add.
    step(sliding, 0, 1.0, True)
    assert sliding[0, dyn.SPEED] == pytest.approx(math.hypot(0.5, 0.5), abs=1e-15)
    assert sliding[0, dyn.PHI] == pytest.approx(np.pi / 4, abs=1e-15)
    assert sliding[0, dyn.X] == pytest.approx(0.005 + 0.0025, abs=1e-15)


def test_break_slows_by_a_tenth_or_stops_and_a_stopped_slider_faces_its_heading():
    state = start(theta=1.0)
    step(state, 0, 0.5, True)  # speed 0.25 along the heading
    step(state, 1, 0.5, True)  # heading 1 + pi/4, still sliding at angle 1
    speeds = []
    for _ in range(3):
        step(state, 2, 0.0, True)
        speeds.append(state[0, dyn.SPEED])
    assert speeds == pytest.approx([0.15, 0.05, 0.0], abs=1e-15) and speeds[-1] == 0.0
    assert state[0, dyn.PHI] == state[0, dyn.THETA] == 1.0 + np.pi / 4


@pytest.mark.parametrize(
    "a, p, theta, speed",
    [
        (0, 2.0, 0.0, 0.5),  # accelerate clipped to 1: 0.5
        (0, -1.0, 0.0, 0.0),
        (1, -3.0, 0.25, 0.0),  # turn clipped to -1: 0.25 - pi/2, wrapped into [0, 2 pi)
        (1, 1.0, 0.25, 0.0),
    ],
)
def test_parameters_are_clipped_and_the_heading_wrapped(a, p, theta, speed):
    state = start(theta=0.25 if a == 1 else 0.0)
    step(state, a, p, False)
    want = (theta + np.clip(p, -1, 1) * np.pi / 2) % (2 * np.pi) if a == 1 else theta
    assert state[0, dyn.THETA] == want and 0 <= state[0, dyn.THETA] < 2 * np.pi and state[0, dyn.SPEED] == speed


def test_the_goal_needs_a_full_stop_strictly_inside_the_target():
    # At distance exactly 0.1 the indicator says "inside" but stopping there is no goal.
    edge = start(x=0.1, tx=0.0, ty=0.0)
    assert dyn.distance(edge, 0) == 0.1 and observe(edge)[8] == 1.0
    assert step(edge, 2, 0.0, False) == (-0.001, False, False)
    inside = start(x=0.05, tx=0.0, ty=0.0)
    step(inside, 0, 0.2, False)  # moving: no goal
    assert not step(inside, 1, 0.0, False)[1]
    d_prev = dyn.distance(inside, 0)
    reward, terminated, goal = step(inside, 2, 0.0, False)  # speed 0.1 - 0.1 = 0: stopped
    assert terminated and goal and reward == ((d_prev - dyn.distance(inside, 0)) - 0.001) + 1


def test_leaving_the_field_is_strict():
    state = start(x=1.0, tx=0.0)
    assert step(state, 1, 0.0, False) == (-0.001, False, False)  # on the edge: still in
    assert step(state, 0, 0.01, False) == (-1.0, True, False) and state[0, dyn.X] > 1.0


def test_an_episode_has_201_steps_the_last_one_rewarded_minus_one():
    env = gymnasium.make("pamdp/Sliding-v0")
    obs, _ = env.reset(seed=3)
    assert obs[7] > 0.1  # the agent does not start in the target, so standing still never scores
    results = []
    for _ in range(300):
        results.append(env.step(act(1, 0.0)))  # turning by 0 at rest: the agent never moves
        if results[-1][2] or results[-1][3]:
            break
    assert len(results) == 201 and [r[1] for r in results[:-1]] == [-0.001] * 200
    assert results[-1][1:] == (-1.0, True, False, {"is_success": False}) and results[-1][0][9] == 1.005


def test_settings_change_the_dynamics():
    env = MovingEnv(max_step=10, penalty=0.0, max_acceleration=1.0, delta_t=0.01, break_value=0.25)
    obs0, _ = env.reset(seed=3)
    obs, reward, *_ = env.step(act(0, 1.0))  # speed 1: one move of 0.01 along the heading
    np.testing.assert_allclose(obs[:2] - obs0[:2], 0.01 * obs0[3:5], rtol=0, atol=1e-15)
    assert obs[2] == 1.0 and obs[9] == 0.1 and reward == obs0[7] - obs[7]
    assert env.step(act(2))[0][2] == 0.75
    ended = [env.step(act(1, 0.0))[2] for _ in range(9)]
    assert ended == [False] * 8 + [True]  # the step after the 10th ends the episode


def test_a_homing_policy_reaches_the_goal():
    env = gymnasium.make("pamdp/Moving-v0")
    successes = []
    for episode in range(20):
        obs, _ = env.reset(seed=episode)
        while True:
            obs, reward, terminated, truncated, info = env.step(act(*homing(obs)))
            if terminated:
                break
        successes.append(info["is_success"])
        if info["is_success"]:
            assert reward > 0.99 and obs[2] == 0.0 and obs[7] < 0.1
    assert np.mean(successes) >= 0.6


# --- the Gymnasium API ---------------------------------------------------------------------------------
@unbounded_ok
@pytest.mark.parametrize("env_id", IDS)
def test_check_env_and_spaces(env_id):
    env = gymnasium.make(env_id, render_mode="rgb_array")
    assert env.spec.max_episode_steps is None
    check_env(env.unwrapped, skip_render_check=False)
    space = env.action_space
    assert space[0].n == 3
    assert [(b.low.tolist(), b.high.tolist(), b.dtype) for b in space[1]] == [
        ([0.0], [1.0], np.float32),
        ([-1.0], [1.0], np.float32),
        ([], [], np.float32),
    ]
    assert env.observation_space.shape == (10,) and env.observation_space.dtype == np.float64


@pytest.mark.parametrize(
    "action, shown",
    [
        (5, "5"),
        ((3, (1.0, 1.0, np.zeros(0))), "3"),
        ((True, (1.0, 1.0, np.zeros(0))), "True"),
        ((0, (1.0, 1.0)), "(1.0, 1.0)"),
        ((0, (np.array([1.0, 2.0]), 1.0, np.zeros(0))), "array([[1., 2.]])"),  # checked as a batch of one
        ((1, (0.5, float("inf"), np.zeros(0))), "inf"),
        ((2, (0.5, 0.5, np.zeros(1))), "break parameter"),
    ],
)
def test_bad_actions_raise(action, shown):
    env = MovingEnv()
    env.reset(seed=0)
    assert_refused(env, action, shown, "expected (a, (p_accelerate, p_turn, p_break))")


@pytest.mark.parametrize(
    "kwargs, shown",
    [
        (dict(max_step=0), "max_step=0; expected a positive integer"),
        (dict(max_step=20.0), "max_step=20.0"),
        (dict(delta_t=-0.1), "delta_t=-0.1; expected a positive number"),
        (dict(penalty=float("nan")), "penalty=nan; expected a finite number"),
        (dict(max_turn="wide"), "max_turn='wide'"),
        (dict(break_value=True), "break_value=True"),
        (dict(render_mode="human"), "render_mode='human' is not supported"),
    ],
)
def test_bad_constructor_arguments_raise(kwargs, shown):
    for make in (MovingEnv, SlidingVectorEnv):
        with pytest.raises(ValueError, match=shown.replace("(", r"\(").replace("[", r"\[")):
            make(**kwargs)


def test_check_settings_names_an_unknown_setting():
    with pytest.raises(ValueError, match="unknown setting 'max_speed'"):
        check_settings(max_speed=1.0)


def test_render_shows_target_and_agent():
    env = SlidingEnv(render_mode="rgb_array")
    env.reset(seed=1)
    frame = env.render()
    s = env.state

    def pixel(x, y):
        return frame[int(round((1.1 - y) * 200)), int(round((x + 1.1) * 200))].tolist()

    assert frame.shape == (440, 440, 3) and frame.dtype == np.uint8
    behind = s[[dyn.X, dyn.Y]] - 0.03 * np.array([np.cos(s[dyn.THETA]), np.sin(s[dyn.THETA])])
    assert pixel(s[dyn.TX], s[dyn.TY]) == [250, 170, 170] and pixel(*behind) == [40, 80, 220]
    assert pixel(*s[[dyn.X, dyn.Y]]) == [0, 0, 0]  # the heading starts at the agent's centre
    assert pixel(-1.05, 0.0) == [150, 150, 150] and MovingEnv().render() is None


# --- the batched envs ------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "env_id, n, seed", [("pamdp/Moving-v0", 1, 0), ("pamdp/Moving-v0", 9, 4), ("pamdp/Sliding-v0", 12, 40)]
)
def test_copy_i_equals_a_scalar_env_seeded_with_seed_plus_i(env_id, n, seed):
    """The batched env against Gymnasium's SyncVectorEnv over scalar envs (env i seeded ``seed + i``, next-step
    autoreset too): copies play random actions, the homing policy or stand still, so episodes end at the
    goal, out of the field and at the step limit; every output and state must be equal after every step."""
    venv = gymnasium.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point")
    assert isinstance(venv, (MovingVectorEnv, SlidingVectorEnv)) and venv.max_episode_steps is None
    ref = SyncVectorEnv([lambda: gymnasium.make(env_id) for _ in range(n)])
    obs, _ = venv.reset(seed=seed)
    np.testing.assert_array_equal(obs, ref.reset(seed=seed)[0])
    venv.action_space.seed(seed)
    kind = np.arange(n) % 3  # 0: random, 1: homing, 2: stand still
    endings = np.zeros(3, dtype=np.int64)
    for t in range(450):
        a, (p0, p1, p2) = venv.action_space.sample()
        scripted = [act(*homing(o)) if k == 1 else act(1, 0.0) for o, k in zip(obs, kind)]
        a = np.where(kind == 0, a, [s[0] for s in scripted])
        p0 = np.where(kind[:, None] == 0, p0, [s[1][0] for s in scripted])
        p1 = np.where(kind[:, None] == 0, p1, [s[1][1] for s in scripted])
        action = (a, (p0, p1, p2))
        got, want = venv.step(action), ref.step(action)
        assert_same_step(got, want, f"step {t}", keys=())
        ended = got[2]
        np.testing.assert_array_equal(got[4]["_is_success"], ended)
        if ended.any():
            np.testing.assert_array_equal(got[4]["is_success"][ended], want[4]["is_success"][ended])
        np.testing.assert_array_equal(venv.unwrapped.states, [e.unwrapped.state for e in ref.envs])
        timed_out = ended & (got[0][:, 9] > 1)
        endings += [
            (got[4]["is_success"] & ended).sum(),
            (ended & ~got[4]["is_success"] & ~timed_out).sum(),
            timed_out.sum(),
        ]
        obs = got[0]
    assert (endings > 0).all() if n > 1 else endings[1] > 0  # goals, leaving the field, the step limit


@pytest.mark.parametrize(
    "action, shown",
    [
        ((np.array([0, 3]), (np.zeros((2, 1)), np.zeros((2, 1)), np.zeros((2, 0)))), "copy 1: discrete action 3"),
        ((np.array([0.0, 1.0]), (np.zeros((2, 1)), np.zeros((2, 1)), np.zeros((2, 0)))), "array([0., 1.])"),
        ((np.array([0, 1]), (np.zeros((2, 2)), np.zeros((2, 1)), np.zeros((2, 0)))), "(2, 2)"),
        ((np.array([0, 1]), (np.zeros((2, 1)), np.array([[np.nan], [0.0]]), np.zeros((2, 0)))), "copy 0"),
        (
            (np.array([0, 1]), (np.zeros((2, 1)), np.zeros((2, 1)), np.zeros((2, 1)))),
            "break parameters of shape (2, 1)",
        ),
        (np.array([0, 1]), "array([0, 1])"),
    ],
)
def test_bad_batched_actions_raise(action, shown):
    venv = MovingVectorEnv(num_envs=2)
    venv.reset(seed=0)
    assert_refused(venv, action, shown, "expected (a, (p_accelerate, p_turn, p_break))")


def test_batched_render_returns_one_frame_per_copy():
    venv = SlidingVectorEnv(num_envs=3, render_mode="rgb_array")
    venv.reset(seed=0)
    frames = venv.render()
    assert len(frames) == 3 and all(f.shape == (440, 440, 3) for f in frames)
    assert not np.array_equal(frames[0], frames[1])
