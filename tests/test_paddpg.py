"""PADDPG: bounded-output gradients by hand, the action mapping, exploration, MC targets (save/load and the CLI as
every algorithm: test_algorithms)."""

import dataclasses

import numpy as np
import pytest
import torch
from conftest import HYBRID, OFF_POLICY_SMALL, module_bytes

from pamdp import PADDPG
from pamdp.algos.offpolicy import invert_gradients, zero_gradients
from pamdp.algos.paddpg import PADDPGConfig
from pamdp.policies import DeterministicActor, TwinQ

SMALL = PADDPGConfig(hidden_sizes=(16, 16), epsilon_steps=300, **OFF_POLICY_SMALL)


def test_inverting_gradients_by_hand():
    p = torch.tensor([0.5, 0.5, -1.0, 1.0, 0.0, 1.2, -1.0, -0.6])
    g = torch.tensor([2.0, -2.0, -3.0, 3.0, 4.0, 1.0, 3.0, 1.0])
    expected = [
        2.0 * (1 - 0.5) / 2,  # increasing: scaled by (p_max - p) / (p_max - p_min)
        -2.0 * (0.5 + 1) / 2,  # decreasing: scaled by (p - p_min) / (p_max - p_min)
        0.0,  # at the lower bound, pushing down: stopped
        0.0,  # at the upper bound, pushing up: stopped
        2.0,  # in the middle: halved either way
        -0.1,  # past the upper bound, pushing up: inverted, (1 - 1.2) / 2 = -0.1
        3.0,  # at the lower bound, pushing up (inwards): untouched
        1.0 * (1 + 0.6) / 2,
    ]
    torch.testing.assert_close(invert_gradients(g, p), torch.tensor(expected))
    # Other bounds: [0, 4], p = 3, increasing by 2 -> 2 * (4 - 3) / 4.
    assert invert_gradients(torch.tensor([2.0]), torch.tensor([3.0]), 0.0, 4.0).item() == pytest.approx(0.5)


def test_zeroing_gradients_by_hand():
    p = torch.tensor([1.0, 1.0, -1.0, 0.3, 1.5, -1.2])
    g = torch.tensor([1.0, -1.0, -1.0, 5.0, -2.0, 0.5])
    # Only components pushing an output at or past a bound further out are zeroed; the rest is untouched.
    torch.testing.assert_close(zero_gradients(g, p), torch.tensor([0.0, -1.0, 0.0, 5.0, -2.0, 0.5]))


# Not "zero": it only removes the gradient at the bound, and Adam's momentum carries the outputs well past
# it, which is why Hausknecht & Stone found zeroing unreliable.
@pytest.mark.parametrize("bound", ["invert", "squash"])
def test_actor_chasing_an_unbounded_critic_stays_in_bounds(bound):
    cfg = dataclasses.replace(SMALL, bound=bound, actor_lr=3e-2, grad_clip=0.0, learning_starts=10**6)
    model = PADDPG("pamdp/Platform-v0", cfg)
    with pytest.warns(UserWarning, match="makes no gradient update"):  # replay only, as meant
        model.learn(100, progress_bar=False)

    def greedy():  # a critic that wants every output as large as possible: Q = 10 * sum(out), no hidden layer
        critic = TwinQ(model.obs_dim + model.out_size, 1, (), "relu", twin=False)
        with torch.no_grad():
            critic.q1[0].weight.copy_(torch.cat([torch.zeros(model.obs_dim), torch.full((model.out_size,), 10.0)]))
            critic.q1[0].bias.zero_()
        return critic

    model.critic, model.critic_target = greedy(), greedy().requires_grad_(False)
    model.critic_optimizer = torch.optim.SGD(model.critic.parameters(), lr=0.0)
    model._bind_networks()
    for _ in range(200):
        model._update()
    with torch.no_grad():
        out = model.actor(model.replay.data["obs"][:100])
    assert out.mean() > 0.9, bound  # pushed up to the bound...
    assert out.max() <= (1.0 if bound == "squash" else 1.05), bound  # ...and not (much) past it


def test_only_squash_keeps_outputs_of_large_weights_in_bounds():
    torch.manual_seed(0)
    obs = torch.randn(100, 4)
    for squash in (True, False):
        actor = DeterministicActor(4, 3 + 4, (8,), "relu", squash, HYBRID, offset=3)
        for p in actor.parameters():
            p.data.mul_(100)
        assert (actor(obs).abs().max() <= 1.0) == squash


def test_executed_action_is_the_argmax_with_its_own_parameters():
    actor = DeterministicActor(4, 3 + 4, (8,), "relu", False, HYBRID, offset=3)
    # Scores for 3 actions, then parameters: action 0 -> [p0], action 1 -> [p1, p2], action 2 -> [p3].
    out = torch.tensor(
        [
            [0.9, 0.1, 0.0, 0.5, -0.2, 0.3, 0.7],
            [0.0, 0.8, 0.1, 0.5, -0.2, 0.3, 0.7],
            [0.0, 0.1, 0.2, 0.5, -0.2, 1.4, 0.7],
        ]
    )
    a, x = actor.action(out)
    np.testing.assert_array_equal(a, [0, 1, 2])
    torch.testing.assert_close(x, torch.tensor([[0.5, 0.0], [-0.2, 0.3], [0.7, 0.0]]))


