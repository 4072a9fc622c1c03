"""The scalar Platform env against the numbers of ``shared/specs/platform.md`` (section 8 and friends)."""

import gymnasium
import numpy as np
import pytest
from domain_replay import assert_refused
from gymnasium.utils.env_checker import check_env

import pamdp  # noqa: F401  (registers pamdp/Platform-v0)
from pamdp.envs.platform import PlatformEnv, ZeroNoise, physics, save_platform_gif

SCRIPT = [(1, 480), (0, 30), (0, 0), (1, 720), (1, 480), (0, 5), (0, 5), (1, 720), (0, 5), (0, 30)]
"""The spec's open-loop policy (§8): noise-free it reaches the goal in 9 steps."""


def act(a, p):
    """Action ``a`` with parameter ``p``; the other parameters get arbitrary in-range values."""
    params = [np.array([v], dtype=np.float32) for v in (15.0, 360.0, 215.0)]
    params[a] = np.array([p], dtype=np.float32)
    return a, tuple(params)


def noise_free_env():
    env = PlatformEnv()
    env.reset()
    env.np_random = ZeroNoise()
    return env


def play(env, actions):
    """Step through ``actions`` until the episode ends; return the list of step results."""
    results = []
    for a, p in actions:
        results.append(env.step(act(a, p)))
        if results[-1][2] or results[-1][3]:
            break
    return results


def test_spaces_and_reset_observation():
    env = gymnasium.make("pamdp/Platform-v0")
    assert env.spec.max_episode_steps is None and env.unwrapped.max_episode_steps == 200  # the env's own limit
    obs, info = env.reset(seed=0)
    s0 = [0.018957, 0, 0.222222, 0, 0.909091, 1, 0.957447, 0, 0]  # spec §4
    np.testing.assert_allclose(obs, s0, atol=1e-6)
    assert obs.dtype == np.float64 and obs in env.observation_space
    assert info == {"substeps": 0}
    space = env.action_space
    assert space[0].n == 3
    assert [(float(b.low[0]), float(b.high[0]), b.shape, b.dtype) for b in space[1]] == [
        (0.0, 30.0, (1,), np.float32),
        (0.0, 720.0, (1,), np.float32),
        (0.0, 430.0, (1,), np.float32),
    ]


def test_run_from_rest():
    env = noise_free_env()
    _, reward, terminated, _, info = env.step(act(0, 30))
    x, y, vx, _ = env.state["player"]
    assert info["substeps"] == 20
    assert x == pytest.approx(67.5, abs=0.05) and vx == pytest.approx(69.3, abs=1e-9) and y == 40.0
    assert reward == pytest.approx(x / 1035) and not terminated


@pytest.mark.parametrize(
    "prefix, a, p, substeps, v0, terminated",
    [
        ([], 1, 720, 144, 30.0, False),  # hop from rest: the take-off impulse is capped at +30
        (SCRIPT[:3], 1, 720, 144, 70.0, False),  # hop at ground speed: lands on platform 2
        ([], 2, 0, 104, 0.0, False),  # leap straight up
        (SCRIPT[:6], 2, 430, 104, 70.0, True),  # leap at ground speed from platform 2: into gap 2
    ],
)
def test_jump_flight(prefix, a, p, substeps, v0, terminated):
    env = noise_free_env()
    play(env, prefix)
    x0 = env.state["player"][0]
    _, _, term, _, info = env.step(act(a, p))
    assert info["substeps"] == substeps and term == terminated
    # §3: horizontal flight distance 5 v0 (1 - 0.99^n): 267.7 px for a hop, 227.0 for a leap at v0 = 70.
    assert env.state["player"][0] - x0 == pytest.approx(5 * v0 * (1 - 0.99**substeps), rel=1e-9, abs=1e-9)
    if not terminated:
        assert env.state["player"][1] == 40.0 and env.state["player"][2] == 0.0  # landing zeroes vx


def test_scripted_policy_noise_free_reaches_goal_in_9_steps():
    env = noise_free_env()
    results = play(env, SCRIPT)
    assert len(results) == 9
    assert results[-1][2] and not results[-1][3]
    assert sum(r[1] for r in results) == pytest.approx(1.0, abs=1e-12)
    assert env.state["player"][0] == 1035.0


