"""Hard Move against the recordings of HyAR's original and ``shared/specs/hard_move.md``; the batched env
against the scalar one, with n = 4 to 10 actuators."""

import json

import gymnasium
import numpy as np
import pytest
from domain_replay import DATA, assert_same_step, load_cases, replay
from gymnasium.utils.env_checker import check_env
from gymnasium.vector import SyncVectorEnv
from test_catch_point import check_particle

import pamdp  # noqa: F401  (registers the envs)
import pamdp.envs.particle as particle
from pamdp.envs.hard_move import HardMoveEnv, HardMoveVectorEnv, motion_table
from pamdp.envs.hard_move.motions import actuators
from pamdp.spaces import BoxRows, HybridActionSpace

CASES = load_cases("hard_move_traces.json")
MOTIONS = json.loads((DATA / "hard_move_motions.json").read_text())
unbounded_ok = pytest.mark.filterwarnings("ignore:.*observation space (minimum|maximum) value")


def act(n, a, p):
    """Action ``a`` with parameter ``p``; the other boxes hold an off-range value, which must be ignored."""
    params = [np.array([9.0], np.float32)] * 2**n
    params[a] = np.array([p], np.float32)
    return a, tuple(params)


def homing(obs, motions):
    """The action whose motion points most nearly at the target, at full push."""
    return int(np.argmax(motions @ obs[2:])), 1.0


# --- the original, replayed -------------------------------------------------------------------------
@pytest.mark.parametrize("case", CASES, ids=[f"n{c['env_kwargs']['n']}-{c['seed']}" for c in CASES])
def test_replays_the_recordings_of_the_original(case):
    identical, records = replay(case, check_particle)
    print(f"hard move n={case['env_kwargs']['n']} {case['seed']}: {identical} of {records} records bit-identical")
    assert records == len(case["trace"]) - 1


@pytest.mark.parametrize("n", [4, 6, 8, 10])
def test_the_motion_table_is_the_originals_to_the_bit(n):
    table = motion_table(n)
    recorded = np.array(MOTIONS["motions"][str(n)])
    assert table.tobytes() == recorded.tobytes()  # signs of zeros included
    np.testing.assert_array_equal(actuators(n), MOTIONS["movement"][str(n)])
    # A plain left-to-right sum, as the spec warns, is not the original's table at n = 8 and 10.
    bits = ((np.arange(2**n)[:, None] >> (n - 1 - np.arange(n))) & 1).astype(float)
    plain = np.zeros((2**n, 2))
    for k in range(n):
        plain += bits[:, k : k + 1] * actuators(n)[k]
    norm = np.linalg.norm(plain, axis=1).max()
    assert norm == MOTIONS["max_norm"][str(n)]
    assert (np.count_nonzero(plain / norm != recorded) > 0) == (n >= 8)


def test_the_specs_worked_numbers():
    # Bit order: the most significant bit is actuator 0; single actuators push with 1 / D.
    m = motion_table(4)
    assert m[8].tolist() == [0.7071067811865475, 0.0] and m[1].tolist() == [0.0, -0.7071067811865475]
    assert m[0].tolist() == [0.0, 0.0] and not m[0b1010].any() and not m[0b1111].any()  # cancelling patterns
    for n, d in ((6, 2.0), (8, 2.6129286251254547), (10, 3.236368953008912)):
        assert np.linalg.norm(motion_table(n), axis=1).max() == pytest.approx(1.0, abs=1e-15)
        assert motion_table(n)[2 ** (n - 1)].tolist() == [1.0 / d, 0.0]
    env = gymnasium.make("pamdp/HardMove-v0", n=6)
    env.reset(seed=0)
    env.unwrapped.np_random = np.random.RandomState(0)
    assert env.reset()[0].tolist() == [0.0, 0.0, 0.10789974428863824, -0.3406123667510452]


def test_the_parameter_is_not_clipped_and_arrival_ends_the_episode():
    env = HardMoveEnv(n=8)
    env.reset(seed=1)
    a, p = 0b01000001, np.float32(-3.5)  # actuators 1 and 7, pushed backwards three and a half times
    start = env.state
    obs, reward, terminated, truncated, info = env.step(act(8, a, p))
    m = motion_table(8)[a]
    v = np.array([(0.0 + (m[0] * p) * 2.0) * 0.1, (0.0 + (m[1] * p) * 2.0) * 0.1])
    pos = start[[particle.AX, particle.AY]] + v * 0.1
    d = pos - start[[particle.GX, particle.GY]]
    assert obs.tolist() == [*v, *(-d)] and reward == -(d[0] * d[0] + d[1] * d[1])
    # Place the target 0.2 ahead: arrival (with <= against 0.2 ** 2) ends the episode, rewarding 20 - d2.
    env._states[0, [particle.GX, particle.GY]] = env.state[[particle.AX, particle.AY]] + [0.0, 0.2]
    env._states[0, [particle.VX, particle.VY]] = 0.0
    obs, reward, terminated, truncated, info = env.step(act(8, 0, 0.0))  # all actuators off
    assert (terminated, info) == (True, {"is_success": True}) and reward == pytest.approx(19.96, abs=1e-15)


