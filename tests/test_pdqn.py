"""P-DQN and MP-DQN: the multi-pass Q by hand, which parameters Q_k depends on, the actor's gradient by finite
differences, the hand-written update against autograd's, acting and exploration, replay, a tiny learning run
(save/load, resuming and the CLI: test_algorithms)."""

import dataclasses

import gymnasium
import numpy as np
import pytest
import torch
from conftest import HYBRID, OFF_POLICY_SMALL, assert_update_matches, progress_rows
from numeric import finite_difference
from test_hybrid_plumbing import MaskedLine
from torch import nn

from pamdp import PDQN
from pamdp.algos.offpolicy import OUNoise, backprop_actor, invert_gradients, mixed_target
from pamdp.algos.pdqn import PDQNConfig
from pamdp.policies import DeterministicActor, QNetwork
from pamdp.spaces import HybridActionSpace

SMALL = PDQNConfig(hidden_sizes=(16,), epsilon_steps=300, **OFF_POLICY_SMALL)
# HYBRID's three actions have 1, 2 and 1 parameters: the flat vector is [x_0 | x_1, x_1' | x_2], 4 values.
BLOCKS = [slice(0, 1), slice(1, 3), slice(3, 4)]


def test_parameter_blocks_and_selection_by_hand():
    np.testing.assert_array_equal(HYBRID.param_blocks, [[1, 0, 0, 0], [0, 1, 1, 0], [0, 0, 0, 1]])
    actor = DeterministicActor(5, 4, (8,), "relu", False, HYBRID)
    params = torch.tensor([[0.1, 0.2, 0.3, 0.4]] * 3)
    x = actor.select(params, torch.tensor([0, 1, 2]))
    torch.testing.assert_close(x, torch.tensor([[0.1, 0.0], [0.2, 0.3], [0.4, 0.0]]))


def _separate_passes(q_net, obs, params, blocks=BLOCKS):
    """Bester et al.'s multi-pass by definition: K forward passes of the whole network, pass k on the parameters
    with every block but action k's zeroed, Q_k read from pass k."""
    columns = []
    for k, block in enumerate(blocks):
        only_k = torch.zeros_like(params)
        only_k[:, block] = params[:, block]
        columns.append(q_net.net(torch.cat([obs, only_k], dim=1))[:, k])
    return torch.stack(columns, dim=1)


# One parameter an action, as Platform's: the first layer's per-pass product takes another form (an outer product).
ONE_EACH = HybridActionSpace(
    (np.array([-1.0]), np.array([0.0]), np.array([-2.0])), (np.ones(1), np.ones(1), np.ones(1))
)


def test_multi_pass_q_equals_k_single_action_passes():
    torch.manual_seed(0)
    q_net = QNetwork(5, HYBRID, (8, 8), "relu", multi_pass=True)
    obs, params = torch.randn(6, 5), torch.randn(6, 4)
    torch.testing.assert_close(q_net(obs, params), _separate_passes(q_net, obs, params))
    # Without multi_pass the same weights see the whole vector at once.
    joint = QNetwork(5, HYBRID, (8, 8), "relu", multi_pass=False)
    joint.load_state_dict(q_net.state_dict())
    torch.testing.assert_close(joint(obs, params), q_net.net(torch.cat([obs, params], dim=1)))


@pytest.mark.parametrize("multi_pass", [False, True])
@pytest.mark.parametrize("hidden, activation", [((8,), "relu"), ((8, 6), "tanh"), ((7, 6, 5), "leaky_relu")])
@pytest.mark.parametrize("space, blocks", [(HYBRID, BLOCKS), (ONE_EACH, [slice(0, 1), slice(1, 2), slice(2, 3)])])
def test_hand_written_q_passes_match_autograd_through_the_definition(multi_pass, hidden, activation, space, blocks):
    torch.manual_seed(4)
    q_net = QNetwork(5, space, hidden, activation, multi_pass=multi_pass).double()
    n = space.total_param_size
    obs = torch.randn(6, 5, dtype=torch.float64)
    params = torch.randn(6, n, dtype=torch.float64, requires_grad=True)
    g = torch.randn(6, 3, dtype=torch.float64)
    if multi_pass:
        expected = _separate_passes(q_net, obs, params, blocks)
    else:
        expected = q_net.net(torch.cat([obs, params], dim=1))
    expected.backward(g)
    with torch.no_grad():
        q, cache = q_net.forward_cached(obs, params)
        grads = q_net.backward(cache, g)
        d_params = q_net.backward(cache, g, weights=False)
    torch.testing.assert_close(q, expected.detach())
    for mine, p in zip(grads, q_net.parameters(), strict=True):
        torch.testing.assert_close(mine, p.grad)
    torch.testing.assert_close(d_params, params.grad)


