"""PAPPO: the clipped surrogate and its gradient by hand, the whole loss against torch.distributions and
finite differences, the value loss, the KL early stop, settings (save/load, resuming and the command line as every
algorithm: test_algorithms)."""

import dataclasses
import math

import numpy as np
import pytest
import torch
from conftest import HYBRID
from numeric import finite_difference
from torch.distributions import Categorical, Normal

from pamdp import PAPPO
from pamdp.algos.pappo import PAPPOConfig, clipped_surrogate, ppo_loss
from pamdp.policies import HybridPolicy, ValueNetwork

SMALL = PAPPOConfig(
    hidden_sizes=(16, 16), vf_hidden_sizes=(16,), batch_size=500, minibatch_size=100, n_epochs=2, num_envs=4
)


def test_clipped_surrogate_and_its_gradient_by_hand():
    eps = 0.2
    ratio = torch.tensor([1.1, 1.5, 0.5, 0.5, 1.5, 0.9], dtype=torch.float64)
    adv = torch.tensor([2.0, 1.0, 1.0, -1.0, -2.0, -1.0], dtype=torch.float64)
    # min(r A, clip(r) A) per sample: inside the range; clipped above with A > 0 (1.2 * 1); below the range with
    # A > 0 (not clipped: 0.5 < 0.8); clipped below with A < 0 (0.8 * -1); above the range with A < 0 (not
    # clipped: -3 < -2.4); inside the range.
    objective = [2.2, 1.2, 0.5, -0.8, -3.0, -0.9]
    clipped = [False, True, False, True, False, False]
    old_logp = torch.tensor([-1.0, 0.3, -2.0, 0.0, -0.5, 1.0], dtype=torch.float64)
    logp = (old_logp + ratio.log()).requires_grad_()
    loss = clipped_surrogate(logp, old_logp, adv, eps)
    assert loss.item() == pytest.approx(-sum(objective) / 6, rel=1e-12)
    loss.backward()
    # d(r A)/d logp = r A where unclipped; a sample clipped on its advantage's side gives no gradient.
    expected = [0.0 if c else -r * a / 6 for r, a, c in zip(ratio.tolist(), adv.tolist(), clipped)]
    np.testing.assert_allclose(logp.grad.numpy(), expected, rtol=1e-12, atol=0)
    assert (logp.grad[torch.tensor(clipped)] == 0).all() and (logp.grad[~torch.tensor(clipped)] != 0).all()


def _tiny_problem(seed=0):
    """A float64 policy and value net on HYBRID, six samples with ratios inside and outside the clip range."""
    torch.manual_seed(seed)
    policy = HybridPolicy(5, HYBRID, (4,), "tanh", init_log_std=-0.3).double()
    value = ValueNetwork(5, (4,)).double()
    with torch.no_grad():
        policy.log_std.add_(0.2 * torch.randn_like(policy.log_std))
        policy.pi_d[-1].weight.mul_(300.0)  # a non-uniform pi_d, so that every entropy term has a gradient
    obs = torch.randn(6, 5, dtype=torch.float64)
    a = torch.tensor([0, 1, 2, 1, 0, 2])
    with torch.no_grad():
        x = policy(obs).sample(torch.Generator().manual_seed(seed))[1]
        ratio = torch.tensor([0.5, 0.9, 1.1, 1.5, 0.6, 1.4], dtype=torch.float64)
        old_logp = policy(obs).log_prob(a, x) - ratio.log()
    adv = torch.tensor([1.0, -1.0, 2.0, -0.5, -1.5, 0.7], dtype=torch.float64)
    returns = torch.randn(6, dtype=torch.float64)
    return policy, value, obs, a, x, old_logp, adv, returns


def _independent_loss(policy, value, obs, a, x, old_logp, adv, returns, cfg):
    """The PAPPO loss sample by sample with torch.distributions, evaluating pi_c for one action at a time."""
    surrogate, entropy_d, entropy_c = [], [], []
    for i in range(len(obs)):
        pi_d = Categorical(logits=policy.pi_d(obs[i]))
        pi_c = []
        for k, m in enumerate(HYBRID.param_sizes):
            mean = policy.pi_c(torch.cat([obs[i], torch.eye(3, dtype=obs.dtype)[k]]))[:m]
            pi_c.append(Normal(mean, policy.log_std[k, :m].exp()))
        k = int(a[i])
        logp = pi_d.log_prob(a[i]) + pi_c[k].log_prob(x[i, : HYBRID.param_sizes[k]]).sum()
        r = torch.exp(logp - old_logp[i])
        surrogate.append(torch.min(r * adv[i], torch.clamp(r, 1 - cfg.clip_range, 1 + cfg.clip_range) * adv[i]))
        entropy_d.append(pi_d.entropy())
        entropy_c.append(sum(pi_d.probs[k] * pi_c[k].entropy().sum() for k in range(3)))
    mse = (value(obs) - returns).pow(2).mean()
    mean = lambda xs: torch.stack(xs).mean()  # noqa: E731
    return -mean(surrogate) + cfg.vf_coef * mse - cfg.ent_coef_d * mean(entropy_d) - cfg.ent_coef_c * mean(entropy_c)


