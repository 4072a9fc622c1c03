"""PATRPO: Trust Region Policy Optimization of the hierarchical policy (Wei, Wicke & Luke 2018).

One epoch, as section "Parameterized Actions TRPO" of the paper reads: sample and compute advantages (the
on-policy family's, :mod:`pamdp.algos.onpolicy`), then maximise the surrogate ``E[pi / pi_old * A]`` subject to
``mean KL(pi_old || pi) <= delta`` by conjugate gradient and a backtracking line search (:mod:`pamdp.algos.trpo`;
``fvp`` chooses how the Fisher-vector products are computed). The maths: docs/algorithms.md, "PATRPO".
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np
import torch

from pamdp.algos.base import Algorithm
from pamdp.algos.onpolicy import LinearFeatureBaseline, OnPolicy, OnPolicyConfig, Rollout, hybrid_policy, update_tensors
from pamdp.algos.settings import NON_NEGATIVE, POSITIVE, AlgoConfig, at_least, interval, one_of, redeclared, setting
from pamdp.algos.trpo import (
    FisherVectorProduct,
    backtracking_line_search,
    conjugate_gradient,
    flat_grad,
    hybrid_gauss_newton_fvp,
)
from pamdp.distributions import KL_ESTIMATORS, kl_divergence
from pamdp.nn.optim import descend
from pamdp.policies import ValueNetwork

__all__ = ["PATRPO", "PATRPOConfig"]


FVP_METHODS = ("auto", "gauss_newton", "double_backprop")


@dataclasses.dataclass(frozen=True)
class PATRPOConfig(OnPolicyConfig, AlgoConfig):
    """PATRPO's settings; the defaults are the paper's preset, rllab's TRPO settings where the paper is silent,
    and two modern choices that do not change the algorithm: an MLP value baseline (rllab's linear one is
    ``baseline="linear"``) and 128 env copies stepped together (samples per epoch are ``batch_size`` either way).
    """

    num_envs: int = redeclared(OnPolicyConfig, "num_envs", 128)
    hidden_sizes: tuple[int, ...] = redeclared(OnPolicyConfig, "hidden_sizes", (200, 100, 50), "paper: {200, 100, 50}")
    activation: str = redeclared(OnPolicyConfig, "activation", "relu", "paper: relu")
    init_log_std: float = redeclared(OnPolicyConfig, "init_log_std", 0.0, "rllab: std 1")
    batch_size: int = redeclared(OnPolicyConfig, "batch_size", 10_000, "one TRPO update; the paper: 10 000")
    delta: float = setting(
        0.005,
        "Trust region: the bound on the mean KL(pi_old || pi). Paper: 0.005 (0.01, 0.05 in its step-size figure).",
        POSITIVE,
    )
    kl_estimator: str = setting(
        "chain_analytic",
        "KL estimator for the constraint: joint_sample, chain_sample or chain_analytic (the paper's preferred).",
        one_of(KL_ESTIMATORS),
    )
    cg_iters: int = setting(10, "Conjugate-gradient iterations for the natural-gradient direction.", at_least(1))
    fvp_subsample: float = setting(
        1.0,
        "Fraction of the batch for Fisher-vector products (0.1-0.2 is a common speed-up; the line search uses all).",
        interval(0, 1, low_open=True),
    )
    fvp: str = setting(
        "auto",
        "How Fisher-vector products are computed: double_backprop (the paper's, any estimator), gauss_newton "
        "(the same matrix from the KL's closed-form Hessian, faster: benchmarks/fvp_speed.md; the chain "
        "estimators only), or auto (gauss_newton where it applies).",
        one_of(FVP_METHODS),
    )
    cg_damping: float = setting(
        1e-5, "Damping added to the Fisher-vector product; raise it if steps are erratic.", NON_NEGATIVE
    )
    backtrack_ratio: float = setting(
        0.8, "Step shrink factor of the line search.", interval(0, 1, low_open=True, high_open=True)
    )
    max_backtracks: int = setting(
        15, "Line-search tries before the update is abandoned (parameters restored).", at_least(1)
    )
    gae_lambda: float = redeclared(
        OnPolicyConfig, "gae_lambda", 1.0, "rllab: 1.0, Monte-Carlo advantages; 0.95-0.99 lowers variance"
    )
    entropy_coef: float = setting(
        0.0,
        "Weight of the policy entropy added to the surrogate (not in the paper); keeps exploring longer.",
        NON_NEGATIVE,
    )
    entropy_coef_d: float = setting(
        0.0,
        "Weight of pi_d's entropy alone added to the surrogate, beside entropy_coef's joint one (not in the paper): "
        "keeps every discrete action tried without widening the parameter noise (Goal from a random start).",
        NON_NEGATIVE,
    )
    baseline: str = setting(
        "mlp",
        "Baseline: mlp (a value network, the modern choice) or linear (rllab's linear-feature baseline).",
        one_of(("mlp", "linear")),
    )
    vf_lr: float = setting(1e-3, "Adam learning rate of the value network.", POSITIVE)
    vf_epochs: int = setting(5, "Passes over each batch when fitting the value network.", at_least(1))
    vf_batch_size: int = setting(256, "Minibatch size of the value network's fit.", at_least(1))

    def __post_init__(self):
        """The checks across settings (each setting's own runs in AlgoConfig)."""
        super().__post_init__()
        self._check(
            not (self.fvp == "gauss_newton" and self.kl_estimator == "joint_sample"),
            "fvp",
            "auto or double_backprop with kl_estimator='joint_sample' (its Hessian has no closed form)",
        )

    PRESETS = {
        "paper": {},
        "tuned": dict(
            delta=0.02,
            gae_lambda=0.97,
            batch_size=5_000,
            init_log_std=-0.5,
            entropy_coef=0.01,
            fvp_subsample=0.2,
        ),
    }


class PATRPO(OnPolicy, Algorithm):
    """Parameterized Actions TRPO. See docs/algorithms.md, "PATRPO", for the update and :class:`PATRPOConfig`."""

    config_class = PATRPOConfig
    config: PATRPOConfig
    MODULES = ("policy", "value")  # the value network and its optimiser with baseline="mlp" only
    OPTIMIZERS = {"value": "vf_optimizer"}

    def _build(self) -> None:
        cfg = self.config
        self.policy = hybrid_policy(self)
        if cfg.baseline == "mlp":
            self.value = ValueNetwork(self.obs_dim, cfg.vf_hidden_sizes)
            self._vf_params = list(self.value.parameters())
            self.vf_optimizer = torch.optim.Adam(self._vf_params, lr=cfg.vf_lr)
        else:
            self.linear_baseline = LinearFeatureBaseline(self.obs_dim)
        self.loop = Rollout(self)  # a loaded model starts new episodes

    def _extra_state(self):
        if self.config.baseline == "linear":
            return {"linear_baseline": torch.as_tensor(self.linear_baseline.coef)}
        return {}

    def _load_extra_state(self, state):
        if self.config.baseline == "linear":
            self.linear_baseline.coef = state["linear_baseline"].numpy()

    # -- one epoch (the rollout and the advantages: Rollout.run_epoch) ------------------------------
    def _learn(self, data: dict[str, np.ndarray]) -> dict[str, float]:
        """The policy's step on an :func:`~pamdp.algos.onpolicy.advantage_batch`, then the baseline's fit."""
        stats = self._update_policy(*update_tensors(data, self.device))
        stats["train/updates"] = 1.0 - stats.get("train/update_skipped", 0.0)  # one natural-gradient step a batch
        stats["losses/value_loss"] = self._fit_baseline(data["obs"], data["t"], data["returns"])
        return stats

    def _update_policy(self, obs, a, x, adv, mask=None) -> dict[str, float]:
        """One natural-gradient step with line search on the surrogate (the paper's PATRPO update); ``mask``: the
        samples' allowed actions, which the policy's probabilities range over (``None``: all)."""
        cfg = self.config
        params = [p for p in self.policy.parameters() if p.requires_grad]
        with torch.no_grad():
            old = self.policy(obs, mask).detach()
            old_logp = old.log_prob(a, x)

        def surrogate(new) -> torch.Tensor:
            gain = (torch.exp(new.log_prob(a, x) - old_logp) * adv).mean()
            gain = gain + cfg.entropy_coef * new.entropy().mean() if cfg.entropy_coef else gain
            return gain + cfg.entropy_coef_d * new.entropy_d().mean() if cfg.entropy_coef_d else gain

        tried = []  # the line search's last policy distribution: the accepted one's, for the KL after the step

        def evaluate() -> tuple[torch.Tensor, torch.Tensor]:  # one forward pass for both of a step's figures
            tried[:] = [self.policy(obs, mask)]
            return surrogate(tried[0]), kl_divergence(old, tried[0], cfg.kl_estimator, a, x).mean()

        objective = surrogate(self.policy(obs, mask))
        g = flat_grad(objective, params)
        fvp = self._fisher_vector_product(obs, a, x, old, mask)
        direction = conjugate_gradient(fvp, g, cfg.cg_iters)
        shs = float(direction @ fvp(direction))
        stats = {
            "train/entropy": float(old.entropy().mean()),
            "train/grad_norm": float(g.norm()),
            "train/param_std": self._param_std(),
        }
        if not (np.isfinite(shs) and shs > 0):  # no direction (a vanishing gradient): no step, no line search
            nothing = ("train/line_search_success", "train/backtracks", "losses/surrogate_improvement", "train/kl")
            return {**stats, "train/update_skipped": 1.0, **dict.fromkeys(nothing, 0.0)}
        full_step = np.sqrt(2.0 * cfg.delta / shs) * direction
        result = backtracking_line_search(
            params, full_step, evaluate, float(objective.detach()), cfg.delta, cfg.backtrack_ratio, cfg.max_backtracks
        )
        with torch.no_grad():
            after = tried[0] if result.success else old  # a rejected step restores the old parameters
            kl_after = float(kl_divergence(old, after, "chain_analytic").mean())
        stats.update(
            {
                "train/update_skipped": 0.0,
                "train/line_search_success": float(result.success),
                "train/backtracks": float(result.backtracks),
                "losses/surrogate_improvement": result.improvement,
                "train/kl": kl_after,
                "train/kl_estimate": result.kl,
            }
        )
        return stats

    def _fisher_vector_product(self, obs, a, x, old, mask=None) -> Callable[[torch.Tensor], torch.Tensor]:
        """The damped Fisher-vector product of the KL estimator, on ``fvp_subsample`` of the batch."""
        cfg = self.config
        n_fvp = max(1, int(round(cfg.fvp_subsample * len(obs))))
        if n_fvp < len(obs):
            sub = torch.randperm(len(obs), generator=self.torch_gen, device=self.device)[:n_fvp]
            obs, a, x, old = obs[sub], a[sub], x[sub], old[sub]
            mask = None if mask is None else mask[sub]
        method = cfg.fvp
        if method == "auto":
            method = "double_backprop" if cfg.kl_estimator == "joint_sample" else "gauss_newton"
        if method == "double_backprop":
            params = [p for p in self.policy.parameters() if p.requires_grad]
            kl = kl_divergence(old, self.policy(obs, mask), cfg.kl_estimator, a, x).mean()
            return FisherVectorProduct(kl, params, cfg.cg_damping)
        return hybrid_gauss_newton_fvp(self.policy, old, obs, a, cfg.kl_estimator, cfg.cg_damping)

    # -- baseline --------------------------------------------------------------------------------
    def _values(self, obs: np.ndarray, t: np.ndarray) -> np.ndarray:
        """The baseline ``V(s)`` of observations at step ``t`` of their episodes."""
        if self.config.baseline == "linear":
            return self.linear_baseline.predict(obs, t)
        return super()._values(obs, t)

    def _fit_baseline(self, obs: np.ndarray, t: np.ndarray, returns: np.ndarray) -> float:
        cfg = self.config
        if cfg.baseline == "linear":
            return self.linear_baseline.fit(obs, t, returns)
        obs_t, ret_t = self._obs_tensor(obs), torch.as_tensor(returns, dtype=torch.float32, device=self.device)
        n = len(ret_t)
        for _ in range(cfg.vf_epochs):
            perm = torch.randperm(n, generator=self.torch_gen, device=self.device)
            for start in range(0, n, cfg.vf_batch_size):
                idx = perm[start : start + cfg.vf_batch_size]
                loss = (self.value(obs_t[idx]) - ret_t[idx]).pow(2).mean()
                descend(self.vf_optimizer, loss, self._vf_params)
        with torch.no_grad():
            return float((self.value(obs_t) - ret_t).pow(2).mean())
