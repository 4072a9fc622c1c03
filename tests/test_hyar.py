"""HyAR-TD3: decoding by hand, the VAE's loss against closed forms, the latent bounds against NumPy, the
representation learning to reconstruct, relabelling, TD3's target and policy delay by hand, the warm-up, resuming
without the replay, a tiny learning run (save/load, resuming and the CLI as every algorithm: test_algorithms)."""

import dataclasses

import numpy as np
import pytest
import torch
from conftest import HYBRID, progress_rows
from numeric import finite_difference

from pamdp import HyAR
from pamdp.algos.hyar import ActionRepresentation, HyARConfig, latent_bounds
from pamdp.algos.offpolicy import backprop_actor, invert_gradients

SMALL = HyARConfig(
    num_envs=4,
    embed_dim=3,
    latent_dim=2,
    hidden_sizes=(16,),
    vae_hidden_sizes=(16, 16),
    epoch_steps=200,
    warmup_steps=150,
    warmup_updates=20,
    vae_interval=50,
    vae_updates=3,
    batch_size=16,
    vae_batch_size=16,
    lsc_samples=100,
    buffer_size=5_000,
    updates_per_step=0.25,
)


def representation(seed=0, **kw):
    torch.manual_seed(seed)
    args = dict(obs_dim=5, hybrid=HYBRID, embed_dim=3, latent_dim=2, hidden_sizes=(16, 16), activation="relu")
    return ActionRepresentation(**{**args, **kw}).double()


def test_decoding_picks_the_nearest_embedding_and_masks_unused_parameters():
    rep = representation()
    with torch.no_grad():
        rep.embedding.copy_(torch.tensor([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]]))
    e = torch.tensor([[0.9, 0.2, 0.0], [0.4, 0.6, 0.0], [0.0, 0.0, -0.1], [0.6, 0.5, 0.1]], dtype=torch.float64)
    expected = np.linalg.norm(e.numpy()[:, None] - rep.embedding.detach().numpy()[None], axis=-1).argmin(1)
    np.testing.assert_array_equal(rep.nearest_action(e), expected)
    obs, z = torch.randn(4, 5, dtype=torch.float64), torch.randn(4, 2, dtype=torch.float64)
    a, x = rep.decode(obs, torch.cat([e, z], -1))
    np.testing.assert_array_equal(a, expected)
    assert torch.all(x.abs() <= 1) and torch.all(x[a != 1, 1] == 0)  # actions 0 and 2 have one parameter
    torch.testing.assert_close(x, rep.decode_params(obs, a, z))


def test_loss_terms_match_closed_forms():
    rep = representation(1)
    obs, nxt = torch.randn(32, 5, dtype=torch.float64), torch.randn(32, 5, dtype=torch.float64)
    a, x = torch.randint(0, 3, (32,)), torch.rand(32, 2, dtype=torch.float64) * 2 - 1
    x = x * rep.mask[a]
    total, terms = rep.loss(obs, a, x, nxt, 0.3, 2.0, torch.Generator().manual_seed(5))
    mean, log_std = rep.encode(obs, a, x)
    q = torch.distributions.Normal(mean, log_std.exp())
    kl = torch.distributions.kl_divergence(q, torch.distributions.Normal(0.0, 1.0)).sum(-1).mean()
    z = mean + log_std.exp() * torch.randn(mean.shape, generator=torch.Generator().manual_seed(5), dtype=mean.dtype)
    recon = ((rep.decode_params(obs, a, z) - x) ** 2).sum(-1).mean()  # unused slots: both zero
    h = rep.act(rep.decoder(torch.cat([obs, z, rep.embedding[a]], -1)))
    dynamics = ((rep.dynamics_head(h) - (nxt - obs)) ** 2).mean()
    assert terms["kl"] == pytest.approx(kl.item()) and terms["recon"] == pytest.approx(recon.item())
    assert terms["dynamics"] == pytest.approx(dynamics.item())
    assert total.item() == pytest.approx((recon + 0.3 * kl + 2.0 * dynamics).item())