def test_scripted_policy_with_noise():
    # Spec §8: the goal in 99.8 % of 500 seeds, mean return 0.998. 100 seeds keep the test fast.
    returns, reached = [], []
    env = PlatformEnv()
    for seed in range(100):
        env.reset(seed=seed)
        returns.append(sum(r[1] for r in play(env, SCRIPT)))
        reached.append(env.state["player"][0] >= 1035.0)
    assert np.mean(reached) >= 0.95 and np.mean(returns) >= 0.98


# Recorded by running the PyPI port `hybrid-platform` 0.1.0 (gym_platform) on SCRIPT with
# numpy.random.RandomState(0) as its noise source (see benchmarks/bench_platform.py, which checks
# hundreds of episodes this way).
REFERENCE_REWARDS = [
    0.10369823135828755, 0.06520048209455667, 0.060728133146570884, 0.24869703498910578,
    0.1020033474387939, 0.04449980051703331, 0.06763285024154589, 0.25223716703702515,
    0.044497615299362164, 0.010805337877718667,
]  # fmt: skip


def test_replays_the_reference_under_random_state():
    substeps = [143, 20, 20, 140, 135, 20, 20, 144, 20, 4]
    last_obs = [1.0, 0.6930000185966492, 0.6750048995018005, 0.002003471367061138]
    env = PlatformEnv()
    env.reset()
    env.np_random = np.random.RandomState(0)
    results = play(env, SCRIPT)
    assert [r[1] for r in results] == REFERENCE_REWARDS
    assert [r[4]["substeps"] for r in results] == substeps
    assert results[-1][0][:4].astype(np.float32).tolist() == last_obs


def test_a_replaced_generator_drops_the_numbers_drawn_ahead():
    # The env draws its normals in blocks; after steps with another generator, assigning RandomState(0)
    # must still replay the reference from RandomState(0)'s first number on.
    env = PlatformEnv()
    env.reset(seed=1)
    play(env, [(0, 30), (1, 300)])
    env.reset()
    env.np_random = np.random.RandomState(0)
    assert [r[1] for r in play(env, SCRIPT)] == REFERENCE_REWARDS


def test_reseeding_restarts_the_stream():
    env = PlatformEnv()
    runs = []
    for _ in range(2):
        env.reset(seed=7)
        runs.append([(r[1], r[4]["substeps"]) for r in play(env, [(0, 20), (1, 500), (2, 300), (0, 10)])])
    assert runs[0] == runs[1]


def test_the_step_refuses_a_buffer_too_short_for_its_longest_step():
    # The env keeps MAX_DRAWS numbers ahead; a step that could run past the buffer's end is an error.
    state, trace = physics.INITIAL_STATE.copy(), np.empty((0, physics.TRACE_SIZE))
    with pytest.raises(ValueError, match="MAX_DRAWS"):
        physics.step(state, 1, 720.0, np.zeros(physics.MAX_DRAWS + 5), 6, trace)
    assert physics.step(state, 1, 720.0, np.zeros(physics.MAX_DRAWS + 5), 5, trace)[2:] == (144, 5 + 2 + 2 * 144)


def test_random_policy_statistics():
    # Spec §8: mean return ~0.154 (std ~0.10), ~2.2 steps per episode, ~72 sub-steps per step.
    env = gymnasium.make("pamdp/Platform-v0")
    env.action_space.seed(0)
    returns, lengths, substeps = [], [], []
    for episode in range(1500):
        env.reset(seed=episode)
        total, done = 0.0, False
        while not done:
            _, r, terminated, truncated, info = env.step(env.action_space.sample())
            total += r
            substeps.append(info["substeps"])
            done = terminated or truncated
        returns.append(total)
        lengths.append(len(substeps) - sum(lengths))
    assert np.mean(returns) == pytest.approx(0.154, abs=0.012)
    assert np.mean(lengths) == pytest.approx(2.2, abs=0.15)
    assert np.mean(substeps) == pytest.approx(72, abs=4)


def test_time_limit_truncates():
    env = gymnasium.make("pamdp/Platform-v0")
    env.reset()
    env.unwrapped.np_random = ZeroNoise()
    results = play(env, SCRIPT[:8] + [(0, 0)] * 300)  # reach platform 3 (no enemy), then stand still
    assert len(results) == 200
    assert results[-1][3] and not results[-1][2]