def test_the_time_limit_truncates_at_30_steps():
    env = gymnasium.make("pamdp/HardMove-v0", n=4)
    env.reset(seed=0)
    flags = [env.step(act(4, 0, 0.0))[2:4] for _ in range(30)]
    assert flags == [(False, False)] * 29 + [(False, True)]
    venv = gymnasium.make_vec("pamdp/HardMove-v0", num_envs=2, vectorization_mode="vector_entry_point")
    assert venv.max_episode_steps == 30


# --- the Gymnasium API ----------------------------------------------------------------------------------
@unbounded_ok
@pytest.mark.parametrize("n", [4, 10])
def test_passes_gymnasiums_env_checker_and_its_spaces_are_the_specs(n):
    env = HardMoveEnv(n=n)
    check_env(env, skip_render_check=True)
    space = HybridActionSpace.from_gym(env.action_space)
    assert space.n_actions == 2**n and space.param_sizes == (1,) * 2**n
    assert all(lo.tolist() == [-1.0] and hi.tolist() == [1.0] for lo, hi in zip(space.lows, space.highs))
    assert env.observation_space == gymnasium.spaces.Box(-np.inf, np.inf, (4,), np.float64)


@pytest.mark.parametrize("n", [5, 0, 12, True, 4.0, "4"])
def test_bad_actuator_counts_are_refused(n):
    # a value of another type than n's int is refused by the shell, one of the wrong size by Hard Move
    expected = r"expected one of \(4, 6, 8, 10\) actuators|argument n=.*; expected int"
    with pytest.raises(ValueError, match=expected):
        HardMoveEnv(n=n)
    with pytest.raises(ValueError, match=expected):
        gymnasium.make_vec("pamdp/HardMove-v0", num_envs=2, vectorization_mode="vector_entry_point", n=n)


@pytest.mark.parametrize(
    "action, match",
    [
        ((16, (np.zeros(1),) * 16), r"discrete actions \[16\] at indices \[0\]"),
        ((3, (np.zeros(1),) * 15), r"invalid parameters \(15 boxes\)"),
        (
            (3, (np.zeros(1),) * 3 + (np.array([np.nan]),) + (np.zeros(1),) * 12),
            r"parameter 3 contains \[nan\]; expected .* each p a finite array",
        ),
        ((3, (np.zeros(2),) * 16), r"the chosen parameters have shapes \[\(1, 2\)\]"),
    ],
)
def test_bad_actions_are_refused(action, match):
    env = HardMoveEnv(n=4)
    env.reset(seed=0)
    with pytest.raises(ValueError, match=match):
        env.step(action)


# --- the batched env ------------------------------------------------------------------------------------
@pytest.mark.parametrize("n_actuators, copies, seed, limit", [(4, 1, 0, 30), (6, 5, 7, 30), (10, 4, 21, 12)])
def test_copy_i_equals_a_scalar_env_seeded_with_seed_plus_i(n_actuators, copies, seed, limit):
    # (At n = 10 a shorter time limit, so that both endings come soon: stepping 1024 boxes costs.)
    kwargs = {"n": n_actuators, "max_episode_steps": limit}
    venv = gymnasium.make_vec("pamdp/HardMove-v0", num_envs=copies, vectorization_mode="vector_entry_point", **kwargs)
    assert isinstance(venv, HardMoveVectorEnv) and venv.max_episode_steps == limit
    ref = SyncVectorEnv([lambda: gymnasium.make("pamdp/HardMove-v0", **kwargs) for _ in range(copies)])
    got, want = venv.reset(seed=seed), ref.reset(seed=seed)
    np.testing.assert_array_equal(got[0], want[0])
    motions, rng, ended = motion_table(n_actuators), np.random.default_rng(seed), np.zeros(2, dtype=int)
    k = 2**n_actuators
    for t in range(3 * limit):
        a = rng.integers(0, k, copies)
        p = rng.uniform(-1.5, 1.5, copies)
        for i in range(0, copies, 2):  # even copies home in on the target, so episodes end both ways
            a[i], p[i] = homing(got[0][i], motions)
        params = np.tile(rng.uniform(-1, 1, (1, copies, 1)), (k, 1, 1)).astype(np.float32)
        params[a, np.arange(copies), 0] = p
        batch = (a, tuple(params))
        got, want = venv.step(batch), ref.step(batch)
        assert_same_step(got, want, f"step {t}")
        np.testing.assert_array_equal(venv.unwrapped.states, [e.unwrapped.state for e in ref.envs])
        ended += got[2].sum(), (got[3] & ~got[2]).sum()
    assert ended.all()  # reached and timed out: autoresets after both compared


def test_stacked_parameters_read_as_the_tuple_of_boxes():
    venv_tuple, venv_stacked = HardMoveVectorEnv(num_envs=64, n=10), HardMoveVectorEnv(num_envs=64, n=10)
    venv_tuple.reset(seed=3)
    venv_stacked.reset(seed=3)
    rng = np.random.default_rng(0)
    for _ in range(40):
        a = rng.integers(0, 1024, 64)
        params = rng.uniform(-1, 1, (1024, 64, 1)).astype(np.float32)
        got, want = venv_stacked.step((a, params)), venv_tuple.step((a, tuple(params[:, :, 0])))
        assert_same_step(got, want, "stacked", keys=())