def test_latent_bounds_are_the_central_percentiles():
    latents = torch.from_numpy(np.random.default_rng(0).standard_normal((1000, 4)) * [1, 2, 3, 4])
    low, high = latent_bounds(latents, 90.0)
    np.testing.assert_allclose(low, np.percentile(latents.numpy(), 5, axis=0))
    np.testing.assert_allclose(high, np.percentile(latents.numpy(), 95, axis=0))
    low, high = latent_bounds(latents, 100.0)
    np.testing.assert_allclose(low, latents.min(0).values)
    np.testing.assert_allclose(high, latents.max(0).values)


def test_representation_learns_to_reconstruct_parameters_from_the_latent():
    """Trained on uniformly random actions, encoding then decoding gives back the parameters (they are not
    predictable from the state, so the latent must carry them)."""
    rep = representation(2).float()
    opt = torch.optim.Adam(rep.parameters(), lr=3e-3)
    gen = torch.Generator().manual_seed(0)
    effect = torch.randn(3, 2, 5, generator=gen)  # the state change is linear in the executed parameters

    def batch(n):
        obs = torch.randn(n, 5, generator=gen)
        a = torch.randint(0, 3, (n,), generator=gen)
        x = (torch.rand(n, 2, generator=gen) * 2 - 1) * rep.mask[a]
        return obs, a, x, obs + torch.einsum("nm,nmd->nd", x, effect[a])

    for _ in range(600):
        loss, _ = rep.loss(*batch(64), 0.01, 1.0, gen)
        opt.zero_grad()
        loss.backward()
        opt.step()
    obs, a, x, _ = batch(2000)
    with torch.no_grad():
        a_dec, x_dec = rep.decode(obs, rep.latent(obs, a, x))
    assert torch.equal(a_dec, a)  # every action's own embedding decodes to it
    assert (x_dec - x).abs().mean() < 0.1  # uniform parameters: 0.5 mean error if the latent were ignored


def model(**kw):
    return HyAR("pamdp/Platform-v0", dataclasses.replace(SMALL, **kw))


def test_warm_up_acts_uniformly_and_its_latents_are_reencoded():
    m = model(warmup_steps=3000, epoch_steps=2000, buffer_size=6000, num_envs=64, vae_updates=0, updates_per_step=0.05)
    obs = torch.from_numpy(np.random.default_rng(0).uniform(0, 1, size=(3000, 9)).astype(np.float32))
    a, x, extras = m._explore(obs, 0, np.zeros(3000, dtype=bool), None)
    np.testing.assert_allclose(np.bincount(a.numpy(), minlength=3) / 3000, [1 / 3] * 3, atol=0.04)
    assert x.min() < -0.95 and x.max() > 0.95 and abs(float(x.mean())) < 0.05
    with pytest.warns(UserWarning, match="makes no gradient update"):  # replay only, as meant
        m.learn(2000, progress_bar=False)
    assert not m.pretrained and m.n_updates == 0  # no update before the warm-up ends
    m.learn(2000, progress_bar=False)
    assert m.pretrained and m.n_updates > 0
    n = 3000  # the warm-up transitions: their stored latents were re-encoded after the pre-training
    d = {k: v[:n] for k, v in m.replay.data.items()}
    with torch.no_grad():
        encoded = m.rep.latent(d["obs"], d["a"], d["x"])
    torch.testing.assert_close(m.replay.data["latent"][:n], encoded)  # no round since (vae_updates 0)
    assert torch.all(m.actor.high > m.actor.low) and torch.equal(m.actor.low, m.actor_target.low)


@pytest.mark.parametrize("remap", [True, False])
def test_lsc_remap_keeps_the_actors_latents_when_the_box_moves(remap):
    m = model(bound="invert", lsc_remap=remap)
    m.learn(400, progress_bar=False)
    assert m.pretrained
    obs = torch.from_numpy(np.random.default_rng(1).uniform(0, 1, size=(50, 9)).astype(np.float32))
    with torch.no_grad():
        before = [actor.to_latent(actor(obs)) for actor in (m.actor, m.actor_target)]
        box = m.actor.low.clone(), m.actor.high.clone()
        for p in m.rep.parameters():  # a representation that has moved: its latents, and so the box, change
            p.mul_(1.5)
    m.train_representation(0)  # no update; new bounds from the changed representation
    assert not torch.allclose(m.actor.low, box[0]) and not torch.allclose(m.actor.high, box[1])
    with torch.no_grad():
        after = [actor.to_latent(actor(obs)) for actor in (m.actor, m.actor_target)]
    for b, a in zip(before, after):
        if remap:
            torch.testing.assert_close(a, b, atol=1e-5, rtol=1e-5)
        else:
            assert (a - b).abs().max() > 1e-2


