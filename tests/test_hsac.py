"""Hybrid SAC: the squashed hybrid distribution's log-probabilities and entropies against torch.distributions,
histograms and quadrature, the target's exact expectation against sampling (masked too), the temperature step,
both forms' layout, and a masked action never chosen (save/load and seeded determinism of both forms:
test_algorithms)."""

import dataclasses
import math

import gymnasium
import numpy as np
import pytest
import torch
from conftest import OFF_POLICY_SMALL
from gymnasium import spaces
from torch.distributions import Normal, TanhTransform, TransformedDistribution

from pamdp import HybridSAC
from pamdp.algos.hsac import HybridSACConfig
from pamdp.algos.offpolicy import temperature_gradient
from pamdp.distributions import SquashedHybrid
from pamdp.policies import HybridSACActor
from pamdp.spaces import HybridActionSpace

SMALL = HybridSACConfig(hidden_sizes=(16, 16), updates_per_step=0.5, **OFF_POLICY_SMALL)
# Three actions with 2, 0 and 1 parameters: padded to m = 2, the all-actions vector [x_0, x_0' | x_2].
HYBRID = HybridActionSpace(
    (np.array([-1.0, 0.0]), np.zeros(0), np.array([-2.0])), (np.array([1.0, 3.0]), np.zeros(0), np.array([2.0]))
)


def _distribution(batch: int) -> SquashedHybrid:
    """One state's distribution over HYBRID's actions, repeated ``batch`` times (unused entries: arbitrary)."""
    logits = torch.tensor([[0.3, -0.2, 0.6]], dtype=torch.float64)
    mean = torch.tensor([[[0.4, -1.1], [7.0, 7.0], [1.3, 7.0]]], dtype=torch.float64)
    log_std = torch.tensor([[[-0.5, 0.2], [3.0, 3.0], [-0.9, 3.0]]], dtype=torch.float64)
    mask = torch.tensor(HYBRID.param_mask, dtype=torch.float64)
    return SquashedHybrid(logits.expand(batch, -1), mean.expand(batch, -1, -1), log_std.expand(batch, -1, -1), mask)


def _squashed_entropy(mu: float, sigma: float) -> float:
    """The differential entropy of tanh(N(mu, sigma)) by quadrature over u: E[-log N(u) + log(1 - tanh(u)^2)]."""
    u = np.linspace(mu - 12 * sigma, mu + 12 * sigma, 200_001)
    density = np.exp(-0.5 * ((u - mu) / sigma) ** 2) / (sigma * math.sqrt(2 * math.pi))
    integrand = density * (-np.log(density + 1e-300) + np.log1p(-(np.tanh(u) ** 2) + 1e-300))
    return float(np.sum(integrand) * (u[1] - u[0]))


def test_log_prob_c_is_torch_tanh_gaussian_and_parameterless_actions_add_nothing():
    dist = _distribution(5)
    u, x = dist.rsample(torch.Generator().manual_seed(0))
    log_pc = dist.log_prob_c(u)
    for a, m in enumerate(HYBRID.param_sizes):
        reference = TransformedDistribution(
            Normal(dist.mean[:, a, :m], dist.log_std[:, a, :m].exp()), [TanhTransform()]
        )
        expected = reference.log_prob(x[:, a, :m]).sum(-1) if m else torch.zeros(5, dtype=torch.float64)
        torch.testing.assert_close(log_pc[:, a], expected)
    assert torch.all(x[:, 1] == 0) and torch.all(x[:, 2, 1] == 0)  # unused entries are zero
    assert torch.all(x.abs() < 1)


