"""The replay buffer (wrap-around, contents, checkpoints) and the shared off-policy loop."""

import time

import numpy as np
import pytest
import torch
from loop_stub import stub_algorithm
from torch import nn

from pamdp.algos.offpolicy import discounted_returns, linear_epsilon, mixed_target, soft_updater
from pamdp.algos.replay import ReplayBuffer
from pamdp.nn.optim import descend

FIELDS = {"obs": ((2,), np.float32), "a": ((), np.int64), "eta": ((3,), np.float32)}


def rows(ids):
    ids = np.asarray(ids)
    return {
        "obs": np.stack([ids, -ids], axis=1).astype(np.float32),
        "a": ids.astype(np.int64),
        "eta": np.repeat(ids[:, None], 3, axis=1).astype(np.float32),
    }


def test_wraps_around_and_keeps_the_newest():
    buf = ReplayBuffer(5, FIELDS)
    np.testing.assert_array_equal(buf.add(**rows([0, 1, 2])), [0, 1, 2])
    assert len(buf) == 3
    np.testing.assert_array_equal(buf.add(**rows([3, 4, 5, 6])), [3, 4, 5, 6])
    assert len(buf) == 5 and buf.added == 7
    # Slots 0 and 1 were overwritten by transitions 5 and 6; 2, 3, 4 are untouched.
    np.testing.assert_array_equal(buf.data["a"], [5, 6, 2, 3, 4])
    np.testing.assert_array_equal(buf.data["obs"][:, 1], [-5, -6, -2, -3, -4])
    np.testing.assert_array_equal(buf.holds(np.arange(7)), [False, False, True, True, True, True, True])
    # A batch longer than the capacity keeps its last `capacity` rows, in ring order.
    buf.add(**rows(range(10, 22)))
    assert buf.added == 19 and sorted(buf.data["a"]) == [17, 18, 19, 20, 21]
    assert buf.data["a"][19 % 5 - 1] == 21


def test_a_batch_with_a_short_field_is_refused_and_writes_nothing():
    buf = ReplayBuffer(2, FIELDS)  # full: a partial write would overwrite live transitions
    buf.add(**rows([0, 1]))
    bad = rows([2, 3])
    bad["eta"] = bad["eta"][:1]
    with pytest.raises(ValueError, match="field 'eta' has 1 rows; expected 2"):
        buf.add(**bad)
    assert buf.added == 2
    np.testing.assert_array_equal(buf.data["a"], [0, 1])
    np.testing.assert_array_equal(buf.data["obs"], [[0, 0], [1, -1]])


def test_write_skips_overwritten_transitions():
    buf = ReplayBuffer(4, {"r": ((), np.float32), "mc": ((), np.float32)})
    first = buf.add(r=np.ones(3), mc=np.full(3, np.nan))
    buf.add(r=np.ones(2), mc=np.full(2, np.nan))  # overwrites transition 0
    buf.write("mc", first, np.array([7.0, 8.0, 9.0]))
    np.testing.assert_array_equal(buf.data["mc"][[1, 2]], [8.0, 9.0])
    assert torch.isnan(buf.data["mc"][0])  # now transition 4's slot: left alone


def test_sampling_returns_stored_rows_from_the_given_rng():
    buf = ReplayBuffer(100, FIELDS)
    buf.add(**rows(range(30)))
    batch = buf.sample(500, np.random.default_rng(0))
    ids = batch["a"].numpy()
    assert set(ids) <= set(range(30)) and len(set(ids)) > 25
    np.testing.assert_array_equal(batch["obs"].numpy(), np.stack([ids, -ids], axis=1))
    np.testing.assert_array_equal(batch["eta"].numpy()[:, 2], ids)
    again = buf.sample(500, np.random.default_rng(0))
    assert torch.equal(again["a"], batch["a"])
    batch["a"][:] = -1  # a sample shares no memory with the buffer
    assert buf.data["a"][:30].min() == 0


def test_sampling_since_a_counter_draws_uniformly_from_the_transitions_added_since():
    buf = ReplayBuffer(8, FIELDS)
    buf.add(**rows(range(12)))  # 0-3 overwritten: 4-11 held, in slots 4-7, 0-3
    ids = buf.sample(20_000, np.random.default_rng(0), first=7)["a"].numpy()
    np.testing.assert_allclose(np.bincount(ids, minlength=12)[7:] / 20_000, [0.2] * 5, atol=0.015)
    assert ids.min() == 7
    ids = buf.sample(20_000, np.random.default_rng(0), first=2)["a"].numpy()  # before the oldest held: all held
    np.testing.assert_allclose(np.bincount(ids, minlength=12)[4:] / 20_000, [0.125] * 8, atol=0.015)
    assert ids.min() == 4
    with pytest.raises(ValueError, match="first = 12: no transition added since it.*expected first < 12"):
        buf.sample(4, np.random.default_rng(0), first=12)


def test_large_capacity_is_cheap_until_filled():
    t = time.perf_counter()
    buf = ReplayBuffer(10_000_000, {"obs": ((9,), np.float32), "next_obs": ((9,), np.float32), "a": ((), np.int64)})
    assert time.perf_counter() - t < 1.0
    buf.add(obs=np.ones((4, 9)), next_obs=np.ones((4, 9)), a=np.arange(4))
    assert len(buf) == 4


def test_state_dict_with_and_without_contents():
    buf = ReplayBuffer(5, FIELDS)
    buf.add(**rows(range(7)))
    full = ReplayBuffer(5, FIELDS)
    full.load_state_dict(buf.state_dict(include_data=True))
    assert full.added == 7
    for name in FIELDS:
        np.testing.assert_array_equal(full.data[name], buf.data[name])
    empty = ReplayBuffer(5, FIELDS)
    empty.load_state_dict(buf.state_dict(include_data=False))
    assert len(empty) == 0


