"""The hand-written passes of pamdp.nn.dense against autograd, and PADDPG's update built on them against
the autograd update it replaced."""

import copy
import dataclasses

import pytest
import torch
from conftest import assert_update_matches
from test_hybrid_plumbing import MaskedLine
from torch import nn

from pamdp import PADDPG, PASVG0
from pamdp.algos.offpolicy import backprop_actor
from pamdp.algos.paddpg import PADDPGConfig
from pamdp.algos.pasvg import PASVG0Config
from pamdp.nn.dense import Dense
from pamdp.nn.optim import clip_grads, optimizer_step
from pamdp.policies import mlp


def _net(activation, output=None, seed=0):
    torch.manual_seed(seed)
    return mlp(7, (16, 12), 5, activation, output)


@pytest.mark.parametrize("activation", ["relu", "leaky_relu", "tanh", "elu"])
@pytest.mark.parametrize("output", [None, nn.Tanh])
def test_backward_matches_autograd(activation, output):
    net = _net(activation, output)
    x = torch.randn(9, 7, requires_grad=True)
    g = torch.randn(9, 5)
    out = net(x)
    out.backward(g)
    dense = Dense.of(net)
    with torch.no_grad():
        y, cache = dense.forward_cached(x)
        grads, dx = dense.backward(cache, g, inputs=True)
    torch.testing.assert_close(y, out.detach())
    torch.testing.assert_close(dense(x.detach()), out.detach())
    for p, mine in zip(net.parameters(), grads, strict=True):
        torch.testing.assert_close(mine, p.grad)
    torch.testing.assert_close(dx, x.grad)
    _, none = dense.backward(cache, g)  # the input gradient only when asked for
    assert none is None


def test_backward_matches_finite_differences():
    net = _net("tanh").double()
    x = torch.randn(3, 7, dtype=torch.float64)
    g = torch.randn(3, 5, dtype=torch.float64)
    dense = Dense.of(net)
    with torch.no_grad():
        _, cache = dense.forward_cached(x)
        grads, _ = dense.backward(cache, g)
        w = net[2].weight  # the middle layer
        i, j, eps = 4, 7, 1e-6
        w[i, j] += eps
        up = (dense(x) * g).sum()
        w[i, j] -= 2 * eps
        down = (dense(x) * g).sum()
        w[i, j] += eps
    assert grads[2][i, j].item() == pytest.approx(((up - down) / (2 * eps)).item(), rel=1e-6)


def test_regression_step_is_the_autograd_step_on_the_mean_squared_error():
    torch.manual_seed(2)
    net = mlp(7, (16,), 1, "tanh")
    twin = copy.deepcopy(net)
    x, y = torch.randn(9, 7), torch.randn(9)
    opt_a, opt_b = (torch.optim.SGD(n.parameters(), lr=0.1) for n in (net, twin))
    loss = ((net(x).squeeze(-1) - y) ** 2).mean()
    loss.backward()
    nn.utils.clip_grad_norm_(net.parameters(), 0.5)
    opt_a.step()
    with torch.no_grad():
        q, error = Dense.of(twin).regression_step(opt_b, x, y, 0.5)
    assert float((error**2).mean()) == pytest.approx(float(loss.detach()))
    torch.testing.assert_close(error, q - y)
    for a, b in zip(net.parameters(), twin.parameters()):
        torch.testing.assert_close(a, b)


def test_layers_it_cannot_apply_are_refused():
    with pytest.raises(TypeError, match="Dropout"):
        Dense.of(nn.Sequential(nn.Linear(3, 4), nn.Dropout(0.1), nn.Linear(4, 1)))


def test_optimizer_step_is_adams_own_step():
    torch.manual_seed(1)
    a = nn.Linear(5, 3)
    b = copy.deepcopy(a)
    opt_a = torch.optim.Adam(a.parameters(), lr=0.1, betas=(0.95, 0.999), fused=True)
    opt_b = torch.optim.Adam(b.parameters(), lr=0.1, betas=(0.95, 0.999), fused=True)
    for _ in range(4):  # the first step initialises the state through Adam's own step, the rest take the kernel
        grads = [torch.randn_like(p) * 5 for p in a.parameters()]
        for p, g in zip(a.parameters(), grads):
            p.grad = g.clone()
        nn.utils.clip_grad_norm_(a.parameters(), 1.0)
        opt_a.step()
        mine = [g.clone() for g in grads]
        clip_grads(mine, 1.0)
        optimizer_step(opt_b, mine)
        for pa, pb in zip(a.parameters(), b.parameters()):
            torch.testing.assert_close(pa, pb)
    assert opt_b.state[b.weight]["step"].item() == 4
    torch.testing.assert_close(opt_a.state[a.weight]["exp_avg_sq"], opt_b.state[b.weight]["exp_avg_sq"])


