"""The hybrid distribution against independent computations (Monte-Carlo, closed forms by hand)."""

import math

import numpy as np
import pytest
import torch

from pamdp.distributions import HybridDistribution, kl_divergence
from pamdp.policies import HybridPolicy
from pamdp.spaces import HybridActionSpace

# HFO's shape: 3 actions with 2, 1 and 2 parameters (padded to 2).
MASK = torch.tensor([[True, True], [True, False], [True, True]])


def make_dist(seed, batch=4, scale=1.0):
    g = torch.Generator().manual_seed(seed)
    logits = torch.randn(batch, 3, generator=g, dtype=torch.float64) * scale
    means = torch.tanh(torch.randn(batch, 3, 2, generator=g, dtype=torch.float64))
    log_std = torch.randn(3, 2, generator=g, dtype=torch.float64) * 0.3 - 0.5
    return HybridDistribution(logits, means, log_std, MASK)


def test_log_prob_by_hand():
    d = make_dist(0)
    a = torch.tensor([0, 1, 2, 1])
    x = torch.tensor([[0.1, -0.2], [0.3, 0.0], [-0.5, 0.7], [0.9, 0.0]], dtype=torch.float64)
    expected = []
    for i in range(4):
        p = math.log(torch.softmax(d.logits[i], -1)[a[i]])
        for j in range(2 if a[i] != 1 else 1):
            mu, sd = float(d.means[i, a[i], j]), float(d.log_std[i, a[i], j].exp())
            p += -0.5 * ((float(x[i, j]) - mu) / sd) ** 2 - math.log(sd) - 0.5 * math.log(2 * math.pi)
        expected.append(p)
    np.testing.assert_allclose(d.log_prob(a, x).numpy(), expected, rtol=1e-12)


def test_unused_parameter_is_ignored():
    d = make_dist(1)
    a = torch.tensor([1, 1, 1, 1])
    x = torch.zeros(4, 2, dtype=torch.float64)
    y = x.clone()
    y[:, 1] = 123.0
    torch.testing.assert_close(d.log_prob(a, x), d.log_prob(a, y))


def test_samples_follow_the_distribution():
    d = make_dist(2, batch=1)
    n = 200_000
    rep = HybridDistribution(d.logits.expand(n, -1), d.means.expand(n, -1, -1), d.log_std[0], MASK)
    a, x = rep.sample(torch.Generator().manual_seed(0))
    freq = torch.bincount(a, minlength=3).double() / n
    torch.testing.assert_close(freq, d.probs_d[0], atol=4e-3, rtol=0)
    for k in range(3):
        xs = x[a == k]
        m = int(MASK[k].sum())
        torch.testing.assert_close(xs[:, :m].mean(0), d.means[0, k, :m], atol=0.02, rtol=0)
        torch.testing.assert_close(xs[:, :m].std(0), d.log_std[0, k, :m].exp(), atol=0.02, rtol=0)
        assert torch.all(xs[:, m:] == 0)


def test_entropy_against_monte_carlo():
    d = make_dist(3, batch=1)
    n = 400_000
    rep = HybridDistribution(d.logits.expand(n, -1), d.means.expand(n, -1, -1), d.log_std[0], MASK)
    a, x = rep.sample(torch.Generator().manual_seed(1))
    mc = -rep.log_prob(a, x).mean()
    se = rep.log_prob(a, x).std() / math.sqrt(n)
    assert abs(float(mc - d.entropy()[0])) < 4 * float(se)


@pytest.mark.parametrize("seed", [4, 5])
def test_chain_analytic_matches_monte_carlo_joint_kl(seed):
    old = make_dist(seed, batch=1, scale=1.5)
    new = make_dist(seed + 100, batch=1, scale=1.5)
    n = 400_000
    rep_old = HybridDistribution(old.logits.expand(n, -1), old.means.expand(n, -1, -1), old.log_std[0], MASK)
    rep_new = HybridDistribution(new.logits.expand(n, -1), new.means.expand(n, -1, -1), new.log_std[0], MASK)
    a, x = rep_old.sample(torch.Generator().manual_seed(2))
    samples = rep_old.log_prob(a, x) - rep_new.log_prob(a, x)
    analytic = kl_divergence(old, new, "chain_analytic")[0]
    assert abs(float(samples.mean() - analytic)) < 4 * float(samples.std() / math.sqrt(n))
    # The sample estimators are unbiased for the same quantity.
    for est in ("joint_sample", "chain_sample"):
        v = kl_divergence(rep_old, rep_new, est, a, x)
        assert abs(float(v.mean() - analytic)) < 4 * float(v.std() / math.sqrt(n)) + 1e-9


