"""The flattening and discretizing action wrappers, checked against the envs' bounds worked out by hand."""

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import pamdp  # noqa: F401  (registers the envs)
from pamdp.wrappers import DiscretizeHybridAction, FlattenHybridAction


def platform():
    return gymnasium.make("pamdp/Platform-v0")


def hfo():
    return gymnasium.make("pamdp/HalfFieldOffense-v0")


def test_flatten_executes_the_argmax_with_its_own_parameters_in_the_domains_units():
    env = FlattenHybridAction(hfo())  # dash (power 0..100, direction -180..180), turn (direction), kick (power, dir)
    assert env.action_space.shape == (3 + 2 + 1 + 2,)
    #                 scores         dash        turn   kick
    v = np.array([0.1, -0.3, 0.9, 0.5, -1.0, 0.25, -0.5, 0.0])
    a, params = env.hybrid_action(v)
    assert a == 2
    np.testing.assert_allclose(params[2], [25.0, 0.0])  # kick: power 0 + (-0.5 + 1) / 2 * 100, direction 0
    a, params = env.hybrid_action(np.array([0.0, 0.7, -0.2, 0.5, -1.0, 0.25, -0.5, 0.0]))
    assert a == 1
    np.testing.assert_allclose(params[1], [45.0])  # turn: -180 + 1.25 / 2 * 360
    a, params = env.hybrid_action(np.array([0.9, 0.7, -0.2, 3.0, -1.0, 0.25, -0.5, 0.0]))
    assert a == 0
    np.testing.assert_allclose(params[0], [100.0, -180.0])  # 3.0 clipped to the high bound
    assert env.action_space.contains(env.action_space.sample())


def test_flatten_steps_the_env_like_the_hybrid_action_it_stands_for():
    flat, plain = FlattenHybridAction(platform()), platform()
    flat.reset(seed=3)
    plain.reset(seed=3)
    rng = np.random.default_rng(0)
    for _ in range(20):
        v = rng.uniform(-1, 1, flat.action_space.shape).astype(np.float32)
        a = int(np.argmax(v[:3]))
        expected = [(15.0, 15.0), (360.0, 360.0), (215.0, 215.0)]  # box centres: the unused actions
        speed = (float(v[3 + a]) + 1) * 0.5 * [30.0, 720.0, 430.0][a]
        out = flat.step(v)
        hybrid = (a, tuple(np.array([speed if b == a else expected[b][0]], np.float32) for b in range(3)))
        ref = plain.step(hybrid)
        np.testing.assert_array_equal(out[0], ref[0])
        assert out[1:4] == ref[1:4]
        if out[2] or out[3]:
            break


def test_discretize_enumerates_every_grid_point_with_both_bounds():
    env = DiscretizeHybridAction(hfo(), bins=3)
    assert env.action_space.n == 3**2 + 3 + 3**2
    decoded = [env.hybrid_action(i) for i in range(env.action_space.n)]
    dash = [tuple(p[0]) for a, p in decoded if a == 0]
    assert dash == [(pw, d) for pw in (0.0, 50.0, 100.0) for d in (-180.0, 0.0, 180.0)]  # last one fastest
    assert [tuple(p[1]) for a, p in decoded if a == 1] == [(-180.0,), (0.0,), (180.0,)]
    assert [a for a, _ in decoded] == [0] * 9 + [1] * 3 + [2] * 9
    centre = DiscretizeHybridAction(platform(), bins=1)
    assert centre.action_space.n == 3
    assert [float(centre.hybrid_action(i)[1][i][0]) for i in range(3)] == [15.0, 360.0, 215.0]


@pytest.mark.filterwarnings("ignore:.*different from the unwrapped version")
def test_wrapped_envs_pass_gymnasiums_checker():
    for env in (FlattenHybridAction(platform()), DiscretizeHybridAction(platform(), bins=4)):
        check_env(env, skip_render_check=True)
        env.reset(seed=0)
        for _ in range(5):
            if any(env.step(env.action_space.sample())[2:4]):
                break


def test_bad_actions_and_settings_are_refused_with_what_was_expected():
    with pytest.raises(ValueError, match=r"bins = 0; expected an integer >= 1"):
        DiscretizeHybridAction(platform(), bins=0)
    with pytest.raises(ValueError, match=r"bins = 2.5; expected an integer >= 1"):
        DiscretizeHybridAction(platform(), bins=2.5)
    env = DiscretizeHybridAction(platform(), bins=2)
    with pytest.raises(ValueError, match=r"action 6; expected an integer in 0..5"):
        env.hybrid_action(6)
    flat = FlattenHybridAction(platform())
    with pytest.raises(ValueError, match=r"action of shape \(5,\); expected \(6,\)"):
        flat.hybrid_action(np.zeros(5))
    with pytest.raises(ValueError, match="non-finite"):
        flat.hybrid_action(np.array([np.nan, 0, 0, 0, 0, 0]))
    with pytest.raises(ValueError, match="unsupported action space Discrete"):
        FlattenHybridAction(gymnasium.make("CartPole-v1"))