def test_bad_arguments_raise():
    with pytest.raises(ValueError, match="capacity = 0"):
        ReplayBuffer(0, FIELDS)
    buf = ReplayBuffer(5, FIELDS)
    with pytest.raises(ValueError, match="got fields"):
        buf.add(obs=np.zeros((1, 2)))
    with pytest.raises(ValueError, match="empty"):
        buf.sample(2, np.random.default_rng(0))


def test_discounted_returns_by_hand():
    np.testing.assert_allclose(discounted_returns(np.array([1.0, 2.0, 3.0]), 0.5), [1 + 0.5 * 2 + 0.25 * 3, 2 + 1.5, 3])
    np.testing.assert_allclose(discounted_returns(np.array([1.0]), 0.5, tail=4.0), [3.0])


def test_soft_update_is_polyak_averaging():
    target, source = nn.Linear(2, 1), nn.Linear(2, 1)
    before = target.weight.detach().clone()
    soft_updater([(target, source)])(0.25)
    torch.testing.assert_close(target.weight.detach(), 0.75 * before + 0.25 * source.weight.detach())


def test_mixed_target_by_hand_keeps_td_where_the_return_is_unknown():
    y = torch.tensor([1.0, 2.0, 3.0])
    mc = torch.tensor([0.0, float("nan"), 5.0])
    torch.testing.assert_close(mixed_target(y, mc, 0.25), torch.tensor([0.75, 2.0, 3.5]))


def test_linear_epsilon_endpoints():
    assert [linear_epsilon(s, 1.0, 0.1, 100) for s in (0, 50, 100, 10**6)] == pytest.approx([1.0, 0.55, 0.1, 0.1])


@pytest.mark.parametrize("max_norm, expected_norm", [(0.0, 5.0), (1.0, 1.0), (10.0, 5.0)])
def test_descend_clips_the_gradient_norm_before_stepping(max_norm, expected_norm):
    w = nn.Parameter(torch.zeros(2))
    loss = -(w * torch.tensor([3.0, 4.0])).sum()  # gradient norm 5
    norm = descend(torch.optim.SGD([w], lr=1.0), loss, [w], max_norm)
    assert float(w.detach().norm()) == pytest.approx(expected_norm)
    assert norm is None if max_norm == 0 else float(norm) == pytest.approx(5.0)


def test_epoch_stats_average_each_figure_over_the_updates_that_computed_it():
    """A figure computed every third update (a delayed actor step) is the mean of those steps, not diluted."""
    from pamdp.algos.offpolicy import OffPolicyLoop
    from pamdp.algos.paddpg import PADDPGConfig
    from pamdp.envs.backends import make_vector_env
    from pamdp.spaces import HybridActionSpace

    env = make_vector_env("pamdp/Platform-v0", 4)
    hybrid = HybridActionSpace.from_gym(env.single_action_space)
    calls = []

    def act(obs, step, episode_start, mask):
        n = len(obs)
        return torch.zeros(n, dtype=torch.long), torch.zeros(n, hybrid.max_param_size), {}

    def update():
        calls.append(len(calls))
        i = calls[-1]
        return {"every": float(i), **({"third": float(10 * i)} if i % 3 == 0 else {})}

    algo = stub_algorithm(PADDPGConfig(epoch_steps=40, learning_starts=0, buffer_size=1000), env, act, update)
    stats = OffPolicyLoop(algo).run_epoch()
    assert stats["train/updates"] == len(calls) >= 40
    assert stats["every"] == pytest.approx(np.mean(calls))
    assert stats["third"] == pytest.approx(np.mean([10 * i for i in calls if i % 3 == 0]))


def test_reward_scale_scales_what_the_critics_learn_from_and_nothing_the_user_sees():
    """Two loops with the same seeds and the same fixed actions, one at reward_scale 1/50: its stored rewards and
    Monte-Carlo returns are the other's times 1/50, its logged episode returns the same."""
    from pamdp.algos.offpolicy import OffPolicyLoop
    from pamdp.algos.paddpg import PADDPGConfig
    from pamdp.envs.backends import make_vector_env
    from pamdp.spaces import HybridActionSpace

    def run(scale):
        env = make_vector_env("pamdp/Platform-v0", 4)
        hybrid = HybridActionSpace.from_gym(env.single_action_space)

        def act(obs, step, episode_start, mask):  # run right at speed 0.6: episodes of several steps, rewards > 0
            n = len(obs)
            return torch.zeros(n, dtype=torch.long), torch.full((n, hybrid.max_param_size), 0.2), {}

        config = PADDPGConfig(epoch_steps=200, learning_starts=10**6, reward_scale=scale, buffer_size=1000)
        loop = OffPolicyLoop(stub_algorithm(config, env, act, lambda: {}), mc_returns=True)
        stats = loop.run_epoch()
        buffer = loop.buffer
        n = len(buffer)
        return stats, {k: buffer.data[k][:n].numpy() for k in ("reward", "mc")}

    stats1, data1 = run(1.0)
    stats50, data50 = run(1 / 50)
    assert data1["reward"].any() and np.isfinite(data1["mc"]).sum() > 50
    np.testing.assert_allclose(data50["reward"], data1["reward"] / 50, rtol=1e-6)
    finite = np.isfinite(data1["mc"])
    np.testing.assert_array_equal(np.isfinite(data50["mc"]), finite)
    np.testing.assert_allclose(data50["mc"][finite], data1["mc"][finite] / 50, rtol=1e-5)
    assert stats50["charts/episodic_return"] == stats1["charts/episodic_return"] > 0