def test_epsilon_draws_embeddings_uniformly_and_anneals():
    m = model(warmup_steps=1, epsilon_start=1.0, epsilon_end=0.2, epsilon_steps=1000, exploration_noise=0.0)
    assert (m.epsilon(0), m.epsilon(500), m.epsilon(10**6)) == (1.0, pytest.approx(0.6), pytest.approx(0.2))
    obs = torch.from_numpy(np.random.default_rng(0).uniform(0, 1, size=(3000, 9)).astype(np.float32))
    with torch.no_grad():
        greedy = m.actor.to_latent(m.actor(obs))
        a, x, extras = m._explore(obs, 1, np.zeros(3000, dtype=bool), None)  # past the warm-up, epsilon ~1
    latent = torch.from_numpy(extras["latent"])
    np.testing.assert_allclose(np.bincount(a.numpy(), minlength=3) / 3000, [1 / 3] * 3, atol=0.04)
    torch.testing.assert_close(latent[:, :3], m.rep.embedding[a].detach())  # exactly the drawn action's row
    torch.testing.assert_close(latent[:, 3:], greedy[:, 3:])  # the parameters' latent is the actor's
    with torch.no_grad():
        torch.testing.assert_close(x, m.rep.decode(obs, latent)[1])
        a_late, _, extras = m._explore(obs, 10**6, np.zeros(3000, dtype=bool), None)  # epsilon 0.2
    replaced = (torch.from_numpy(extras["latent"])[:, :3] != greedy[:, :3]).any(-1).float().mean()
    assert float(replaced) == pytest.approx(0.2, abs=0.03)


def test_exploration_noise_falls_from_its_start_after_the_warm_up():
    """The spread of explored actor outputs around a greedy one at 0, in the actor's [-1, 1] units: the start's std
    at the end of the warm-up, the schedule's midpoint halfway, exploration_noise after it (HyAR's schedule)."""
    m = model(warmup_steps=100, exploration_noise=0.05, exploration_noise_start=0.35, exploration_noise_steps=1000)
    u = torch.zeros(20_000, m.latent_size)  # the clamp at +-1 is 2.9 start stds away: it trims nothing measurable
    for step, std in ((0, 0.35), (100, 0.35), (600, 0.2), (1100, 0.05), (10**6, 0.05)):
        explored = m._noisy(u, step)
        assert explored.std().item() == pytest.approx(std, rel=0.03), step
        assert abs(explored.mean().item()) < 0.01
    constant = model(exploration_noise=0.05, exploration_noise_start=0.35)  # no schedule: exploration_noise always
    assert constant._noisy(u, 0).std().item() == pytest.approx(0.05, rel=0.03)


def test_relabelling_replaces_exactly_the_stale_latents():
    m = model()
    gen = torch.Generator().manual_seed(0)
    obs = torch.rand(64, 9, generator=gen)
    a = torch.randint(0, 3, (64,), generator=gen)
    x = torch.rand(64, 1, generator=gen) * 2 - 1
    with torch.no_grad():
        current = m.rep.latent(obs, a, x)
        x_current = m.rep.decode(obs, current)[1]
    # Valid rows store the latent whose decoding is what was executed; stale rows store a far-away latent.
    stored = current.clone()
    stored[32:, :3] = m.rep.embedding[(a[32:] + 1) % 3].detach()  # another action's embedding
    batch = {"obs": obs, "a": a, "x": x_current, "latent": stored}
    out, fraction = m.relabel(batch)
    torch.testing.assert_close(out[:32], stored[:32], rtol=0, atol=0)
    with torch.no_grad():
        torch.testing.assert_close(out[32:], m.rep.latent(obs, a, x_current)[32:])  # what was executed, encoded now
    assert fraction == 0.5
    with torch.no_grad():  # parameters beyond the tolerance are stale too
        far = dict(batch, x=(x_current + 0.5).clamp(-1, 1))
    moved = (far["x"] - x_current).abs().amax(-1) > m.config.relabel_tolerance
    out, fraction = m.relabel(far)
    assert fraction == pytest.approx(float((moved | (torch.arange(64) >= 32)).float().mean()))
    m_all, m_none = model(relabel="all"), model(relabel="none")
    m_all.rep.load_state_dict(m.rep.state_dict())
    with torch.no_grad():
        torch.testing.assert_close(m_all.relabel(batch)[0], m.rep.latent(obs, a, x_current))
    assert m_none.relabel(batch) == (stored, 0.0)


