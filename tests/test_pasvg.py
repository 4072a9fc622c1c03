"""PASVG(0): the Gumbel-Softmax sample, the reparameterised gradient, replay, the twin critics, the entropy weight
(reproducibility and save/load as every algorithm: test_algorithms)."""

import dataclasses

import numpy as np
import pytest
import torch
from conftest import HYBRID, OFF_POLICY_SMALL, module_bytes

from pamdp import PASVG0
from pamdp.algos.pasvg import PASVG0Config, expected_q
from pamdp.distributions import gumbel_noise, gumbel_softmax_sample
from pamdp.policies import GumbelHybridPolicy

SMALL = PASVG0Config(hidden_sizes=(16, 16), **OFF_POLICY_SMALL)


def test_straight_through_sample_is_one_hot_with_gradient_to_the_logits():
    logits = torch.tensor([[0.3, -0.2, 1.0], [2.0, 0.0, -1.0]], requires_grad=True)
    eta = gumbel_noise((2, 3), torch.Generator().manual_seed(0))
    index, sample = gumbel_softmax_sample(logits, eta, temperature=1.0, hard=True)
    torch.testing.assert_close(sample.detach(), torch.nn.functional.one_hot(index, 3).float())
    np.testing.assert_array_equal(index, (logits.log_softmax(-1) + eta).argmax(-1))
    (sample * torch.tensor([1.0, 2.0, 3.0])).sum().backward()
    assert logits.grad.abs().sum() > 0
    # The backward pass is the soft sample's.
    soft_logits = logits.detach().clone().requires_grad_(True)
    _, soft = gumbel_softmax_sample(soft_logits, eta, 1.0, hard=False)
    (soft * torch.tensor([1.0, 2.0, 3.0])).sum().backward()
    torch.testing.assert_close(logits.grad, soft_logits.grad)


def test_gumbel_max_draws_follow_the_softmax():
    logits = torch.tensor([0.5, -1.0, 1.5]).expand(40_000, 3)
    index, _ = gumbel_softmax_sample(logits, gumbel_noise((40_000, 3), torch.Generator().manual_seed(1)), 1.0, True)
    freq = np.bincount(index.numpy(), minlength=3) / 40_000
    np.testing.assert_allclose(freq, torch.softmax(logits[0], -1).numpy(), atol=0.01)


def toy_critic(obs, a, x):
    """A smooth stand-in for Q(s, a, x), non-linear in every input."""
    w = torch.tensor([0.7, -1.3, 2.1], dtype=obs.dtype)
    return torch.sin(obs.sum(-1)) * (a @ w) + (a @ w) * (x - 0.3).pow(2).sum(-1) + torch.cos(3 * x[:, 0])


def assert_gradients_match_finite_differences(objective, params: dict, names, picks: int = 4, h: float = 1e-6):
    """Autograd's gradient of ``objective()`` against central differences, at ``picks`` entries of each named tensor."""
    grads = dict(zip(params, torch.autograd.grad(objective(), list(params.values()))))
    rng = np.random.default_rng(3)
    for name in names:
        p = params[name]
        for flat in rng.choice(p.numel(), size=min(picks, p.numel()), replace=False):
            with torch.no_grad():
                orig = p.view(-1)[flat].item()
                p.view(-1)[flat] = orig + h
                up = objective().item()
                p.view(-1)[flat] = orig - h
                down = objective().item()
                p.view(-1)[flat] = orig
            fd = (up - down) / (2 * h)
            assert grads[name].view(-1)[flat].item() == pytest.approx(fd, rel=1e-5, abs=1e-8), name
    return grads