SMALL = PADDPGConfig(hidden_sizes=(32, 24), learning_starts=64, batch_size=16, epoch_steps=200, beta=0.3)


def _autograd_update(model):
    """PADDPG's update on autograd: the form its hand-written update must equal (with action masks, the critic
    sees a forbidden action's score at -1)."""
    cfg = model.config
    batch = model.replay.sample(cfg.batch_size, model.np_rng)
    obs, next_obs = batch["obs"], batch["next_obs"]
    with torch.no_grad():
        out_next = model._masked(model.actor_target(next_obs).clamp(-1.0, 1.0), batch.get("next_mask"))
        q_next = model.critic_target.smaller(next_obs, out_next).squeeze(-1)
        y = batch["reward"] + cfg.gamma * (~batch["terminated"]).float() * q_next
        y = torch.where(torch.isnan(batch["mc"]), y, cfg.beta * batch["mc"].nan_to_num() + (1 - cfg.beta) * y)
    q = model.critic.smaller(obs, batch["out"]).squeeze(-1)
    model.critic_optimizer.zero_grad(set_to_none=True)
    model.actor_optimizer.zero_grad(set_to_none=True)
    (q - y).square().mean().backward()
    nn.utils.clip_grad_norm_(model.critic.parameters(), cfg.grad_clip)
    model.critic_optimizer.step()
    params = list(model.actor.parameters())
    _, _, grads = backprop_actor(
        lambda o: model._masked(model.actor(o), batch.get("mask")),
        lambda o, out: model.critic.smaller(o, out).squeeze(-1),
        obs,
        cfg.bound,
        params,
    )
    for p, g in zip(params, grads):
        p.grad = g
    nn.utils.clip_grad_norm_(model.actor.parameters(), cfg.grad_clip)
    model.actor_optimizer.step()
    with torch.no_grad():
        for target, source in ((model.critic_target, model.critic), (model.actor_target, model.actor)):
            for t, s in zip(target.parameters(), source.parameters()):
                t.lerp_(s, cfg.tau)


@pytest.mark.parametrize("bound, masked", [("invert", False), ("squash", False), ("zero", False), ("invert", True)])
def test_paddpg_update_matches_the_autograd_update(bound, masked):
    cfg = dataclasses.replace(SMALL, bound=bound, grad_clip=0.5, activation="leaky_relu", action_mask=masked)
    mine = PADDPG(MaskedLine() if masked else "pamdp/Platform-v0", cfg)
    mine.learn(200, progress_bar=False)  # fills the replay and takes ~140 updates, so Adam's state exists
    assert_update_matches(mine, _autograd_update)


SVG_SMALL = PASVG0Config(hidden_sizes=(32, 24), learning_starts=64, batch_size=16, epoch_steps=200, grad_clip=0.5)


@pytest.mark.parametrize(
    "settings",
    [
        {},  # the paper's: straight-through, learned log-std, no entropy bonus
        {"straight_through": False, "entropy_coef": 0.05, "activation": "tanh"},
        {"learn_std": False, "temperature": 0.5, "init_log_std": 2.0},  # log-std at the clamp's bound
        {"action_mask": True, "entropy_coef": 0.05},  # on an env that forbids an action in some states
    ],
)
def test_pasvg_update_matches_the_autograd_update(settings):
    cfg = dataclasses.replace(SVG_SMALL, **settings)
    mine = PASVG0(MaskedLine() if cfg.action_mask else "pamdp/Platform-v0", cfg)
    mine.learn(200, progress_bar=False)
    ref = copy.deepcopy(mine)
    ref._bind_networks()  # its soft update over its own copies
    ref._dense = None  # the autograd update
    for _ in range(30):  # both draw the same batch and noise from their (equal) random streams
        stats = mine._update()
        ref_stats = ref._update()
    assert stats.keys() == ref_stats.keys() and list(stats) == list(ref_stats)  # the same log columns
    for key in stats:
        assert stats[key] == pytest.approx(ref_stats[key], rel=1e-4, abs=1e-6), key
    for name, module in mine._modules().items():
        for (pname, p), q in zip(module.named_parameters(), ref._modules()[name].parameters()):
            torch.testing.assert_close(p, q, atol=2e-6, rtol=1e-4, msg=f"{name}.{pname}")