def test_hybrid_density_matches_a_histogram_of_samples():
    n = 400_000
    dist = _distribution(n)
    gen = torch.Generator().manual_seed(1)
    a = dist.sample_discrete(gen)
    u, x_all = dist.rsample(gen)
    p = dist.probs_d[0]
    freq = torch.bincount(a, minlength=3).double() / n
    torch.testing.assert_close(freq, p, atol=3e-3, rtol=0)
    # P(a = 2, x within h / 2 of c) / h against pi_d(2) * pi_c(c | 2)
    x2 = x_all[a == 2, 2, 0]
    h = 0.02
    for c in (0.5, 0.7, 0.85, 0.95):
        empirical = ((x2 - c).abs() < h / 2).double().sum() / n / h
        point = torch.tensor([[[0.0, 0.0], [0.0, 0.0], [math.atanh(c), 0.0]]], dtype=torch.float64)
        density = p[2] * _one(dist, point)[2].exp()
        assert float(empirical) == pytest.approx(float(density), rel=0.06), c
    # action 0's two parameters: a box of side 2h around a point
    x0 = x_all[a == 0, 0]
    h = 0.05
    for c in ((0.2, -0.6), (0.5, -0.9)):
        inside = ((x0 - torch.tensor(c, dtype=torch.float64)).abs() < h).all(-1)
        empirical = inside.double().sum() / n / (2 * h) ** 2
        point = torch.tensor([[[math.atanh(c[0]), math.atanh(c[1])], [0.0, 0.0], [0.0, 0.0]]], dtype=torch.float64)
        assert float(empirical) == pytest.approx(float(p[0] * _one(dist, point)[0].exp()), rel=0.08), c


def _one(dist: SquashedHybrid, u: torch.Tensor) -> torch.Tensor:
    """``log pi_c`` of every action at pre-squash values ``u`` (1, K, m), for the first state of ``dist``."""
    first = SquashedHybrid(dist.logits[:1], dist.mean[:1], dist.log_std[:1], dist.param_mask)
    return first.log_prob_c(u)[0]


def test_entropies_match_quadrature():
    n = 200_000
    dist = _distribution(n)
    gen = torch.Generator().manual_seed(2)
    u, _ = dist.rsample(gen)
    a = dist.sample_discrete(gen)
    mean, std = dist.mean[0], dist.log_std[0].exp()
    h_c = [
        sum(_squashed_entropy(float(mean[k, i]), float(std[k, i])) for i in range(m)) for k, m in enumerate([2, 0, 1])
    ]
    estimate = -dist.log_prob_c(u).mean(0)  # the single-draw estimates the updates use, averaged
    torch.testing.assert_close(estimate, torch.tensor(h_c, dtype=torch.float64), atol=0.01, rtol=0)
    p = dist.probs_d[0].numpy()
    joint = -(p * np.log(p)).sum() + float(np.dot(p, h_c))  # the chain rule: H(pi_d) + sum_a pi_d(a) H_c(a)
    sampled = -(dist.log_probs_d.gather(1, a[:, None]).squeeze(1) + dist.log_prob_c(u).gather(1, a[:, None]).squeeze(1))
    assert float(sampled.mean()) == pytest.approx(joint, abs=0.01)
    assert float(dist.entropy_d()[0]) == pytest.approx(-(p * np.log(p)).sum(), abs=1e-12)


@pytest.mark.parametrize("form", ["flat", "hierarchical"])
def test_forms_lay_out_every_actions_parameters(form):
    torch.manual_seed(3)
    actor = HybridSACActor(4, HYBRID, form, (8,), "tanh")
    obs = torch.randn(6, 4)
    dist = actor(obs)
    assert dist.logits.shape == (6, 3) and dist.mean.shape == (6, 3, 2)
    x = torch.randn(6, 3, 2) * actor.param_mask
    flat = actor.flat_params(x)
    torch.testing.assert_close(flat, torch.stack([x[:, 0, 0], x[:, 0, 1], x[:, 2, 0]], -1))
    if form == "flat":  # the network's raw outputs: [logits 3 | means 3 | log-stds 3], means placed per action
        with torch.no_grad():
            actor.net[-1].bias.copy_(torch.arange(9.0) / 10)
        dist = actor(obs)
        raw = actor.net(obs)
        torch.testing.assert_close(dist.mean[:, 0], raw[:, 3:5])
        torch.testing.assert_close(dist.mean[:, 2, 0], raw[:, 5])
        torch.testing.assert_close(dist.log_std[:, 2, 0], raw[:, 8])
    else:  # pi_c(x | s, a) depends on a through the one-hot
        with torch.no_grad():
            actor.pi_c[-1].weight.normal_()
        dist = actor(obs)
        onehot = torch.eye(3)[2].expand(6, -1)
        torch.testing.assert_close(dist.mean[:, 2, 0], actor.pi_c(torch.cat([obs, onehot], -1))[:, 0])
        assert not torch.allclose(dist.mean[:, 0, 0], dist.mean[:, 2, 0])