@pytest.mark.parametrize("hard", [False, True])
def test_reparameterised_gradient_matches_finite_differences(hard):
    torch.manual_seed(0)
    policy = GumbelHybridPolicy(4, HYBRID, (8,), "tanh", init_log_std=-0.7).double()
    for p in policy.parameters():  # undo the near-zero output layers, so that every term matters
        p.data.normal_(0, 0.5)
    gen = torch.Generator().manual_seed(2)
    obs = torch.randn(6, 4, generator=gen, dtype=torch.float64)
    eta_a = gumbel_noise((6, 3), gen).double()
    eta_x = torch.randn(6, 2, generator=gen, dtype=torch.float64)

    def objective():
        *_, a, x = policy(obs, eta_a, eta_x, 0.8, hard)
        return toy_critic(obs, a, x).mean()

    params = dict(policy.named_parameters())
    # With soft samples J is smooth in every parameter. With hard samples the forward pass is piecewise
    # constant in pi_d (straight-through is a biased estimator by design), but exact for pi_c and the std.
    names = list(params) if not hard else [n for n in params if not n.startswith("pi_d")]
    grads = assert_gradients_match_finite_differences(objective, params, names)
    if hard:
        assert grads["pi_d.0.weight"].abs().sum() > 0  # the straight-through gradient reaches pi_d


def test_expected_value_is_the_mean_over_gumbel_samples_and_its_gradient_is_exact():
    torch.manual_seed(0)
    policy = GumbelHybridPolicy(4, HYBRID, (8,), "tanh", init_log_std=-0.7).double()
    for p in policy.parameters():
        p.data.normal_(0, 0.5)
    gen = torch.Generator().manual_seed(5)
    obs = torch.randn(3, 4, generator=gen, dtype=torch.float64)
    eta_x = torch.randn(3, 2, generator=gen, dtype=torch.float64)

    def critic(s, a, x):  # toy_critic on (B, K, .) inputs
        return toy_critic(s.reshape(-1, 4), a.reshape(-1, 3), x.reshape(-1, 2)).reshape(s.shape[:-1])

    logits, value = expected_q(policy, critic, obs, eta_x)
    torch.testing.assert_close(logits, policy.pi_d(obs))
    # Monte-Carlo: the hard Gumbel-Softmax sample with the same parameter noise, averaged over eta_a.
    n = 200_000
    with torch.no_grad():
        obs_n, eta_x_n = obs.repeat(n, 1), eta_x.repeat(n, 1)
        *_, a, x = policy(obs_n, gumbel_noise((3 * n, 3), gen).double(), eta_x_n, 1.0, True)
        q = toy_critic(obs_n, a, x).reshape(n, 3)
    np.testing.assert_allclose(value.detach(), q.mean(0), atol=4 * float(q.std(0).max()) / n**0.5)

    # Its gradient reaches pi_d, pi_c and the std, and matches finite differences.
    def objective():
        return expected_q(policy, critic, obs, eta_x)[1].mean()

    names = ("pi_d.0.weight", "pi_d.2.bias", "pi_c.0.weight", "pi_c.2.bias", "log_std")
    grads = assert_gradients_match_finite_differences(objective, dict(policy.named_parameters()), names, picks=3)
    assert all(grads[name].abs().sum() > 0 for name in names)


def test_expected_td_target_averages_the_target_policys_actions():
    model = PASVG0("pamdp/Platform-v0", dataclasses.replace(SMALL, discrete_gradient="expected", learning_starts=10**6))
    with pytest.warns(UserWarning, match="makes no gradient update"):  # replay only, as meant
        model.learn(200, progress_bar=False)
    batch = model.replay.sample(16, np.random.default_rng(0))
    model.replay.sample = lambda n, rng: batch
    gen_state = model.torch_gen.get_state()
    with torch.no_grad():
        q = model._q1(batch["obs"], batch["a_in"], batch["x"])
        model.torch_gen.set_state(gen_state)
        _, eta_x = model._noise(16)
        model.torch_gen.set_state(gen_state)
        s2, pt, K = batch["next_obs"], model.policy_target, 3
        total = torch.zeros(16)
        for k in range(K):  # one action at a time, by hand
            onehot = torch.nn.functional.one_hot(torch.full((16,), k), K).float()
            x_k = pt.params(s2, torch.full((16,), k), onehot, eta_x)
            total += pt.pi_d(s2).softmax(-1)[:, k] * model.critic_target.smaller(s2, onehot, x_k).squeeze(-1)
        y = batch["reward"] + 0.99 * (~batch["terminated"]).float() * total
    stats = model._update()
    assert stats["losses/critic_loss"] == pytest.approx(float(((q - y) ** 2).mean()), rel=1e-5)
    assert {"losses/actor_loss", "train/q_pi_mean"} <= set(stats)


