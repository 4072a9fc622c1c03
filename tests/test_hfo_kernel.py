"""The batched HFO env's Numba backend (``hfo_kernel.py``) against its NumPy backend, the reference."""

import numpy as np
import pytest

from pamdp.envs.hfo_baseline import scripted_scorer_batch
from pamdp.envs.hfo_vector import HalfFieldOffenseVectorEnv


def _mixed_actions(obs, rng):
    """The scripted scorer's actions (kicks, goals, hence autoresets) with a third of the games replaced by
    random actions whose parameters overshoot the action space (backward dashes, clipped turns and kicks)."""
    a, (dash, turn, kick) = scripted_scorer_batch(obs)
    a = np.array(a)
    dash, turn, kick = (np.array(p, dtype=np.float64) for p in (dash, turn, kick))
    n = a.shape[0]
    i = np.flatnonzero(rng.random(n) < 1 / 3)
    a[i] = rng.integers(0, 3, i.size)
    dash[i] = rng.uniform(-150.0, 150.0, (i.size, 2))
    turn[i] = rng.uniform(-200.0, 200.0, (i.size, 1))
    kick[i] = rng.uniform(-20.0, 150.0, (i.size, 2))
    return a, (dash, turn, kick)


@pytest.mark.parametrize(
    "kwargs",
    [
        {},
        {"deterministic": True},
        {"body_reset": "uniform"},
        {"profile": "hfo2016", "deterministic": True, "body_reset": "uniform"},
        {"profile": "hfo2019", "timeout_terminal": True, "first_step_reward": True, "terminal_deltas": True},
    ],
)
def test_numba_backend_equals_numpy_step_for_step(kwargs):
    pytest.importorskip("numba")
    n, steps = 64, 300
    envs = [HalfFieldOffenseVectorEnv(num_envs=n, backend=backend, **kwargs) for backend in ("numpy", "numba")]
    results = [env.reset(seed=7) for env in envs]
    rng = np.random.default_rng(0)
    ended = kicks = 0
    for t in range(steps):
        actions = _mixed_actions(results[0][0], rng)
        kicks += np.count_nonzero((actions[0] == 2) & envs[0]._kickable)
        results = [env.step(actions) for env in envs]
        (obs, reward, terminated, truncated, info), (obs_k, reward_k, terminated_k, truncated_k, info_k) = results
        assert obs_k.dtype == np.float32
        np.testing.assert_array_equal(obs_k, obs, err_msg=f"step {t}")
        np.testing.assert_array_equal(reward_k, reward, err_msg=f"step {t}")
        np.testing.assert_array_equal(terminated_k, terminated, err_msg=f"step {t}")
        np.testing.assert_array_equal(truncated_k, truncated, err_msg=f"step {t}")
        np.testing.assert_array_equal(info_k["status"], info["status"], err_msg=f"step {t}")
        np.testing.assert_array_equal(info_k["step"], info["step"], err_msg=f"step {t}")
        ended += np.count_nonzero(terminated | truncated)
    for name in ("_state", "seen", "effort", "recovery", "capacity", "untouched", "cycles", "holder", "bonus_paid"):
        np.testing.assert_array_equal(getattr(envs[1], name), getattr(envs[0], name), err_msg=name)
    # the same draws from the same generator: the streams end in the same state
    assert envs[1].np_random.bit_generator.state == envs[0].np_random.bit_generator.state
    assert ended > n and kicks > n  # several episodes per game, and kicks: the test covers autoresets and kicks


def test_numba_backend_after_reset_with_options():
    pytest.importorskip("numba")
    n = 8
    options = {"ball": (30.0, 5.0), "player": np.tile((29.8, 5.0), (n, 1)), "body": np.linspace(-170, 170, n)}
    envs = [HalfFieldOffenseVectorEnv(num_envs=n, backend=backend) for backend in ("numpy", "numba")]
    results = [env.reset(seed=1, options=options) for env in envs]
    rng = np.random.default_rng(1)
    for _ in range(50):
        actions = _mixed_actions(results[0][0], rng)
        results = [env.step(actions) for env in envs]
        np.testing.assert_array_equal(results[1][0], results[0][0])
        np.testing.assert_array_equal(results[1][1], results[0][1])


def test_numba_backend_draws_alike_when_player_and_ball_coincide():
    """The rare draws between the kernels: a random direction to push apart a player and ball that end a
    cycle on the same spot, or that a placement puts there."""
    hfo_kernel = pytest.importorskip("pamdp.envs.hfo_kernel")
    envs = [HalfFieldOffenseVectorEnv(num_envs=4, backend=b, deterministic=True) for b in ("numpy", "numba")]
    for env in envs:
        env.reset(seed=2)
        # game 1's player runs onto the ball at rest: (9, 0) + (1, 0) = (10, 0)
        env.px[1], env.py[1], env.pvx[1], env.pvy[1] = 9.0, 0.0, 1.0, 0.0
        env.bx[1], env.by[1], env.bvx[1], env.bvy[1] = 10.0, 0.0, 0.0, 0.0
    turn_in_place = (np.ones(4, dtype=np.int64), (np.zeros((4, 2)), np.zeros((4, 1)), np.zeros((4, 2))))
    results = [env.step(turn_in_place) for env in envs]
    np.testing.assert_array_equal(results[1][0], results[0][0])
    np.testing.assert_array_equal(envs[1]._state, envs[0]._state)
    assert envs[1].np_random.bit_generator.state == envs[0].np_random.bit_generator.state
    assert envs[0].collided_ball[1] and envs[0].px[1] != envs[0].bx[1]
    # a placement can put them on one spot only with draws of exactly 0: ball at y = -27.2, the player
    # 0 in x and clipped to the same y from 21 m below
    u = np.array([[0.5, 0.0, 0.5, 0.0, 0.0]])
    assert hfo_kernel.placements_coincide(u)
    assert not hfo_kernel.placements_coincide(np.random.default_rng(0).random((1000, 5)))
