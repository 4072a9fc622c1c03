"""The every-action computations that avoid building ``B * K`` inputs of width ``K`` (large K, e.g. Hard Move n = 10)
against the explicit constructions they replace, in float64: values and gradients."""

from __future__ import annotations

import numpy as np
import pytest
import torch
import torch.nn.functional as F

from pamdp import policies
from pamdp.algos.pasvg import every_action_q
from pamdp.policies import GumbelHybridPolicy, HybridPolicy, QNetwork, TwinQ, every_action_linear
from pamdp.spaces import HybridActionSpace

SIZES = (2, 0, 1, 3, 1)  # unequal boxes, one without parameters
HYBRID = HybridActionSpace(tuple(np.zeros(m) for m in SIZES), tuple(np.ones(m) for m in SIZES))
K, M, D, B = len(SIZES), max(SIZES), 4, 6


def randomised(module: torch.nn.Module) -> torch.nn.Module:
    """``module`` in float64 with every parameter drawn anew (no zero or tiny initial layer hides a term)."""
    module = module.double()
    gen = torch.Generator().manual_seed(3)
    with torch.no_grad():
        for p in module.parameters():
            p.copy_(torch.randn(p.shape, generator=gen, dtype=torch.float64) * 0.7)
    return module


def inputs(*shapes):
    gen = torch.Generator().manual_seed(11)
    return [torch.randn(s, generator=gen, dtype=torch.float64, requires_grad=True) for s in shapes]


def assert_same_function(module, fast, explicit, *args):
    """``fast(*args) == explicit(*args)`` to float64 rounding, and so are the gradients of a random functional of
    them in every parameter of ``module`` and every argument."""
    out_fast, out_explicit = fast(*args), explicit(*args)
    torch.testing.assert_close(out_fast, out_explicit, rtol=1e-12, atol=1e-12)
    weights = torch.randn(out_fast.shape, generator=torch.Generator().manual_seed(5), dtype=torch.float64)
    leaves = [*module.parameters(), *args]
    g_fast = torch.autograd.grad((out_fast * weights).sum(), leaves, allow_unused=True)
    g_explicit = torch.autograd.grad((out_explicit * weights).sum(), leaves, allow_unused=True)
    for g1, g2 in zip(g_fast, g_explicit):
        torch.testing.assert_close(g1, g2, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("activation", ["leaky_relu", "tanh"])
def test_multi_pass_q_is_the_explicit_b_times_k_passes(activation):
    q_net = randomised(QNetwork(D, HYBRID, (7, 5), activation, multi_pass=True))
    blocks = torch.tensor(HYBRID.param_blocks, dtype=torch.float64)  # pass k keeps block k only

    def explicit(obs, params):  # Bester et al.'s construction: B * K inputs, K outputs each, Q_k of pass k
        passes = torch.cat([obs.unsqueeze(1).expand(B, K, D), params.unsqueeze(1) * blocks], -1)
        return q_net.net(passes.reshape(B * K, -1)).view(B, K, K).diagonal(dim1=1, dim2=2)

    assert_same_function(q_net, q_net, explicit, *inputs((B, D), (B, sum(SIZES))))


def test_multi_pass_q_loads_a_model_saved_with_the_block_table():
    q_net = QNetwork(D, HYBRID, (7,), "relu", multi_pass=True)
    saved = {**q_net.state_dict(), "blocks": torch.tensor(HYBRID.param_blocks, dtype=torch.float32)}
    fresh = QNetwork(D, HYBRID, (7,), "relu", multi_pass=True)
    fresh.load_state_dict(saved)
    for name, tensor in q_net.state_dict().items():
        assert torch.equal(fresh.state_dict()[name], tensor)


def test_every_action_linear_is_the_layer_on_one_hot_inputs():
    layer = randomised(torch.nn.Linear(D + K, 5))
    obs, a = inputs((B, D))[0], torch.tensor([4, 0, 2, 2, 1, 3])

    def explicit(obs):
        eye = torch.eye(K, dtype=obs.dtype).expand(B, K, K)
        return layer(torch.cat([obs.unsqueeze(1).expand(B, K, D), eye], -1))

    assert_same_function(layer, lambda obs: every_action_linear(obs, layer.weight, layer.bias), explicit, obs)
    chosen = every_action_linear(obs, layer.weight, layer.bias, a)
    torch.testing.assert_close(chosen, layer(torch.cat([obs, F.one_hot(a, K).double()], -1)), rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("pi_c_input", ["onehot", "state"])
@pytest.mark.parametrize("deterministic", [False, True])
def test_policy_acts_as_its_distribution_does_from_the_chosen_action_alone(deterministic, pi_c_input):
    policy = randomised(HybridPolicy(D, HYBRID, (8, 8), pi_c_input=pi_c_input))
    obs = inputs((300, D))[0].detach()
    a, x = policy.act(obs, None, deterministic, torch.Generator().manual_seed(2))
    dist = policy(obs)
    a_ref, x_ref = dist.mode() if deterministic else dist.sample(torch.Generator().manual_seed(2))
    assert torch.equal(a, a_ref)  # the same draws, in the same order
    torch.testing.assert_close(x, x_ref, rtol=1e-12, atol=1e-12)
    assert len(set(a.tolist())) > 1


def test_pasvg_critic_and_parameters_of_every_action_are_the_explicit_ones():
    critic = randomised(TwinQ(D + K + M, 1, (7, 5), "relu"))
    policy = randomised(GumbelHybridPolicy(D, HYBRID, (6,), "tanh", init_log_std=-0.5))
    obs, eta_x = inputs((B, D), (B, M))

    def explicit(obs, eta_x):  # each action's parameters and value from its own [s, onehot(k)] rows
        index = torch.arange(K).expand(B, K)
        onehots = torch.eye(K, dtype=obs.dtype).expand(B, K, K)
        obs_k = obs.unsqueeze(1).expand(B, K, D)
        x = policy.params(obs_k, index, onehots, eta_x.unsqueeze(1))
        return torch.cat([x.flatten(1), critic(obs_k, onehots, x)[0].squeeze(-1)], -1)

    def fast(obs, eta_x):
        obs_k, onehots, x = policy.params_all(obs, eta_x)
        return torch.cat([x.flatten(1), every_action_q(critic)(obs_k, onehots, x)], -1)

    both = torch.nn.ModuleList([critic, policy])
    assert_same_function(both, fast, explicit, obs, eta_x)
    obs_k, onehots, x = policy.params_all(obs, eta_x)
    torch.testing.assert_close(
        every_action_q(critic, smaller=True)(obs_k, onehots, x),
        torch.minimum(*critic(obs_k, onehots, x)).squeeze(-1),
        rtol=1e-12,
        atol=1e-12,
    )


def test_passes_without_gradients_in_chunks_of_states_give_the_whole_batchs_values(monkeypatch):
    policy = randomised(HybridPolicy(D, HYBRID, (8, 8)))
    q_net = randomised(QNetwork(D, HYBRID, (7, 5), "relu", multi_pass=True))
    obs, params = (t.detach() for t in inputs((B, D), (B, sum(SIZES))))
    whole = policy.every_param_mean(obs), q_net(obs, params)  # with gradients: one pass over the batch
    monkeypatch.setattr(policies, "EVERY_ACTION_ROWS", 2 * K)  # two states a chunk
    with torch.no_grad():
        chunked = policy.every_param_mean(obs), q_net(obs, params)
    for w, c in zip(whole, chunked):
        torch.testing.assert_close(c, w.detach(), rtol=1e-12, atol=1e-12)