def test_parameters_stay_in_bounds_and_unused_ones_are_zero():
    policy = GumbelHybridPolicy(4, HYBRID, (8,), "relu", init_log_std=1.5)
    gen = torch.Generator().manual_seed(0)
    _, index, _, x = policy(
        torch.randn(500, 4, generator=gen), gumbel_noise((500, 3), gen), torch.randn(500, 2) * 5, 1.0, True
    )
    assert x.abs().max() <= 1.0
    mask = torch.tensor(HYBRID.param_mask)[index]
    assert torch.all(x[~mask] == 0)


def test_epoch_stores_valid_transitions_with_their_noise_and_learns():
    model = PASVG0("pamdp/Platform-v0", SMALL)
    stats = []
    model.learn(400, progress_bar=False, callback=lambda m, s: stats.append(s))
    n = len(model.replay)
    assert n == model.num_timesteps >= 400  # autoreset steps are not stored
    a, a_in, eta_a = (model.replay.data[k][:n].numpy() for k in ("a", "a_in", "eta_a"))
    np.testing.assert_array_equal(a_in.argmax(1), a)
    np.testing.assert_array_equal(a_in.max(1), 1.0)  # straight-through: the critic sees one-hots
    assert np.all(np.isfinite(eta_a)) and model.replay.data["eta_x"][:n].abs().max() > 0
    assert stats[-1]["train/updates"] > 0
    for key in ("losses/critic_loss", "losses/actor_loss", "train/q_mean", "train/action_freq_2"):
        assert np.isfinite(stats[-1][key]), key
    # With the recorded noise, the current policy reproduces the stored action until it is updated.
    fresh = PASVG0("pamdp/Platform-v0", dataclasses.replace(SMALL, learning_starts=10**6))
    with pytest.warns(UserWarning, match="makes no gradient update"):  # replay only, as meant
        fresh.learn(100, progress_bar=False)
    k = len(fresh.replay)
    with torch.no_grad():
        _, index, _, x = fresh.policy(
            fresh.replay.data["obs"][:k],
            fresh.replay.data["eta_a"][:k],
            fresh.replay.data["eta_x"][:k],
            1.0,
            True,
        )
    np.testing.assert_array_equal(index.numpy(), fresh.replay.data["a"][:k].numpy())
    np.testing.assert_allclose(x.numpy(), fresh.replay.data["x"][:k].numpy(), atol=1e-6)


def test_greedy_evaluations_during_training_are_logged_and_leave_training_unchanged(tmp_path):
    plain = PASVG0("pamdp/Platform-v0", SMALL)
    plain.learn(400, progress_bar=False)
    evaluated = PASVG0("pamdp/Platform-v0", SMALL)
    stats = []
    evaluated.learn(
        400, progress_bar=False, run_dir=tmp_path, eval_every=1, eval_episodes=7, callback=lambda m, s: stats.append(s)
    )
    assert module_bytes(plain) == module_bytes(evaluated)
    assert len(stats) == 2 and all(0 <= s["eval/mean_return"] <= 1 for s in stats)
    # The logged figure is a greedy evaluation of the model as it was after that epoch: the same call reproduces it.
    from pamdp.evaluation import evaluate

    assert stats[-1]["eval/mean_return"] == evaluate(evaluated, episodes=7, seed=10_000)["mean_return"]
    assert "eval/mean_return" in (tmp_path / "progress.csv").read_text().splitlines()[0]
    with pytest.raises(ValueError, match="eval_every = -1"):
        plain.learn(10, eval_every=-1)