def test_loss_matches_an_independent_computation_and_finite_differences():
    cfg = PAPPOConfig(clip_range=0.2, vf_coef=0.7, ent_coef_d=0.3, ent_coef_c=0.2)
    policy, value, obs, a, x, old_logp, adv, returns = _tiny_problem()
    loss, parts = ppo_loss(policy(obs), value(obs), a, x, old_logp, adv, returns, cfg)
    independent = _independent_loss(policy, value, obs, a, x, old_logp, adv, returns, cfg)
    assert loss.item() == pytest.approx(independent.item(), rel=1e-12)
    assert parts["train/clip_fraction"].item() == pytest.approx(4 / 6)  # 0.5, 0.6, 1.4, 1.5 leave [0.8, 1.2]

    params = [*policy.parameters(), *value.parameters()]
    loss.backward()
    with torch.no_grad():
        expected = finite_difference(
            lambda: _independent_loss(policy, value, obs, a, x, old_logp, adv, returns, cfg).item(), params
        )
    for p, e in zip(params, expected):
        torch.testing.assert_close(p.grad, e, rtol=1e-6, atol=1e-8)
    assert policy.log_std.grad[1, 1] != 0 and policy.log_std.grad[0, 1] == 0  # action 0 has one parameter


def test_value_loss_by_hand():
    policy = HybridPolicy(2, HYBRID, (4,))
    obs = torch.zeros(3, 2)
    dist = policy(obs)
    a, x = dist.mode()
    cfg = PAPPOConfig(vf_coef=0.25, ent_coef_d=0.0)
    values, returns = torch.tensor([1.0, 2.0, 3.0]), torch.tensor([0.0, 2.0, 5.0])
    # Zero advantages: the surrogate vanishes, and the loss is vf_coef * mean((V - R)^2) = 0.25 * 5 / 3.
    loss, parts = ppo_loss(dist, values, a, x, dist.log_prob(a, x), torch.zeros(3), returns, cfg)
    assert parts["losses/value_loss"].item() == pytest.approx(5 / 3)
    assert loss.item() == pytest.approx(0.25 * 5 / 3)
    assert parts["losses/entropy_d"].item() == pytest.approx(math.log(3), rel=1e-3)  # pi_d starts near uniform


def test_entropy_parts_add_up_to_the_chain_rule_entropy():
    policy, value, obs, a, x, old_logp, adv, returns = _tiny_problem(1)
    dist = policy(obs)
    _, parts = ppo_loss(dist, value(obs), a, x, old_logp, adv, returns, PAPPOConfig())
    total = parts["losses/entropy_d"] + parts["losses/entropy_c"]
    torch.testing.assert_close(total, dist.entropy().mean())
    torch.testing.assert_close(parts["losses/entropy_d"], Categorical(logits=dist.logits).entropy().mean())


def test_update_improves_the_surrogate_and_target_kl_stops_it_early():
    model = PAPPO("pamdp/Platform-v0", SMALL)
    batch = model.loop.collect(500)
    valid = batch["valid"].reshape(-1)
    obs = model._obs_tensor(batch["obs"].reshape(-1, model.obs_dim)[valid])
    a, x = torch.as_tensor(batch["a"].reshape(-1)[valid]), torch.as_tensor(batch["x"].reshape(-1, 1)[valid])
    adv = torch.randn(len(a), generator=torch.Generator().manual_seed(0))
    returns = torch.zeros(len(a))
    with torch.no_grad():
        old_logp = model.policy(obs).log_prob(a, x)
    stats = model._update(obs, a, x, adv, returns)
    n_minibatches = len(a) // SMALL.minibatch_size
    assert stats["train/updates"] == SMALL.n_epochs * n_minibatches and stats["train/early_stop"] == 0
    assert stats["train/kl"] > 0
    with torch.no_grad():
        ratio = (model.policy(obs).log_prob(a, x) - old_logp).exp()
    assert (ratio * adv).mean() > 0.05  # the surrogate E[r A] started at E[A] ~ 0

    strict = PAPPO("pamdp/Platform-v0", dataclasses.replace(SMALL, target_kl=1e-7, n_epochs=5))
    stats = strict._update(obs, a, x, adv, returns)
    assert stats["train/early_stop"] == 1 and 1 <= stats["train/updates"] < 5 * n_minibatches


def test_plain_data_with_an_unknown_or_mistyped_setting_is_refused_naming_it():
    with pytest.raises(ValueError, match="unknown PAPPOConfig setting"):
        PAPPOConfig.from_dict({"clip": 0.1})
    with pytest.raises(ValueError, match="'n_epochs' = 2.5"):
        PAPPOConfig.from_dict({"n_epochs": 2.5})
