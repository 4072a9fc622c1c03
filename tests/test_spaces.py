import numpy as np
import pytest
from gymnasium import spaces

from pamdp.spaces import HybridActionSpace


def hfo_like():
    return spaces.Tuple(
        (
            spaces.Discrete(3),
            spaces.Tuple(
                (
                    spaces.Box(np.array([0.0, -180.0], np.float32), np.array([100.0, 180.0], np.float32)),
                    spaces.Box(-180.0, 180.0, (1,), np.float32),
                    spaces.Box(np.array([0.0, -180.0], np.float32), np.array([100.0, 180.0], np.float32)),
                )
            ),
        )
    )


def test_shapes_and_mask():
    hs = HybridActionSpace.from_gym(hfo_like())
    assert hs.n_actions == 3
    assert hs.param_sizes == (2, 1, 2)
    assert hs.max_param_size == 2 and hs.total_param_size == 5
    np.testing.assert_array_equal(hs.param_mask, [[True, True], [True, False], [True, True]])


def test_scale_round_trip_and_endpoints():
    hs = HybridActionSpace.from_gym(hfo_like())
    np.testing.assert_allclose(hs.scale(0, [-1.0, 1.0]), [0.0, 180.0])
    np.testing.assert_allclose(hs.scale(0, [0.0, 0.0]), [50.0, 0.0])
    rng = np.random.default_rng(0)
    a = rng.integers(0, 3, size=100)
    x = rng.uniform(-1, 1, size=(100, 2))
    np.testing.assert_allclose(hs.unscale(a, hs.scale(a, x)), x, atol=1e-12)
    # Values outside [-1, 1] are clipped into the box.
    np.testing.assert_allclose(hs.scale(1, [5.0, 0.0])[0], 180.0)


def test_to_env_is_accepted_by_the_gym_space_and_inverts():
    space = hfo_like()
    hs = HybridActionSpace.from_gym(space)
    action = hs.to_env(2, np.array([0.5, -0.5]))
    assert space.contains(action)
    np.testing.assert_allclose(action[1][2], [75.0, -90.0])
    a, x = hs.from_env(action)
    assert a == 2
    np.testing.assert_allclose(x, [0.5, -0.5], atol=1e-6)
    a, x = hs.from_env(hs.to_env(1, np.array([0.25, 0.9])))
    assert a == 1 and x[1] == 0.0
    np.testing.assert_allclose(x[0], 0.25, atol=1e-6)


def test_to_env_batch_matches_scalar():
    hs = HybridActionSpace.from_gym(hfo_like())
    a = np.array([0, 1, 2, 1])
    x = np.array([[0.1, 0.2], [-0.3, 0.4], [0.5, -0.6], [1.0, 1.0]])
    ba, bp = hs.to_env_batch(a, x)
    for i in range(4):
        sa, sp = hs.to_env(a[i], x[i])
        assert ba[i] == sa
        for k in range(3):
            np.testing.assert_array_equal(bp[k][i], sp[k])


def test_to_env_batch_of_many_equal_boxes_matches_scalar():
    """Hard Move's shape (2^n boxes of one parameter, each with its own bounds) takes the one-block path."""
    rng = np.random.default_rng(0)
    lows = rng.uniform(-3, 0, size=16)
    boxes = tuple(spaces.Box(np.float32(lo), np.float32(lo + 1 + k), (1,), np.float32) for k, lo in enumerate(lows))
    hs = HybridActionSpace.from_gym(spaces.Tuple((spaces.Discrete(16), spaces.Tuple(boxes))))
    a = rng.integers(16, size=50)
    x = rng.uniform(-1.2, 1.2, size=(50, 1))
    ba, bp = hs.to_env_batch(a, x)
    assert len(bp) == 16 and all(p.shape == (50, 1) and p.dtype == np.float32 for p in bp)
    for i in range(50):
        sa, sp = hs.to_env(a[i], x[i])
        assert ba[i] == sa
        for k in range(16):
            np.testing.assert_array_equal(bp[k][i], sp[k])


@pytest.mark.parametrize(
    "space",
    [
        spaces.Discrete(3),
        spaces.Tuple((spaces.Discrete(2), spaces.Tuple((spaces.Box(0, 1, (1,)),)))),
        spaces.Tuple((spaces.Discrete(1), spaces.Tuple((spaces.Box(-np.inf, np.inf, (1,)),)))),
    ],
)
def test_unsupported_spaces_raise_a_clear_error(space):
    with pytest.raises(ValueError, match="expected|finite"):
        HybridActionSpace.from_gym(space)


def test_out_of_range_action_is_named():
    hs = HybridActionSpace.from_gym(hfo_like())
    with pytest.raises(ValueError, match="discrete action 3 out of range"):
        hs.to_env(3, np.zeros(2))