def test_every_action_with_all_parameters_lays_out_and_draws_as_the_masked_layout_does():
    """Where every action has all m parameters (Hard Move's layout) the actor skips the gathers and the mask: its
    means and log-stds are the network's outputs in order, action by action, and its draws and log-densities those
    of the same distribution with an all-ones mask."""
    dense = HybridActionSpace((-np.ones(2),) * 3, (np.ones(2),) * 3)
    torch.manual_seed(4)
    actor = HybridSACActor(4, dense, "flat", (8,), "tanh")
    with torch.no_grad():
        actor.net[-1].bias.copy_(torch.arange(15.0) / 10)
    obs = torch.randn(5, 4)
    dist, raw = actor(obs), actor.net(obs)
    for a in range(3):
        torch.testing.assert_close(dist.mean[:, a], raw[:, 3 + 2 * a : 5 + 2 * a])
        torch.testing.assert_close(dist.log_std[:, a], raw[:, 9 + 2 * a : 11 + 2 * a].clamp(-5, 2))
    masked = SquashedHybrid(dist.logits, dist.mean, dist.log_std, torch.ones(3, 2))
    (u, x), (u_m, x_m) = (d.rsample(torch.Generator().manual_seed(1)) for d in (dist, masked))
    torch.testing.assert_close(x, x_m)
    torch.testing.assert_close(dist.log_prob_c(u), masked.log_prob_c(u_m))
    torch.testing.assert_close(actor.flat_params(x), torch.cat([x[:, 0], x[:, 1], x[:, 2]], -1))
    torch.testing.assert_close(dist.mode()[1], masked.mode()[1])


def _model(**changes) -> HybridSAC:
    return HybridSAC("pamdp/Platform-v0", dataclasses.replace(SMALL, **changes))


@pytest.mark.parametrize("masked", [False, True])
def test_target_is_the_exact_expectation_over_next_actions(masked):
    model = _model(init_alpha_d=0.3, init_alpha_c=0.2)
    with torch.no_grad():  # a target critic that tells the actions apart, and a pi_d far from uniform
        for p in model.critic_target.parameters():
            p.normal_(0, 0.5)
        model.actor.net[-1].bias[:3] = torch.tensor([1.0, -0.5, 0.2])
    n = 100_000
    state = torch.from_numpy(np.random.default_rng(4).uniform(0, 1, size=(1, 9)).astype(np.float32))
    obs = state.expand(n, -1)
    mask = torch.tensor([[True, False, True]]).expand(n, -1) if masked else None
    # sampling the next action from pi_d instead, with its own parameters; log-probabilities written out here
    with torch.no_grad():
        dist = model.actor(obs, mask)
        a, _, x_all = model._sample(dist)
        u = torch.atanh(x_all.clamp(-1 + 1e-6, 1 - 1e-6).double())
        logits = model.actor.net(state)[0, :3].double()
        if masked:
            logits[1] = -math.inf
        log_pd = torch.log_softmax(logits, 0)[a]
        mean, std = dist.mean.double(), dist.log_std.double().exp()
        chosen = torch.arange(n), a
        normal = Normal(mean[chosen][:, 0], std[chosen][:, 0])
        log_pc = normal.log_prob(u[chosen][:, 0]) - torch.log1p(-(x_all[chosen][:, 0].double() ** 2))
        q1, q2 = model.critic_target(obs, model.actor.flat_params(x_all))
        q = torch.minimum(q1, q2)[chosen].double()
        sampled = q - 0.2 * log_pc - 0.3 * log_pd
        exact = model.target_value(obs, mask)
    assert not masked or not (a == 1).any()
    error = 4 * math.sqrt((float(sampled.var()) + float(exact.var())) / n)
    assert float(exact.mean()) == pytest.approx(float(sampled.mean()), abs=error)
    # without the mask the two differ by more than that: action 1 weighs in
    if masked:
        unmasked = model.target_value(obs).mean()
        assert abs(float(unmasked) - float(exact.mean())) > 3 * error