@pytest.mark.filterwarnings("ignore:.*symmetric and normalized")  # the boxes are in the domain's units
def test_check_env():
    check_env(gymnasium.make("pamdp/Platform-v0", render_mode="rgb_array").unwrapped, skip_render_check=False)


@pytest.mark.parametrize(
    "action, shown",
    [
        (5, "5"),
        ((0, 1, 2), "(0, 1, 2)"),
        ((3, (1.0, 1.0, 1.0)), "3"),
        ((-1, (1.0, 1.0, 1.0)), "-1"),
        ((1.0, (1.0, 1.0, 1.0)), "array([1.])"),  # one action is checked as a batch of one
        ((0, (1.0, 1.0)), "(1.0, 1.0)"),
        ((0, (np.array([1.0, 2.0]), 1.0, 1.0)), "array([[1., 2.]])"),
        ((0, (float("nan"), 1.0, 1.0)), "nan"),
        ((2, (1.0, 1.0, np.array([np.inf], dtype=np.float32))), "inf"),
        ((0, ("fast", 1.0, 1.0)), "'fast'"),
    ],
)
def test_bad_actions_raise(action, shown):
    env = PlatformEnv()
    env.reset()
    assert_refused(env, action, shown, "expected (a, (p_run, p_hop, p_leap))")


@pytest.mark.parametrize("a, p, clipped", [(0, 100.0, 30.0), (0, -5.0, 0.0), (1, 1e6, 720.0), (2, -1.0, 0.0)])
def test_parameters_are_clipped_into_their_box(a, p, clipped):
    out = []
    for value in (p, clipped):
        params = tuple(np.float64(value) if i == a else 1.0 for i in range(3))
        out.append(noise_free_env().step((a, params)))
    np.testing.assert_array_equal(out[0][0], out[1][0])
    assert out[0][1] == out[1][1]


def test_render_shows_the_player_moving():
    env = PlatformEnv(render_mode="rgb_array")
    env.reset(seed=0)

    def player_column(frame):
        blue = (frame[..., 2] > 200) & (frame[..., 0] < 80)
        return np.nonzero(blue)[1].mean()

    before = env.render()
    assert before.shape == (120, 633, 3) and before.dtype == np.uint8
    env.step(act(0, 30))
    assert player_column(env.render()) > player_column(before) + 20  # ~67 px at scale 0.6


def test_render_substeps_draws_every_substep():
    env = PlatformEnv(render_mode="rgb_array")
    env.reset(seed=0)
    assert env.render_substeps() == []
    env.np_random = ZeroNoise()
    _, _, _, _, info = env.step(act(1, 720))  # a hop from rest: 144 sub-steps, up and down again
    frames = env.render_substeps()
    assert len(frames) == info["substeps"] == 144
    np.testing.assert_array_equal(frames[-1], env.render())
    # The player's box rises and falls: its top row (in image rows, y down) is highest mid-flight.
    tops = [np.nonzero((f[..., 2] > 200) & (f[..., 0] < 80))[0].min() for f in frames]
    peak = [k for k, top in enumerate(tops) if top == min(tops)]
    assert peak[0] <= 72 <= peak[-1]  # noise-free, the apex is half-way through the flight
    assert all(np.diff(tops[: peak[0] + 1]) <= 0) and all(np.diff(tops[peak[-1] :]) >= 0)
    assert tops[0] > min(tops) + 30 and tops[-1] > min(tops) + 30  # peak ~63 px above: ~38 px at scale 0.6


def test_episode_gif(tmp_path):
    from PIL import Image

    path, total = save_platform_gif(tmp_path / "platform.gif", seed=0)
    env = PlatformEnv()  # the same episode again, to count its sub-steps
    env.reset(seed=0)
    space = gymnasium.make("pamdp/Platform-v0").action_space
    space.seed(0)
    substeps, done = 0, False
    while not done:
        _, _, terminated, truncated, info = env.step(space.sample())
        substeps += info["substeps"]
        done = terminated or truncated
    with Image.open(path) as gif:
        assert gif.size == (633, 120)
        durations = []  # Pillow merges repeated frames into one of longer duration
        for k in range(gif.n_frames):
            gif.seek(k)
            durations.append(gif.info["duration"])
    assert sum(durations) == (1 + substeps) * 50  # one 50 ms frame per sub-step (dt = 0.05 s), and the start
    assert 0.0 <= total <= 1.0 + 1e-9
