"""TRPO machinery against explicit linear algebra."""

import numpy as np
import pytest
import torch
from torch import nn

from pamdp.algos.trpo import (
    FisherVectorProduct,
    GaussNewtonFVP,
    backtracking_line_search,
    conjugate_gradient,
    flat_grad,
    flat_params,
    set_flat_params,
)
from pamdp.distributions import HybridDistribution, kl_divergence
from pamdp.policies import HybridPolicy, LinearizedMLP, mlp
from pamdp.spaces import HybridActionSpace


def tiny_policy(seed=0, activation="tanh", hidden_sizes=(4,), pi_c_input="onehot"):
    hs = HybridActionSpace((np.zeros(2), np.zeros(1)), (np.ones(2), np.ones(1)))
    torch.manual_seed(seed)
    pol = HybridPolicy(3, hs, hidden_sizes=hidden_sizes, activation=activation, pi_c_input=pi_c_input).double()
    # Larger final layers than the default near-zero init, so the Hessian is not trivially tiny.
    for p in pol.parameters():
        p.data.normal_(0, 0.5)
    return pol


def explicit_hessian(fn, params):
    theta = flat_params(params)
    n = theta.numel()
    g = flat_grad(fn(), params, create_graph=True)
    rows = [flat_grad(g[i], params, retain_graph=True) for i in range(n)]
    return torch.stack(rows)


def test_flat_params_round_trip():
    pol = tiny_policy()
    params = list(pol.parameters())
    theta = flat_params(params)
    set_flat_params(params, theta * 2)
    torch.testing.assert_close(flat_params(params), theta * 2)


def test_fisher_vector_product_matches_explicit_hessian():
    pol = tiny_policy()
    params = list(pol.parameters())
    obs = torch.randn(16, 3, dtype=torch.float64, generator=torch.Generator().manual_seed(0))
    with torch.no_grad():
        old = pol(obs).detach()

    def kl():
        return kl_divergence(old, pol(obs), "chain_analytic").mean()

    H = explicit_hessian(kl, params)
    torch.testing.assert_close(H, H.T, atol=1e-10, rtol=0)
    damping = 1e-3
    fvp = FisherVectorProduct(kl(), params, damping)
    v = torch.randn(H.shape[0], dtype=torch.float64, generator=torch.Generator().manual_seed(1))
    torch.testing.assert_close(fvp(v), H @ v + damping * v, atol=1e-10, rtol=1e-8)
    # At the old parameters the KL's Hessian is a Fisher matrix: positive semi-definite.
    assert torch.linalg.eigvalsh(H).min() > -1e-10


@pytest.mark.parametrize(
    "activation, pi_c_input",
    [
        ("tanh", "onehot"),
        ("relu", "onehot"),
        ("leaky_relu", "onehot"),
        ("elu", "onehot"),
        ("tanh", "state"),
        ("relu", "state"),
    ],
)
@pytest.mark.parametrize("estimator", ["chain_analytic", "chain_sample"])
def test_gauss_newton_product_matches_explicit_hessian(estimator, activation, pi_c_input):
    pol = tiny_policy(3, activation, hidden_sizes=(5, 4), pi_c_input=pi_c_input)
    named = list(pol.named_parameters())
    names, params = [n for n, _ in named], [p for _, p in named]
    g = torch.Generator().manual_seed(0)
    obs = torch.randn(16, 3, dtype=torch.float64, generator=g)
    with torch.no_grad():
        old = pol(obs).detach()
        a, x = old.sample(g)

    def kl():
        return kl_divergence(old, pol(obs), estimator, a, x).mean()

    H = explicit_hessian(kl, params)
    new, jvp = pol.linearize(obs)
    torch.testing.assert_close(new.logits, pol(obs).logits)
    fvp = GaussNewtonFVP(
        (new.logits, new.means, pol.log_std),
        params,
        lambda ts: jvp(dict(zip(names, ts))),
        lambda *t: old.kl_hessian_product(*t, estimator, a),
        damping=1e-3,
    )
    for seed in range(3):
        v = torch.randn(H.shape[0], dtype=torch.float64, generator=torch.Generator().manual_seed(seed))
        torch.testing.assert_close(fvp(v), H @ v + 1e-3 * v, atol=1e-10, rtol=1e-8)