def test_temperature_gradient_sign_and_fixed_point():
    entropy = torch.tensor([0.7, 0.9, 1.4])
    log_alpha = torch.tensor(0.3, dtype=torch.float64)
    loss = lambda la: float((la * (entropy.double() - 0.5)).mean())  # noqa: E731
    fd = (loss(log_alpha + 1e-6) - loss(log_alpha - 1e-6)) / 2e-6
    assert float(temperature_gradient(entropy, 0.5)) == pytest.approx(fd)
    model = _model(alpha_lr=0.01)
    start = model.alphas
    hot = torch.full((8,), 2.0)  # both parts more random than their targets: both temperatures fall
    model.temperatures.step(model.alpha_optimizer, (hot, 1.0), (hot, 1.0))
    assert model.alphas[0] < start[0] and model.alphas[1] < start[1]
    after = model.alphas
    model.temperatures.step(
        model.alpha_optimizer, (torch.zeros(8), 1.0), (torch.full((8,), -3.0), -2.0)
    )  # less random: both rise
    assert model.alphas[0] > after[0] and model.alphas[1] > after[1]
    fixed = _model(alpha_lr=0.01)
    at_target = torch.tensor([0.5, 1.5])  # mean 1.0: the target
    fixed.temperatures.step(fixed.alpha_optimizer, (at_target, 1.0), (at_target - 3.0, -2.0))
    assert fixed.alphas == pytest.approx(start, abs=1e-7)


class _MaskedEnv(gymnasium.Env):
    """Three actions with 2, 0 and 1 parameters; action 0 pays but is forbidden in every other state, action 2 in
    states where the observation's first entry is negative. Counts the forbidden actions taken."""

    observation_space = spaces.Box(-1.0, 1.0, (2,), np.float32)
    action_space = HYBRID.to_gym()
    forbidden_taken = 0

    def _obs(self):
        self.mask = np.array([self.t % 2 == 0, True, self.state[0] >= 0])
        return self.state, {"action_mask": self.mask.copy()}

    def reset(self, seed=None, options=None):
        super().reset(seed=seed)
        self.t, self.state = 0, self.np_random.uniform(-1, 1, 2).astype(np.float32)
        return self._obs()

    def step(self, action):
        a = int(action[0])
        type(self).forbidden_taken += int(not self.mask[a])
        self.t += 1
        self.state = self.np_random.uniform(-1, 1, 2).astype(np.float32)
        obs, info = self._obs()
        return obs, float(a == 0), False, self.t >= 10, info


def test_masked_actions_are_never_chosen():
    env = gymnasium.vector.SyncVectorEnv([_MaskedEnv for _ in range(4)])
    cfg = dataclasses.replace(SMALL, action_mask=True, alpha_lr=0.01)
    model = HybridSAC(env, cfg).learn(600, progress_bar=False)
    assert _MaskedEnv.forbidden_taken == 0 and len(model.replay) >= 600
    counts = np.bincount(model.replay.data["a"][: len(model.replay)].numpy(), minlength=3)
    assert counts.min() > 0  # every action was taken where allowed
    # acting from states whose masks forbid what pi_d prefers
    with torch.no_grad():
        model.actor.net[-1].bias[:3] = torch.tensor([5.0, -5.0, 5.0])
    obs = torch.zeros(2000, 2)
    mask = torch.tensor([[False, True, False]]).expand(2000, -1)
    for deterministic in (True, False):
        a, _ = model._act(obs, deterministic, mask)
        assert torch.all(a == 1)
    a, _ = model._act(obs, False, torch.tensor([[True, True, False]]).expand(2000, -1))
    assert not (a == 2).any()
