"""The batched envs' shared machinery (``envs/vector.py``): per-copy random streams, and copying a batched env."""

import copy
import pickle

import gymnasium
import numpy as np
import pytest
from gymnasium.utils import seeding

import pamdp  # noqa: F401  (registers the envs)
from pamdp.envs.streams import RandomStreams, copy_seeds

GENERATORS = {"Generator": lambda s: np.random.default_rng(s), "RandomState": lambda s: np.random.RandomState(s)}


@pytest.mark.parametrize("kind", GENERATORS)
@pytest.mark.parametrize("draw", ["standard_normal", "random"])
def test_a_copy_consumes_exactly_its_generators_stream(kind, draw):
    # Consumers take 0..need numbers per round, the buffer refilled in blocks in between; what they read,
    # copy by copy, must be the copy's generator's numbers drawn one at a time.
    need, n = 9, 3
    streams = RandomStreams(n, draw, capacity=20)
    for i in range(n):
        streams.set(i, GENERATORS[kind](7 + i))
    rng = np.random.default_rng(0)
    got = [[] for _ in range(n)]
    for _ in range(200):
        streams.refill(need)
        for i in range(n):
            k, c = int(rng.integers(0, need + 1)), int(streams.cursors[i])
            got[i].extend(streams.buffers[i, c : c + k])
            streams.cursors[i] += k
    for i in range(n):
        one_by_one = GENERATORS[kind](7 + i)
        assert got[i] == [getattr(one_by_one, draw)() for _ in range(len(got[i]))]


def test_seeding_follows_gymnasium_and_a_replaced_generator_drops_the_buffer():
    streams = RandomStreams(2, "standard_normal", capacity=8)
    streams.seed(5)
    streams.refill(8)
    want = [seeding.np_random(5 + i)[0].standard_normal(8) for i in range(2)]
    np.testing.assert_array_equal(streams.buffers, want)
    first = streams.generators[0]
    streams.follow(0, first)  # the same generator: the numbers drawn ahead stay
    streams.refill(1)
    np.testing.assert_array_equal(streams.buffers[0], want[0])
    streams.follow(0, np.random.RandomState(1))
    streams.refill(1)
    np.testing.assert_array_equal(streams.buffers[0], np.random.RandomState(1).standard_normal(8))
    streams.seed([None, 3])  # None keeps copy 0's generator
    assert streams.generators[0] is not first and isinstance(streams.generators[0], np.random.RandomState)


def test_copy_seeds_and_bad_arguments():
    assert copy_seeds(4, 3) == [4, 5, 6]
    assert copy_seeds([1, None, np.int64(2)], 3) == [1, None, 2]
    for bad in (2.0, [1, 2], "1", False):
        with pytest.raises(ValueError, match="expected None, an int, or a list of 3 ints"):
            copy_seeds(bad, 3)
    with pytest.raises(ValueError, match="draw='gauss'"):
        RandomStreams(1, "gauss", 4)
    with pytest.raises(ValueError, match="exceed the capacity 4"):
        RandomStreams(1, "random", 4).refill(5)


@pytest.mark.parametrize("env_id", ["pamdp/Platform-v0", "pamdp/HalfFieldOffense-v0"])
def test_a_copied_batched_env_goes_on_as_the_original(env_id):
    # The copies' generators and the numbers drawn ahead travel with the env.
    env = gymnasium.make_vec(env_id, num_envs=3, vectorization_mode="vector_entry_point")
    env.reset(seed=1)
    env.action_space.seed(0)
    for _ in range(5):
        env.step(env.action_space.sample())
    copies = [copy.deepcopy(env), pickle.loads(pickle.dumps(env))]
    for _ in range(60):
        action = env.action_space.sample()
        obs, reward, *_ = env.step(action)
        for other in copies:
            obs2, reward2, *_ = other.step(action)
            np.testing.assert_array_equal(obs2, obs)
            np.testing.assert_array_equal(reward2, reward)