def test_the_algorithms_rows_of_one_block_read_as_their_tuple_and_a_nan_in_any_row_is_refused():
    """``HybridActionSpace.to_env_batch`` hands Hard Move's boxes as rows of one array (``BoxRows``), which the env
    checks in one pass: the same steps as the rows handed as a plain tuple, the same refusal of a NaN no copy chose."""
    space = HybridActionSpace.from_gym(HardMoveEnv(n=10).action_space)
    venv_rows, venv_tuple = HardMoveVectorEnv(num_envs=16, n=10), HardMoveVectorEnv(num_envs=16, n=10)
    venv_rows.reset(seed=4)
    venv_tuple.reset(seed=4)
    rng = np.random.default_rng(1)
    for _ in range(30):
        a, params = space.to_env_batch(rng.integers(0, 1024, 16), rng.uniform(-1, 1, (16, 1)))
        assert isinstance(params, BoxRows)
        assert_same_step(venv_rows.step((a, params)), venv_tuple.step((a, tuple(params))), "rows", keys=())
    params.block[int(np.setdiff1d(np.arange(1024), a)[0]), 3] = np.nan
    for venv, given in ((venv_rows, params), (venv_tuple, tuple(params))):
        with pytest.raises(ValueError, match=r"contains \[nan\]; expected"):
            venv.step((a, given))


@pytest.mark.parametrize(
    "n, bad_shape, bad_list",  # n = 4 stacks its 16 boxes, n = 10 takes each copy's own of 1024
    [
        (4, "the parameter boxes differ in shape", "the parameter boxes differ in shape"),
        (10, r"the chosen parameters have shapes \[\(2, 2\)\]", "the chosen parameters are not all arrays"),
    ],
)
def test_batched_actions_are_checked(n, bad_shape, bad_list):
    venv = HardMoveVectorEnv(num_envs=2, n=n)
    venv.reset(seed=0)
    k = 2**n
    boxes = [np.zeros((2, 1), np.float32)] * k
    with pytest.raises(ValueError, match=rf"discrete actions \[{k}\] at indices \[1\]"):
        venv.step((np.array([0, k]), tuple(boxes)))
    before = venv.states
    for chosen in ([0, 5], [0, 1]):  # the box with an infinity chosen by copy 1, and chosen by none
        bad = boxes[:5] + [np.array([[0.0], [np.inf]], np.float32)] + boxes[6:]
        for params in (tuple(bad), np.stack(bad)):
            with pytest.raises(ValueError, match=r"parameter 5 contains \[inf\]; expected .* finite"):
                venv.step((np.array(chosen), params))
    np.testing.assert_array_equal(venv.states, before)  # checked before any copy moves
    with pytest.raises(ValueError, match=bad_shape):
        venv.step((np.array([5, 5]), tuple(boxes[:5] + [np.zeros((2, 2))] + boxes[6:])))
    with pytest.raises(ValueError, match=bad_list):
        venv.step((np.array([5, 5]), tuple(boxes[:5] + [[0.0, 0.0, 0.0]] + boxes[6:])))
    with pytest.raises(ValueError, match=rf"invalid parameters \({k - 1} boxes\)"):
        venv.step((np.array([5, 5]), tuple(boxes[1:])))
    with pytest.raises(ValueError, match=rf"parameters stacked to shape \({k}, 3, 1\)"):
        venv.step((np.array([5, 5]), np.zeros((k, 3, 1))))


# --- pictures -------------------------------------------------------------------------------------------
def test_frames_show_the_target_the_agent_and_the_actuators_switched_on():
    env = HardMoveEnv(n=4, render_mode="rgb_array")
    env.reset(seed=5)
    env.step(act(4, 0b1000, 1.0))  # actuator 0 alone: +x
    env._states[0, [particle.VX, particle.VY]] = 0.0  # (the velocity's line would cover the spoke)
    frame = env.render()
    assert frame.shape == (particle.RENDER_SIZE, particle.RENDER_SIZE, 3) and frame.dtype == np.uint8
    s = env.state
    gx, gy = particle.to_pixels(s[particle.GX], s[particle.GY])
    assert tuple(frame[int(gy), int(gx)]) == (40, 160, 60)
    x, y = particle.to_pixels(s[particle.AX] + 0.2, s[particle.AY])  # on the spoke of actuator 0
    assert tuple(frame[int(round(y)), int(round(x))]) == (240, 140, 20)
    venv = HardMoveVectorEnv(num_envs=2, n=4, render_mode="rgb_array")
    venv.reset(seed=5)
    venv.step((np.array([0b1000, 0]), (np.ones((2, 1), np.float32),) * 16))
    venv._states[:, [particle.VX, particle.VY]] = 0.0
    np.testing.assert_array_equal(venv.render()[0], frame)