@pytest.mark.parametrize("beta", [0.0, 0.4])
def test_td3_critic_loss_by_hand_and_the_policy_delay(beta):
    """TD3's target by hand; with ``beta`` > 0, Hausknecht & Stone's mix of it with the Monte-Carlo return where an
    episode's end made that known (NaN where not)."""
    m = model(target_noise=0.0, policy_delay=2, beta=beta)
    m.learn(200, progress_bar=False)  # warm-up done and a few updates
    mc = m.replay.data["mc"][: len(m.replay)] if beta else None  # the returns of the episodes that ended
    assert not beta or (torch.isfinite(mc).any() and torch.isnan(mc).any())
    gen = torch.Generator().manual_seed(1)
    b = {
        "obs": torch.rand(16, 9, generator=gen),
        "a": torch.randint(0, 3, (16,), generator=gen),
        "x": torch.rand(16, 1, generator=gen) * 2 - 1,
        "reward": torch.rand(16, generator=gen),
        "next_obs": torch.rand(16, 9, generator=gen),
        "terminated": torch.rand(16, generator=gen) < 0.3,
        "latent": torch.zeros(16, m.latent_size),
    }
    if beta:
        mc = torch.rand(16, generator=gen) * 3
        b["mc"] = torch.where(torch.arange(16) % 3 == 0, torch.nan, mc)
    m.replay.sample = lambda n, rng, first=0: b
    m.config = dataclasses.replace(m.config, vae_updates=0)  # no representation round inside these updates
    m.n_updates = 10  # the next update (11) is odd: critics only
    with torch.no_grad():
        latent, _ = m.relabel(b)
        latent_next = m.actor_target.to_latent(m.actor_target(b["next_obs"]))
        q1n, q2n = (q.squeeze(-1) for q in m.critic_target(b["next_obs"], latent_next))
        y = b["reward"] + m.config.gamma * (~b["terminated"]).float() * torch.minimum(q1n, q2n)
        if beta:
            y = torch.tensor([t if i % 3 == 0 else beta * b["mc"][i] + (1 - beta) * t for i, t in enumerate(y)])
        q1, q2 = (q.squeeze(-1) for q in m.critic(b["obs"], latent))
        expected = ((q1 - y) ** 2).mean() + ((q2 - y) ** 2).mean()
    actor_before = [p.clone() for p in m.actor.parameters()]
    target_before = [p.clone() for p in m.critic_target.parameters()]
    stats = m._update()
    assert stats["losses/critic_loss"] == pytest.approx(expected.item(), rel=1e-5)
    assert all(torch.equal(p, q) for p, q in zip(actor_before, m.actor.parameters()))
    assert all(torch.equal(p, q) for p, q in zip(target_before, m.critic_target.parameters()))
    critic_before = [p.clone() for p in m.critic.parameters()]
    m.critic_optimizer.param_groups[0]["lr"] = 0.0  # isolate the actor's step: the critics must not move with it
    m._update()  # update 12: the actor and the targets move, the critics' weights get no gradient from it
    assert not all(torch.equal(p, q) for p, q in zip(actor_before, m.actor.parameters()))
    assert not all(torch.equal(p, q) for p, q in zip(target_before, m.critic_target.parameters()))
    assert all(torch.equal(p, q) for p, q in zip(critic_before, m.critic.parameters()))