def test_conjugate_gradient_solves_spd_system():
    g = torch.Generator().manual_seed(0)
    A = torch.randn(20, 20, generator=g, dtype=torch.float64)
    A = A @ A.T + 20 * torch.eye(20, dtype=torch.float64)
    b = torch.randn(20, generator=g, dtype=torch.float64)
    x = conjugate_gradient(lambda v: A @ v, b, iters=50, residual_tol=1e-24)
    torch.testing.assert_close(x, torch.linalg.solve(A, b), atol=1e-8, rtol=1e-8)


def test_line_search_accepts_improving_step_within_bound():
    w = nn.Parameter(torch.tensor([0.0], dtype=torch.float64))
    result = backtracking_line_search(
        [w],
        torch.tensor([2.0], dtype=torch.float64),
        evaluate=lambda: (-(w - 1.0).pow(2).sum(), w.pow(2).sum()),
        before=-1.0,
        max_kl=1.5,
        backtrack_ratio=0.5,
        max_backtracks=10,
    )
    # Step 2.0 overshoots (no improvement: -1 vs -1); 1.0 improves with KL 1.0 <= 1.5.
    assert result.success and result.backtracks == 1
    assert float(w.detach()) == 1.0 and result.improvement == 1.0 and result.kl == 1.0


def test_line_search_rejects_and_restores():
    w = nn.Parameter(torch.tensor([0.5], dtype=torch.float64))
    result = backtracking_line_search(
        [w],
        torch.tensor([1.0], dtype=torch.float64),
        evaluate=lambda: (w.sum(), 100 * w.pow(2).sum()),
        before=0.5,
        max_kl=1.0,
        backtrack_ratio=0.5,
        max_backtracks=3,
    )
    # Every tried step improves the surrogate but breaks the KL bound: all rejected, parameters restored.
    assert not result.success and result.backtracks == 3
    assert float(w.detach()) == 0.5


def test_natural_step_improves_the_surrogate_within_the_trust_region():
    pol = tiny_policy(1)
    params = list(pol.parameters())
    g = torch.Generator().manual_seed(2)
    obs = torch.randn(256, 3, dtype=torch.float64, generator=g)
    with torch.no_grad():
        old = pol(obs).detach()
        a, x = old.sample(g)
        old_logp = old.log_prob(a, x)
    adv = torch.randn(256, dtype=torch.float64, generator=g)

    def surrogate():
        return (torch.exp(pol(obs).log_prob(a, x) - old_logp) * adv).mean()

    def kl():
        return kl_divergence(old, pol(obs), "chain_analytic").mean()

    before = float(surrogate().detach())
    grad = flat_grad(surrogate(), params)
    fvp = FisherVectorProduct(kl(), params, 1e-5)
    d = conjugate_gradient(fvp, grad, 10)
    delta = 0.01
    step = torch.sqrt(2 * delta / (d @ fvp(d))) * d
    result = backtracking_line_search(params, step, lambda: (surrogate(), kl()), before, delta)
    assert result.success
    assert float(surrogate().detach()) > before
    assert float(kl().detach()) <= delta
    # The quadratic model predicts the KL of the full step to be delta; the accepted one is near it.
    assert float(kl().detach()) > 0.2 * delta


def test_hybrid_distribution_dtype_is_preserved():
    d = HybridDistribution(
        torch.zeros(2, 2), torch.zeros(2, 2, 1), torch.zeros(2, 1), torch.ones(2, 1, dtype=torch.bool)
    )
    assert d.entropy().dtype == torch.float32


@pytest.mark.parametrize("activation", ["tanh", "relu", "leaky_relu", "elu"])
def test_linearized_mlp_matches_forward_mode_autodiff(activation):
    net = mlp(4, (6, 5), 3, activation, nn.Tanh).double()
    g = torch.Generator().manual_seed(0)
    inputs = torch.randn(7, 2, 4, dtype=torch.float64, generator=g)  # any leading shape
    params = dict(net.named_parameters())
    tangents = {n: torch.randn(p.shape, dtype=p.dtype, generator=g) for n, p in params.items()}
    lin = LinearizedMLP(net, inputs)
    out, expected = torch.func.jvp(
        lambda *w: torch.func.functional_call(net, dict(zip(params, w)), (inputs,)),
        tuple(p.detach() for p in params.values()),
        tuple(tangents.values()),
    )
    torch.testing.assert_close(lin.outputs, out)
    torch.testing.assert_close(lin.jvp(list(tangents.values())), expected, atol=1e-12, rtol=1e-10)


def test_linearized_mlp_names_a_layer_it_cannot_differentiate():
    with pytest.raises(TypeError, match="Softplus"):
        LinearizedMLP(nn.Sequential(nn.Linear(2, 2), nn.Softplus()), torch.zeros(1, 2))
