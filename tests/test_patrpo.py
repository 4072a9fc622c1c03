"""PATRPO: advantages by hand, the natural step against explicit linear algebra, settings, and the errors of loading,
predicting and saving (reproducibility and the save/load round trip as every algorithm: test_algorithms)."""

import copy
import dataclasses
import os
import stat

import gymnasium
import numpy as np
import pytest
import torch
from test_trpo import explicit_hessian

from pamdp import PATRPO
from pamdp.algos.onpolicy import LinearFeatureBaseline, advantage_batch, gae, update_tensors
from pamdp.algos.paddpg import PADDPGConfig
from pamdp.algos.patrpo import PATRPOConfig
from pamdp.algos.trpo import flat_grad, flat_params
from pamdp.distributions import KL_ESTIMATORS, kl_divergence

SMALL = PATRPOConfig(hidden_sizes=(32, 32), batch_size=1000, num_envs=8, vf_hidden_sizes=(32,))


def test_gae_by_hand():
    # One env, three steps: r = 1, 2, 3; the second step is truncated (bootstrap, cut), the third terminates.
    r = np.array([[1.0], [2.0], [3.0]])
    v = np.array([[0.5], [0.25], [0.75]])
    nv = np.array([[0.25], [4.0], [9.0]])
    term = np.array([[0.0], [0.0], [1.0]])
    done = np.array([[0.0], [1.0], [1.0]])
    g, lam = 0.9, 0.5
    d0 = 1 + g * 0.25 - 0.5
    d1 = 2 + g * 4.0 - 0.25  # truncation: bootstraps from the final observation's value
    d2 = 3 - 0.75  # termination: no bootstrap
    expected = [d0 + g * lam * d1, d1, d2]
    np.testing.assert_allclose(gae(r, v, nv, term, done, g, lam)[:, 0], expected)


def test_gae_lambda_one_gives_discounted_returns_minus_values():
    rng = np.random.default_rng(0)
    r = rng.normal(size=(6, 1))
    v = rng.normal(size=(6, 1))
    nv = np.vstack([v[1:], [[0.0]]])
    term = np.zeros((6, 1))
    term[-1] = 1
    ret = np.array([sum(0.9**k * r[t + k, 0] for k in range(6 - t)) for t in range(6)])
    np.testing.assert_allclose(gae(r, v, nv, term, term.copy(), 0.9, 1.0)[:, 0], ret - v[:, 0], atol=1e-12)


def test_linear_baseline_recovers_a_linear_function():
    rng = np.random.default_rng(1)
    obs = rng.uniform(-1, 1, size=(500, 3))
    t = rng.integers(0, 200, size=500)
    coef = rng.normal(size=10)
    y = LinearFeatureBaseline.features(obs, t) @ coef
    base = LinearFeatureBaseline(3)
    assert base.fit(obs, t, y) < 1e-8
    np.testing.assert_allclose(base.coef, coef, atol=1e-4)


def test_config_from_dict_rejects_unknown_and_mistyped():
    with pytest.raises(ValueError, match="unknown PATRPOConfig setting"):
        PATRPOConfig.from_dict({"dleta": 0.1})
    with pytest.raises(ValueError, match="'batch_size' = 'many'"):
        PATRPOConfig.from_dict({"batch_size": "many"})
    assert PATRPOConfig.from_dict({"hidden_sizes": [8, 8], "delta": 1}).hidden_sizes == (8, 8)


def test_config_may_be_a_dict_of_settings_over_the_defaults():
    model = PATRPO("pamdp/Platform-v0", {"delta": 0.02, "hidden_sizes": [8]})
    assert model.config == PATRPOConfig(delta=0.02, hidden_sizes=(8,))
    with pytest.raises(ValueError, match="unknown PATRPOConfig setting"):
        PATRPO("pamdp/Platform-v0", {"dleta": 0.02})
    with pytest.raises(ValueError, match="PATRPO needs a PATRPOConfig or a dict of its settings, got PADDPGConfig"):
        PATRPO("pamdp/Platform-v0", PADDPGConfig())


def test_rejects_non_hybrid_action_space():
    with pytest.raises(ValueError, match="unsupported action space"):
        PATRPO(gymnasium.make("CartPole-v1"), SMALL)