def test_td3_replay_draws_td3_batches_from_its_window_after_the_warm_up():
    m = model(td3_replay=300)
    calls, sample = [], m.replay.sample

    def spy(n, rng, first=0):
        calls.append((n, first, m.replay.added))
        return sample(n, rng, first)

    m.replay.sample = spy
    m.learn(800, progress_bar=False)
    warmup = calls[0][2]  # the replay when the representation's pre-training drew its first batch
    assert m.rl_start == warmup >= SMALL.warmup_steps
    td3 = [(first, added) for n, first, added in calls if n == SMALL.batch_size]  # the VAE's batches are 16 too
    td3 = [(first, added) for first, added in td3 if first > 0]
    assert len(td3) == m.n_updates > 0
    for first, added in td3:
        assert first == max(warmup, added - 300) and added - first >= SMALL.batch_size
    assert td3[0][1] >= warmup + SMALL.batch_size  # no TD3 step before a batch of its own samples
    assert td3[-1][1] - td3[-1][0] == 300  # the window, once the run is longer than it


@pytest.mark.parametrize("bound", ["squash", "invert"])
def test_actor_gradient_through_the_latent_box_matches_finite_differences(bound):
    m = model(bound=bound)
    m.actor.double(), m.critic.double()
    with torch.no_grad():
        m.actor.low.copy_(torch.tensor([-0.5, -1.0, 0.0, -2.0, -0.1]))
        m.actor.high.copy_(torch.tensor([0.5, 2.0, 0.3, 1.0, 0.1]))
        m.actor.net[-2 if bound == "squash" else -1].weight.mul_(30.0)  # outputs near and past the bounds
    obs = torch.rand(6, 9, dtype=torch.float64, generator=torch.Generator().manual_seed(0))
    m.actor.zero_grad()
    params = list(m.actor.net.parameters())
    _, _, grads = backprop_actor(m.actor, m._q1, obs, "invert" if bound == "invert" else "none", params)
    with torch.no_grad():
        if bound == "squash":  # Tanh outputs: the plain gradient of -mean Q1(s, latent(u(s)))
            loss = lambda: -m._q1(obs, m.actor(obs)).mean().item()  # noqa: E731
        else:  # the inverted dQ/du, held fixed, times du/dtheta
            u = m.actor(obs)
            assert (u.abs() > 1).any()
            (dq_du,) = finite_difference(lambda: m._q1(obs, u).sum().item(), [u])
            g = invert_gradients(dq_du, u)
            loss = lambda: -(g * m.actor(obs)).sum().item() / len(obs)  # noqa: E731
        expected = finite_difference(loss, params)
    for grad, e in zip(grads, expected):
        torch.testing.assert_close(grad, e, rtol=1e-5, atol=1e-7)
    m.actor.float()
    with torch.no_grad():
        u = m.actor(obs.float()).clamp(-1, 1)
        a, x = m._act(obs.float(), deterministic=True)  # acting clamps the output into the box, then decodes
        torch.testing.assert_close(x, m.rep.decode(obs.float(), m.actor.to_latent(u))[1])


def test_resume_keeps_the_representation_schedule(tmp_path):
    m = model()
    m.learn(400, progress_bar=False, run_dir=tmp_path)
    resumed = HyAR.load(tmp_path / "checkpoint.pt")
    assert (resumed.num_timesteps, resumed.n_updates, resumed.pretrained) == (m.num_timesteps, m.n_updates, True)
    assert len(resumed.replay) == len(m.replay)  # save_replay is on by default: the representation's data
    stats = []
    resumed.learn(200, progress_bar=False, run_dir=tmp_path, callback=lambda _, s: stats.append(s))
    assert stats[0]["train/updates"] > 0 and resumed.pretrained
    no_replay = model(save_replay=False)
    no_replay.learn(400, progress_bar=False)
    no_replay.save(tmp_path / "n.pt")
    back = HyAR.load(tmp_path / "n.pt")
    assert len(back.replay) == 0 and not back.pretrained  # it warms the representation up again on new data


def test_tiny_learning_run_logs(tmp_path):
    m = model()
    m.learn(800, progress_bar=False, run_dir=tmp_path)
    rows = progress_rows(tmp_path)
    assert len(rows) == 4
    last = rows[-1]
    for key in ("losses/critic_loss", "losses/actor_loss", "losses/vae_recon", "losses/vae_kl", "train/relabelled"):
        assert np.isfinite(float(last[key])), key
    assert 0.0 <= float(last["train/relabelled"]) <= 1.0 and float(last["train/latent_box_width"]) > 0