def test_kl_is_zero_against_itself_and_positive_otherwise():
    d, e = make_dist(6), make_dist(7)
    for est in ("chain_analytic", "chain_sample"):
        a, x = d.sample(torch.Generator().manual_seed(0))
        torch.testing.assert_close(kl_divergence(d, d, est, a, x), torch.zeros(4, dtype=torch.float64))
        assert torch.all(kl_divergence(d, e, est, a, x) > 0)


def test_unknown_estimator_and_missing_samples_raise():
    d = make_dist(8)
    with pytest.raises(ValueError, match="unknown KL estimator 'exact'"):
        kl_divergence(d, d, "exact", torch.zeros(4), torch.zeros(4, 2))
    with pytest.raises(ValueError, match="needs the sampled actions"):
        kl_divergence(d, d, "chain_sample")


def test_mode_is_argmax_with_mean_parameters():
    d = make_dist(9)
    a, x = d.mode()
    torch.testing.assert_close(a, d.logits.argmax(-1))
    for i in range(4):
        expected = d.means[i, a[i]] * MASK[a[i]]
        torch.testing.assert_close(x[i], expected)


def test_policy_evaluates_pi_c_for_every_action_in_one_pass():
    hs = HybridActionSpace((np.zeros(2), np.zeros(1), np.zeros(2)), (np.ones(2), np.ones(1), np.ones(2)))
    torch.manual_seed(0)
    pol = HybridPolicy(5, hs, hidden_sizes=(8, 8))
    obs = torch.randn(6, 5)
    dist = pol(obs)
    assert dist.means.shape == (6, 3, 2) and dist.logits.shape == (6, 3)
    for k in range(3):
        onehot = torch.nn.functional.one_hot(torch.full((6,), k), 3).float()
        torch.testing.assert_close(dist.means[:, k], pol.pi_c(torch.cat([obs, onehot], -1)))
    assert torch.all(dist.means.abs() <= 1)


@pytest.mark.parametrize("shared_std", [True, False])
@pytest.mark.parametrize("estimator", ["chain_analytic", "chain_sample"])
def test_kl_hessian_product_matches_autograd_in_the_distribution_parameters(estimator, shared_std):
    old = make_dist(7, batch=5, scale=2.0).detach()
    if not shared_std:  # a per-state log-std
        old = HybridDistribution(old.logits, old.means, old.log_std + 0.1 * torch.arange(5.0)[:, None, None], MASK)
    a, _ = old.sample(torch.Generator().manual_seed(1))
    std0 = old.log_std[0].clone() if shared_std else old.log_std.clone()
    leaves = [old.logits.clone().requires_grad_(), old.means.clone().requires_grad_(), std0.requires_grad_()]
    kl = kl_divergence(old, HybridDistribution(*leaves, MASK), estimator, a).mean()
    grads = torch.autograd.grad(kl, leaves, create_graph=True)
    g = torch.Generator().manual_seed(2)
    tangent = [torch.randn(t.shape, dtype=t.dtype, generator=g) for t in leaves]
    # The Hessian-vector product by double back-propagation of the KL itself, at new = old.
    expected = torch.autograd.grad(sum((gr * t).sum() for gr, t in zip(grads, tangent)), leaves)
    got = old.kl_hessian_product(*tangent, estimator, a)
    for e, r in zip(expected, got):
        assert r.shape == e.shape
        torch.testing.assert_close(r, e, atol=1e-12, rtol=1e-9)


def test_kl_hessian_product_refuses_the_joint_sample_estimator():
    d = make_dist(0)
    with pytest.raises(ValueError, match="joint_sample"):
        d.kl_hessian_product(d.logits, d.means, d.log_std, "joint_sample")
    with pytest.raises(ValueError, match="needs the sampled actions"):
        d.kl_hessian_product(d.logits, d.means, d.log_std, "chain_sample")