def float64_batch(model: PATRPO, n: int) -> tuple[torch.Tensor, ...]:
    """``n`` samples of ``model``'s policy with their advantages, as the policy update takes them, after which
    the policy computes in float64: so that its conjugate gradients converge to rounding."""
    cfg = model.config
    batch = model.loop.collect(n)
    model.policy.double()
    data, _ = advantage_batch(batch, model._values, cfg.gamma, cfg.gae_lambda, True)
    return tuple(t.double() if t is not None and t.is_floating_point() else t for t in update_tensors(data))


@pytest.mark.parametrize("estimator", ["chain_analytic", "chain_sample"])
def test_gauss_newton_and_double_backprop_take_the_same_step(estimator):
    """The two Fisher-vector products are the same matrix, so from the same batch, parameters and random
    stream (the product's subsample) the two updates take the same step. The products agree to float64
    rounding; ten conjugate-gradient iterations on an ill-conditioned matrix amplify that to about 1e-6 of
    the step's largest entry."""
    cfg = PATRPOConfig.from_dict({"kl_estimator": estimator, "fvp_subsample": 0.5}, base=SMALL)
    model = PATRPO("pamdp/Platform-v0", cfg)
    tensors = float64_batch(model, 1000)
    start, stream = copy.deepcopy(model.policy.state_dict()), model.torch_gen.get_state()
    before = flat_params(list(model.policy.parameters()))
    steps = []
    for fvp in ("gauss_newton", "double_backprop"):
        model.policy.load_state_dict(start)
        model.torch_gen.set_state(stream)
        model.config = dataclasses.replace(cfg, fvp=fvp)
        assert model._update_policy(*tensors)["train/line_search_success"] == 1.0
        steps.append(flat_params(list(model.policy.parameters())) - before)
    torch.testing.assert_close(steps[0], steps[1], atol=1e-5 * float(steps[1].abs().max()), rtol=0)


def test_an_update_without_a_direction_is_logged_as_skipped_not_as_a_failed_line_search():
    """Zero advantages and no entropy bonus: the surrogate's gradient is exactly zero, conjugate gradients return
    the zero direction, and the policy stays as it is without a line search (catch_point.md: a collapsed pi_d)."""
    model = PATRPO("pamdp/Platform-v0", PATRPOConfig.from_dict({"entropy_coef": 0.0}, base=SMALL))
    obs, a, x, adv, _ = float64_batch(model, 200)
    before = flat_params(list(model.policy.parameters()))
    stats = model._update_policy(obs, a, x, torch.zeros_like(adv))
    assert stats["train/update_skipped"] == 1.0 and stats["train/backtracks"] == 0.0 and stats["train/kl"] == 0.0
    assert torch.equal(flat_params(list(model.policy.parameters())), before)
    assert model._update_policy(obs, a, x, adv)["train/update_skipped"] == 0.0


def test_the_discrete_entropy_bonus_moves_pi_d_alone_towards_uniform():
    """Zero advantages and entropy_coef_d alone: the surrogate is pi_d's entropy, whose gradient has no part in
    pi_c's network or the log-stds; the chain-rule KL's Fisher matrix has no block between pi_d's parameters and
    pi_c's at the old policy, so the natural step leaves pi_c exactly as it was and raises pi_d's entropy."""
    model = PATRPO(
        "pamdp/Platform-v0", PATRPOConfig.from_dict({"entropy_coef": 0.0, "entropy_coef_d": 0.5}, base=SMALL)
    )
    obs, a, x, adv = float64_batch(model, 200)[:4]
    with torch.no_grad():  # a pi_d far from uniform, so that there is entropy to gain
        model.policy.pi_d[-1].bias.copy_(torch.tensor([2.0, -1.0, 0.0], dtype=torch.float64))
    entropy = lambda: model.policy(obs).entropy_d().mean().item()  # noqa: E731
    before, pi_c = entropy(), {k: v.clone() for k, v in model.policy.state_dict().items() if not k.startswith("pi_d")}
    stats = model._update_policy(obs, a, x, torch.zeros_like(adv))
    assert stats["train/update_skipped"] == 0.0 and entropy() > before
    assert all(torch.equal(v, model.policy.state_dict()[k]) for k, v in pi_c.items())


def test_load_errors_are_clear(tmp_path):
    with pytest.raises(FileNotFoundError, match="no pamdp model at"):
        PATRPO.load(tmp_path / "missing.pt")
    bad = tmp_path / "bad.pt"
    bad.write_bytes(b"not a checkpoint")
    with pytest.raises(ValueError, match="not a readable pamdp checkpoint"):
        PATRPO.load(bad)
    torch.save({"something": 1}, tmp_path / "other.pt")
    with pytest.raises(ValueError, match="not a pamdp checkpoint"):
        PATRPO.load(tmp_path / "other.pt")