@pytest.mark.parametrize("space, blocks", [(HYBRID, BLOCKS), (ONE_EACH, [slice(0, 1), slice(1, 2), slice(2, 3)])])
def test_float32_multi_pass_equals_the_definition_to_rounding(space, blocks):
    torch.manual_seed(5)
    q_net = QNetwork(5, space, (64, 32), "relu", multi_pass=True)
    obs, params = torch.randn(128, 5), torch.rand(128, space.total_param_size) * 2 - 1
    expected = _separate_passes(q_net, obs, params, blocks)
    torch.testing.assert_close(q_net(obs, params), expected, rtol=1e-5, atol=1e-6)


def test_only_p_dqn_q_depends_on_other_actions_parameters():
    torch.manual_seed(1)
    joint = QNetwork(5, HYBRID, (16,), "tanh", multi_pass=False)
    multi = QNetwork(5, HYBRID, (16,), "tanh", multi_pass=True)
    multi.load_state_dict(joint.state_dict())
    obs, params = torch.randn(8, 5, dtype=torch.float64), torch.randn(8, 4, dtype=torch.float64)
    joint.double(), multi.double()
    h = 1e-4
    for j, block in enumerate(BLOCKS):
        moved = params.clone()
        moved[:, block] += h
        d_joint = (joint(obs, moved) - joint(obs, params)) / h  # (B, K) finite differences along block j
        d_multi = (multi(obs, moved) - multi(obs, params)) / h
        others = [k for k in range(3) if k != j]
        assert d_joint[:, others].abs().min() > 1e-6, j  # P-DQN: Q_k moves with x_j, j != k
        assert torch.all(d_multi[:, others] == 0), j  # MP-DQN: exactly not
        assert d_multi[:, j].abs().min() > 1e-6, j  # ...but Q_j does move with x_j


@pytest.mark.parametrize("multi_pass", [False, True])
def test_actor_gradient_matches_finite_differences_of_sum_of_q(multi_pass):
    torch.manual_seed(2)
    actor = DeterministicActor(5, 4, (6,), "tanh", True, HYBRID).double()
    q_net = QNetwork(5, HYBRID, (6,), "tanh", multi_pass=multi_pass).double()
    obs = torch.randn(4, 5, dtype=torch.float64)
    _, _, grads = backprop_actor(actor, q_net, obs, "squash", list(actor.parameters()))  # Tanh: the plain gradient
    assert all(p.grad is None for p in q_net.parameters())  # Q's weights are not trained by the actor loss

    with torch.no_grad():
        expected = finite_difference(lambda: q_net(obs, actor(obs)).sum(-1).mean().item(), list(actor.parameters()))
    for grad, g in zip(grads, expected):
        torch.testing.assert_close(grad, -g, rtol=1e-6, atol=1e-8)  # descent on -mean sum_k Q_k


def test_inverted_actor_gradient_matches_finite_differences():
    torch.manual_seed(3)
    actor = DeterministicActor(5, 4, (6,), "tanh", False, HYBRID).double()
    with torch.no_grad():
        actor.net[-1].weight.mul_(4.0)  # push some outputs past the bounds, where the inversion flips the sign
    q_net = QNetwork(5, HYBRID, (6,), "tanh", multi_pass=True).double()
    obs = torch.randn(4, 5, dtype=torch.float64)
    _, _, grads = backprop_actor(actor, q_net, obs, "invert", list(actor.parameters()))

    with torch.no_grad():
        p = actor(obs)
        assert (p.abs() > 1).any()
        (dq_dp,) = finite_difference(lambda: q_net(obs, p).sum().item(), [p])  # d(sum_k Q_k)/dx per sample
        g = invert_gradients(dq_dp, p)
        expected = finite_difference(lambda: -(g * actor(obs)).sum().item() / len(obs), list(actor.parameters()))
    for grad, e in zip(grads, expected):
        torch.testing.assert_close(grad, e, rtol=1e-6, atol=1e-8)