def test_explore_epsilon_draws_uniform_actions_with_their_own_parameters():
    # pi_d made all but certain of action 0: what reaches replay besides action 0 comes from the epsilon draws,
    # about eps * (K - 1) / K of the samples, each with pi_c's parameters for the action actually taken.
    eps = 0.3
    model = PASVG0("pamdp/Platform-v0", dataclasses.replace(SMALL, explore_epsilon=eps, learning_starts=10**6))
    with torch.no_grad():
        model.policy.pi_d[-1].bias.copy_(torch.tensor([30.0, 0.0, 0.0]))
    with pytest.warns(UserWarning, match="makes no gradient update"):  # replay only, as meant
        model.learn(2000, progress_bar=False)
    n = len(model.replay)
    a = model.replay.data["a"][:n].numpy()
    others = np.mean(a != 0)
    assert abs(others - eps * 2 / 3) < 4 * np.sqrt(eps * 2 / 3 / n), (others, n)
    np.testing.assert_array_equal(model.replay.data["a_in"][:n].numpy().argmax(1), a)
    obs, eta_x = (model.replay.data[k][:n] for k in ("obs", "eta_x"))
    onehot = torch.nn.functional.one_hot(torch.from_numpy(a), 3).float()
    with torch.no_grad():
        x = model.policy.params(obs, torch.from_numpy(a), onehot, eta_x)
    np.testing.assert_allclose(x.numpy(), model.replay.data["x"][:n].numpy(), atol=1e-6)


def test_twin_critics_learn_towards_the_smaller_target(tmp_path):
    model = PASVG0("pamdp/Platform-v0", dataclasses.replace(SMALL, twin_critics=True, learning_starts=10**6))
    with pytest.warns(UserWarning, match="makes no gradient update"):  # replay only, as meant
        model.learn(200, progress_bar=False)  # fills replay, no update
    batch = model.replay.sample(16, np.random.default_rng(0))
    model.replay.sample = lambda n, rng: batch
    outs = {}
    for name in ("q1", "q2"):
        net = getattr(model.critic_target, name)
        net.register_forward_hook(lambda m, i, o, name=name: outs.__setitem__(name, o.squeeze(-1).clone()))
    with torch.no_grad():
        model.critic_target.q2[-1].bias.fill_(-3.0)  # the second target critic is now the smaller one
        q1, q2 = (q.squeeze(-1) for q in model.critic(batch["obs"], batch["a_in"], batch["x"]))
    stats = model._update()
    assert torch.all(outs["q2"] < outs["q1"])
    y = batch["reward"] + 0.99 * (~batch["terminated"]).float() * torch.minimum(*outs.values())
    expected = ((q1 - y) ** 2).mean() + ((q2 - y) ** 2).mean()
    assert stats["losses/critic_loss"] == pytest.approx(float(expected), rel=1e-5)
    model.save(tmp_path / "m.pt")
    loaded = PASVG0.load(tmp_path / "m.pt")
    assert module_bytes(loaded) == module_bytes(model)
    assert torch.equal(loaded.critic.q2[0].weight, model.critic.q2[0].weight) and loaded.critic_updates == 1


@pytest.mark.parametrize("twin", [False, True])
def test_checkpoints_of_the_critics_before_they_were_one_twin_q_still_load(tmp_path, twin):
    """Files written when the critics were modules ``critic`` and ``critic2`` (and their targets), each an ``mlp``
    under ``net``, load into the TwinQ's ``q1`` and ``q2`` (checkpoints.RENAMED)."""
    model = PASVG0("pamdp/Platform-v0", dataclasses.replace(SMALL, twin_critics=twin))
    model.learn(100, progress_bar=False)
    model.save(tmp_path / "new.pt")
    payload = torch.load(tmp_path / "new.pt", weights_only=True)
    modules = payload["modules"]
    for name in ("critic", "critic_target"):
        state = modules.pop(name)
        for q, old in (("q1", name), ("q2", name.replace("critic", "critic2"))):
            keys = [k for k in state if k.startswith(q + ".")]
            if keys:
                modules[old] = {"net." + k[3:]: state[k] for k in keys}
    assert ("critic2" in modules) == twin
    torch.save(payload, tmp_path / "old.pt")
    assert module_bytes(PASVG0.load(tmp_path / "old.pt")) == module_bytes(model)