def test_predict_and_save_refuse_bad_input_clearly(tmp_path):
    model = PATRPO("pamdp/Platform-v0", SMALL)
    with pytest.raises(ValueError, match=r"observation.* of shape \(5,\); expected .*\(9,\) or \(N, 9\)"):
        model.predict(np.zeros(5))
    obs = np.zeros((3, 9))
    obs[1, 4] = np.nan
    with pytest.raises(ValueError, match=r"non-finite value nan at index \[1, 4\]"):
        model.predict(obs)
    (tmp_path / "model.pt").mkdir()
    with pytest.raises(ValueError, match="it is a directory; expected a file path"):
        model.save(tmp_path / "model.pt")
    assert list((tmp_path / "model.pt").iterdir()) == [] and len(list(tmp_path.iterdir())) == 1


def test_saved_files_get_the_permissions_open_would_give(tmp_path):
    model = PATRPO("pamdp/Platform-v0", SMALL)
    old = os.umask(0o027)
    try:
        model.save(tmp_path / "model.pt")
    finally:
        os.umask(old)
    assert stat.S_IMODE((tmp_path / "model.pt").stat().st_mode) == 0o640


def test_loading_never_executes_code(tmp_path):
    class Evil:
        def __reduce__(self):
            return (exec, ("import pathlib; pathlib.Path('%s').write_text('pwned')" % (tmp_path / "flag"),))

    torch.save({"format": "pamdp-checkpoint", "evil": Evil()}, tmp_path / "evil.pt")
    with pytest.raises(ValueError):
        PATRPO.load(tmp_path / "evil.pt")
    assert not (tmp_path / "flag").exists()


def test_linear_baseline_option_trains_and_round_trips(tmp_path):
    cfg = PATRPOConfig.from_dict({"baseline": "linear"}, base=SMALL)
    model = PATRPO("pamdp/Platform-v0", cfg)
    model.learn(1000, progress_bar=False)
    assert np.any(model.linear_baseline.coef != 0)
    model.save(tmp_path / "lin.pt")
    loaded = PATRPO.load(tmp_path / "lin.pt")
    np.testing.assert_array_equal(loaded.linear_baseline.coef, model.linear_baseline.coef)


@pytest.mark.parametrize("estimator", KL_ESTIMATORS)
def test_an_update_takes_the_natural_step_of_its_kl_estimators_explicit_hessian(estimator):
    """One policy update against explicit linear algebra: with ``H`` the Hessian of the estimator's mean KL
    (built row by row by autograd), ``D = H + cg_damping I`` and ``g`` the surrogate's gradient, the update moves
    the parameters along ``D^-1 g`` (``D step`` parallel to ``g``) by ``ratio^k`` times the length where
    ``step^T D step / 2 = delta``."""
    settings = {"hidden_sizes": [6], "kl_estimator": estimator, "delta": 1e-3, "cg_iters": 200, "cg_damping": 1e-2}
    cfg = PATRPOConfig.from_dict(settings, SMALL)
    model = PATRPO("pamdp/Platform-v0", cfg)
    obs, a, x, adv, _ = float64_batch(model, 300)
    params = [p for p in model.policy.parameters() if p.requires_grad]
    with torch.no_grad():
        old = model.policy(obs).detach()
        old_logp = old.log_prob(a, x)
    g = flat_grad((torch.exp(model.policy(obs).log_prob(a, x) - old_logp) * adv).mean(), params)
    hessian = explicit_hessian(lambda: kl_divergence(old, model.policy(obs), estimator, a, x).mean(), params)
    damped = hessian + cfg.cg_damping * torch.eye(len(g), dtype=torch.float64)
    before = flat_params(params)
    stats = model._update_policy(obs, a, x, adv)
    assert stats["train/line_search_success"] == 1.0
    step = flat_params(params) - before
    d_step = damped @ step
    assert float(torch.nn.functional.cosine_similarity(d_step, g, dim=0)) > 1 - 1e-8
    shrink = cfg.backtrack_ratio ** stats["train/backtracks"]
    assert float(step @ d_step) / 2 == pytest.approx(cfg.delta * shrink**2, rel=1e-6)