def test_epsilon_is_annealed_linearly():
    model = PADDPG("pamdp/Platform-v0", dataclasses.replace(SMALL, epsilon_steps=1000))
    assert model.epsilon(0) == 1.0
    assert model.epsilon(500) == pytest.approx(0.55)
    assert model.epsilon(10**6) == pytest.approx(0.1)


def test_epoch_stores_monte_carlo_returns_and_explores():
    model = PADDPG("pamdp/Platform-v0", dataclasses.replace(SMALL, ou_sigma=0.2))
    stats = []
    model.learn(400, progress_bar=False, callback=lambda m, s: stats.append(s))
    n = len(model.replay)
    assert n == model.num_timesteps
    r, mc, term = (model.replay.data[k][:n].numpy() for k in ("reward", "mc", "terminated"))
    # The last step of a terminated episode has return-to-go = its reward; most episodes have ended.
    np.testing.assert_allclose(mc[term], r[term], rtol=1e-6)
    assert np.isfinite(mc).mean() > 0.9
    assert np.all(mc[np.isfinite(mc)] >= r[np.isfinite(mc)] - 1e-6)  # Platform's rewards are non-negative
    out = model.replay.data["out"][:n].numpy()
    assert np.abs(out).max() <= 1.0
    np.testing.assert_array_equal(out[:, :3].argmax(1), model.replay.data["a"][:n].numpy())
    assert stats[-1]["train/updates"] > 0 and stats[-1]["train/epsilon"] < 1.0
    for key in ("losses/critic_loss", "losses/actor_loss", "train/q_mean", "train/action_freq_0"):
        assert np.isfinite(stats[-1][key]), key


def test_beta_zero_stores_no_returns_and_learns_from_the_pure_td_target():
    model = PADDPG("pamdp/Platform-v0", dataclasses.replace(SMALL, beta=0.0, learning_starts=10**6))
    with pytest.warns(UserWarning, match="makes no gradient update"):  # replay only, as meant
        model.learn(200, progress_bar=False)
    assert "mc" not in model.replay.data and len(model.replay) >= 200
    batch = model.replay.sample(16, np.random.default_rng(0))
    model.replay.sample = lambda n, rng: batch
    with torch.no_grad():
        q = model.critic.smaller(batch["obs"], batch["out"]).squeeze(-1)
        s2 = batch["next_obs"]
        y = batch["reward"] + 0.99 * (~batch["terminated"]).float() * model.critic_target.smaller(
            s2, model.actor_target(s2).clamp(-1, 1)
        ).squeeze(-1)
    stats = model._update()
    assert stats["losses/critic_loss"] == pytest.approx(float(((q - y) ** 2).mean()), rel=1e-5)


def test_critic_loss_falls_on_a_fixed_batch():
    model = PADDPG("pamdp/Platform-v0", dataclasses.replace(SMALL, learning_starts=10**6, hidden_sizes=(64, 64)))
    with pytest.warns(UserWarning, match="makes no gradient update"):  # replay only, as meant
        model.learn(200, progress_bar=False)
    b = model.replay.sample(128, np.random.default_rng(0))
    losses = []
    for _ in range(150):
        loss = (model.critic.smaller(b["obs"], b["out"]).squeeze(-1) - b["reward"]).pow(2).mean()
        model.critic_optimizer.zero_grad()
        loss.backward()
        model.critic_optimizer.step()
        losses.append(loss.item())
    assert losses[-1] < 0.2 * losses[0]


def test_checkpoints_of_the_critic_before_it_was_a_twin_q_still_load(tmp_path):
    """Files written when the critic (and its target) held its ``mlp`` under ``net`` load into the TwinQ's ``q1``
    (checkpoints.RENAMED), optimiser state included, and act as the model that wrote them."""
    model = PADDPG("pamdp/Platform-v0", dataclasses.replace(SMALL, learning_starts=64))
    model.learn(200, progress_bar=False)
    model.save(tmp_path / "new.pt")
    payload = torch.load(tmp_path / "new.pt", weights_only=True)
    for name in ("critic", "critic_target"):
        state = payload["modules"][name]
        assert all(k.startswith("q1.") for k in state)
        payload["modules"][name] = {"net." + k[3:]: v for k, v in state.items()}
    torch.save(payload, tmp_path / "old.pt")
    loaded = PADDPG.load(tmp_path / "old.pt")
    assert module_bytes(loaded) == module_bytes(model)
    obs = model.replay.data["obs"][:8].numpy()
    for a, b in zip(loaded.predict(obs), model.predict(obs)):
        np.testing.assert_array_equal(a, b)