def test_policy_delay_updates_the_policy_and_targets_every_kth_step():
    model = PASVG0("pamdp/Platform-v0", dataclasses.replace(SMALL, policy_delay=3, learning_starts=10**6))
    with pytest.warns(UserWarning, match="makes no gradient update"):  # replay only, as meant
        model.learn(200, progress_bar=False)
    target = [p.clone() for p in model.policy_target.parameters()]
    for k in range(1, 7):
        model._update()
        moved = not all(torch.equal(a, b) for a, b in zip(target, model.policy_target.parameters()))
        assert moved == (k >= 3), k
    steps = {int(s["step"]) for s in model.policy_optimizer.state.values()}
    assert steps == {2} and {int(s["step"]) for s in model.critic_optimizer.state.values()} == {6}


def test_target_entropy_above_ln_k_is_refused():
    with pytest.raises(ValueError, match=r"target_entropy = 1.2; expected at most ln K = 1.0986"):
        PASVG0("pamdp/Platform-v0", dataclasses.replace(SMALL, target_entropy=1.2, entropy_coef=0.1))


@pytest.mark.parametrize("peaked, target, direction", [(False, 0.05, -1), (True, 1.0, 1)])
def test_entropy_weight_moves_towards_the_target(tmp_path, peaked, target, direction):
    # pi_d starts near uniform (entropy ~ln 3 = 1.10), far above a target of 0.05: the weight must fall at
    # each update. Made peaked (logits 8, 0, 0: entropy ~0.003), it is far below a target of 1.0: it must rise.
    cfg = dataclasses.replace(SMALL, target_entropy=target, entropy_coef=0.1, entropy_lr=0.01, learning_starts=64)
    model = PASVG0("pamdp/Platform-v0", cfg)
    if peaked:
        with torch.no_grad():
            model.policy.pi_d[-1].bias.copy_(torch.tensor([8.0, 0.0, 0.0]))
    stats = []
    model.learn(200, progress_bar=False, callback=lambda m, s: stats.append(s))
    updates = sum(s["train/updates"] for s in stats)
    change = float(model.entropy_weight.log_alpha.detach()) - np.log(0.1)
    # Each Adam step moves log alpha by about entropy_lr in the sign of (target - entropy).
    assert direction * change > 0.5 * 0.01 * updates > 0, (change, updates)
    model.save(tmp_path / "m.pt")
    loaded = PASVG0.load(tmp_path / "m.pt")
    assert torch.equal(loaded.entropy_weight.log_alpha.detach(), model.entropy_weight.log_alpha.detach())


def test_critic_loss_falls_on_a_fixed_batch():
    model = PASVG0("pamdp/Platform-v0", dataclasses.replace(SMALL, learning_starts=10**6, hidden_sizes=(64, 64)))
    with pytest.warns(UserWarning, match="makes no gradient update"):  # replay only, as meant
        model.learn(200, progress_bar=False)
    b = model.replay.sample(128, np.random.default_rng(0))
    target = b["reward"]  # a fixed regression target: the one-step reward
    losses = []
    for _ in range(150):
        loss = (model._q1(b["obs"], b["a_in"], b["x"]) - target).pow(2).mean()
        model.critic_optimizer.zero_grad()
        loss.backward()
        model.critic_optimizer.step()
        losses.append(loss.item())
    assert losses[-1] < 0.2 * losses[0]