@pytest.mark.parametrize("multi_pass", [False, True])
def test_acted_action_is_the_argmax_with_its_own_parameters(multi_pass):
    model = PDQN("pamdp/Platform-v0", dataclasses.replace(SMALL, multi_pass=multi_pass))
    obs = torch.from_numpy(np.random.default_rng(0).uniform(0, 1, size=(64, 9)).astype(np.float32))
    with torch.no_grad():
        a, x = model._act(obs, deterministic=True)
        params = model.actor(obs).clamp(-1, 1)
        q = model.q_net(obs, params)
    np.testing.assert_array_equal(a, q.argmax(-1))
    torch.testing.assert_close(x[:, 0], params[torch.arange(64), a])  # Platform: action k's one parameter is k-th

    env = gymnasium.make("pamdp/Platform-v0")
    o, _ = env.reset(seed=0)
    for _ in range(30):
        action = model.predict(o)
        assert env.action_space.contains(action)
        with torch.no_grad():
            t = torch.from_numpy(np.asarray(o, dtype=np.float32))[None]
            p = model.actor(t).clamp(-1, 1)
            k = int(model.q_net(t, p).argmax())
        assert action[0] == k
        np.testing.assert_allclose(action[1][k], model.hybrid.scale(k, [p[0, k].item()]), rtol=1e-6)
        o, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            o, _ = env.reset()


def test_epsilon_annealing_endpoints_and_exploration():
    model = PDQN("pamdp/Platform-v0", dataclasses.replace(SMALL, epsilon_steps=1000, epsilon_end=0.05))
    assert model.epsilon(0) == 1.0
    assert model.epsilon(500) == pytest.approx(0.525)
    assert model.epsilon(1000) == pytest.approx(0.05) and model.epsilon(10**6) == pytest.approx(0.05)

    obs = torch.from_numpy(np.random.default_rng(0).uniform(0, 1, size=(3000, 9)).astype(np.float32))
    starts = np.zeros(3000, dtype=bool)
    with torch.no_grad():
        greedy, _ = model._act(obs, deterministic=True)
        a, x, extras = model._explore(obs, 0, starts, None)  # epsilon 1: uniform actions
        np.testing.assert_allclose(np.bincount(a.numpy(), minlength=3) / 3000, [1 / 3] * 3, atol=0.04)
        a, _, _ = model._explore(obs, 10**6, starts, None)  # epsilon 0.05: greedy but for about 5% x 2/3
        assert np.mean(a.numpy() != greedy.numpy()) == pytest.approx(0.05 * 2 / 3, abs=0.015)


def test_explore_params_redraws_only_the_random_actions_parameters():
    cfg = dataclasses.replace(SMALL, explore_params=True, ou_sigma=0.0, epsilon_steps=1000)
    model = PDQN("pamdp/Platform-v0", cfg)
    obs = torch.from_numpy(np.random.default_rng(0).uniform(0, 1, size=(2000, 9)).astype(np.float32))
    with torch.no_grad():
        clean = model.actor(obs).clamp(-1, 1)
        a, x, extras = model._explore(obs, 0, np.zeros(2000, dtype=bool), None)
    params = torch.from_numpy(extras["params"])
    chosen = torch.tensor(model.hybrid.param_blocks)[a]
    torch.testing.assert_close(params[~chosen], clean[~chosen])  # the other actions keep the actor's
    drawn = params[chosen].numpy()
    assert drawn.min() < -0.9 and drawn.max() > 0.9 and abs(drawn.mean()) < 0.05  # uniform in [-1, 1]
    torch.testing.assert_close(x[:, 0], params[torch.arange(2000), a])


def test_ou_noise_restarts_per_episode_and_is_gaussian_at_theta_one():
    rng = np.random.default_rng(0)
    gauss = OUNoise(theta=1.0, sigma=0.3)
    draws = np.stack([gauss((2, 3), np.zeros(2, dtype=bool), rng).copy() for _ in range(5000)])
    assert draws.std() == pytest.approx(0.3, rel=0.03)
    assert abs(np.corrcoef(draws[:-1, 0, 0], draws[1:, 0, 0])[0, 1]) < 0.05  # independent steps
    ou = OUNoise(theta=0.15, sigma=0.3)
    draws = np.stack([ou((1, 1), np.zeros(1, dtype=bool), rng).copy() for _ in range(20_000)])[:, 0, 0]
    assert np.corrcoef(draws[:-1], draws[1:])[0, 1] == pytest.approx(0.85, abs=0.02)
    zero_rng = np.random.default_rng(1)
    state = ou((1, 1), np.array([True]), zero_rng)  # a restarted copy: the first step from 0
    assert state[0, 0] == pytest.approx(0.3 * np.random.default_rng(1).standard_normal())


def test_bad_types_from_plain_data_are_named():
    with pytest.raises(ValueError, match="'multi_pass' = 'yes'"):
        PDQNConfig.from_dict({"multi_pass": "yes"})


def test_replay_holds_what_q_saw_and_monte_carlo_returns():
    model = PDQN("pamdp/Platform-v0", dataclasses.replace(SMALL, beta=0.5, ou_sigma=0.2, ou_theta=1.0))
    model.learn(400, progress_bar=False)
    n = len(model.replay)
    d = {k: v[:n].numpy() for k, v in model.replay.data.items()}
    assert np.abs(d["params"]).max() <= 1.0
    np.testing.assert_array_equal(d["x"][:, 0], d["params"][np.arange(n), d["a"]])
    term = d["terminated"]
    np.testing.assert_allclose(d["mc"][term], d["reward"][term], rtol=1e-6)  # last step: return = reward
    assert np.isfinite(d["mc"]).mean() > 0.9


@pytest.mark.parametrize("multi_pass", [False, True])
def test_tiny_learning_run_logs(tmp_path, multi_pass):
    cfg = dataclasses.replace(SMALL, multi_pass=multi_pass, epoch_steps=500, epsilon_steps=1000, updates_per_step=0.25)
    model = PDQN("pamdp/Platform-v0", cfg)
    model.learn(2000, progress_bar=False, run_dir=tmp_path)
    rows = progress_rows(tmp_path)
    assert len(rows) == 4 and (tmp_path / "tb").is_dir() and (tmp_path / "checkpoint.pt").is_file()
    last = rows[-1]
    keys = ("losses/critic_loss", "losses/actor_loss", "train/q_mean", "train/epsilon", "train/updates")
    keys += ("train/outputs_out_of_bounds", "charts/episodic_return", "charts/SPS", "train/action_freq_2")
    for key in keys:
        assert np.isfinite(float(last[key])), key
    assert float(last["train/epsilon"]) == pytest.approx(cfg.epsilon_end)
    assert 0.0 <= float(last["charts/episodic_return"]) <= 1.0


def _autograd_update(model):
    """P-DQN's update on autograd and the modules' own forward: the form its hand-written update must equal."""
    cfg = model.config
    b = model.replay.sample(cfg.batch_size, model.np_rng)
    obs = b["obs"]
    with torch.no_grad():
        y = b["reward"] + cfg.gamma * (~b["terminated"]).float() * model._next_value(b["next_obs"], b.get("next_mask"))
        if cfg.beta > 0:
            y = mixed_target(y, b["mc"], cfg.beta)
    q = model.q_net(obs, b["params"]).gather(1, b["a"][:, None]).squeeze(1)
    model.q_optimizer.zero_grad(set_to_none=True)
    nn.functional.mse_loss(q, y).backward()
    nn.utils.clip_grad_norm_(model.q_net.parameters(), cfg.grad_clip)
    model.q_optimizer.step()
    params = list(model.actor.parameters())
    _, _, grads = backprop_actor(model.actor, model.q_net, obs, cfg.bound, params)
    for p, g in zip(params, grads):
        p.grad = g
    nn.utils.clip_grad_norm_(params, cfg.grad_clip)
    model.actor_optimizer.step()
    with torch.no_grad():
        for target, source, tau in (
            (model.q_target, model.q_net, cfg.tau_q),
            (model.actor_target, model.actor, cfg.tau_actor),
        ):
            for t, s in zip(target.parameters(), source.parameters()):
                t.lerp_(s, tau)


@pytest.mark.parametrize(
    "settings",
    [
        {"multi_pass": True},
        {"multi_pass": False},
        {"multi_pass": True, "bound": "squash", "hidden_sizes": (16, 12), "activation": "tanh", "beta": 0.3},
        {"multi_pass": True, "bound": "zero", "action_mask": True},
        {"multi_pass": False, "hidden_sizes": (16, 12), "activation": "leaky_relu", "action_mask": True},
    ],
)
def test_pdqn_update_matches_the_autograd_update(settings):
    cfg = dataclasses.replace(SMALL, grad_clip=0.5, **settings)
    mine = PDQN(MaskedLine() if cfg.action_mask else "pamdp/Platform-v0", cfg)
    mine.learn(200, progress_bar=False)  # fills the replay and takes updates, so Adam's state exists
    assert_update_matches(mine, _autograd_update)
