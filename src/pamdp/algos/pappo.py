"""PAPPO: Proximal Policy Optimization of the hierarchical policy, H-PPO style (Fan et al., IJCAI 2019).

The policy, the sampling and the advantages are PATRPO's (the on-policy family's
:class:`~pamdp.algos.onpolicy.Rollout` and :func:`~pamdp.algos.onpolicy.advantage_batch`); PPO's clipped
surrogate of the joint ratio ``pi(a,x|s) / pi_old(a,x|s)`` (Schulman et al. 2017, eq. 7) replaces the
trust-region step. The loss and how it differs from Fan et al.'s: docs/algorithms.md, "PAPPO".
"""

from __future__ import annotations

import dataclasses

import numpy as np
import torch

from pamdp.algos.base import Algorithm
from pamdp.algos.onpolicy import OnPolicy, OnPolicyConfig, Rollout, hybrid_policy, update_tensors
from pamdp.algos.settings import NON_NEGATIVE, POSITIVE, AlgoConfig, Check, at_least, interval, setting
from pamdp.distributions import HybridDistribution, kl_divergence
from pamdp.nn.optim import descend
from pamdp.policies import ValueNetwork

__all__ = ["PAPPO", "PAPPOConfig", "clipped_surrogate", "ppo_loss"]


@dataclasses.dataclass(frozen=True)
class PAPPOConfig(OnPolicyConfig, AlgoConfig):
    """PAPPO's settings; the defaults are the common PPO ones (Schulman et al. 2017; CleanRL, Stable-Baselines3)
    on PATRPO's hierarchical policy (:class:`~pamdp.algos.onpolicy.OnPolicyConfig`'s), with a separate value
    network trained in the same loss.
    """

    n_epochs: int = setting(
        10, "Passes over each batch; more reuse per sample, and more drift from pi_old.", at_least(1)
    )
    minibatch_size: int = setting(
        256,
        "Samples per gradient step (the batch is split into equal minibatches of about this size).",
        Check(lambda v: v >= 1, "an integer in [1, batch_size]"),  # the upper end: __post_init__
    )
    lr: float = setting(
        3e-4, "Adam learning rate of the policy and the value network (one optimiser, one loss).", POSITIVE
    )
    clip_range: float = setting(
        0.2,
        "eps: the ratio pi / pi_old is clipped to [1 - eps, 1 + eps] in the surrogate; 0.1-0.3 is usual.",
        interval(0, 1, low_open=True, high_open=True),
    )
    ent_coef_d: float = setting(
        0.01,
        "Weight of pi_d's entropy in the loss: keeps every discrete action tried. Platform needs about 0.3 (the "
        "tuned preset): with less, pi_d turns deterministic early and the return stalls below the optimum.",
        NON_NEGATIVE,
    )
    ent_coef_c: float = setting(
        0.0,
        "Weight of the parameter policy's entropy (expected over pi_d) in the loss; it only widens the noise.",
        NON_NEGATIVE,
    )
    vf_coef: float = setting(0.5, "Weight of the value loss E[(V(s) - R)^2] in the joint loss.", POSITIVE)
    max_grad_norm: float = setting(0.5, "Clip the joint gradient's norm to this before each Adam step.", POSITIVE)
    target_kl: float = setting(
        0.0,
        "Stop an epoch's passes once a minibatch's chain-rule KL(pi_old || pi) exceeds this (0: never; 0.01-0.05).",
        NON_NEGATIVE,
    )

    def __post_init__(self):
        """The checks across settings (each setting's own runs in AlgoConfig)."""
        super().__post_init__()
        self._check(
            self.minibatch_size <= self.batch_size,
            "minibatch_size",
            f"an integer in [1, batch_size={self.batch_size}]",
        )

    # "tuned": found by single probe runs on Platform (ent_coef_d's help says why; the record of its
    # learning: benchmarks/later_platform.md)
    PRESETS = {"default": {}, "tuned": dict(ent_coef_d=0.3, target_kl=0.02)}


def clipped_surrogate(logp: torch.Tensor, old_logp: torch.Tensor, adv: torch.Tensor, clip_range: float) -> torch.Tensor:
    """PPO's clipped surrogate as a loss to minimise: ``-mean(min(r A, clip(r, 1 - eps, 1 + eps) A))``.

    ``r = exp(logp - old_logp)``. A sample whose ratio has left the clip range on the side its advantage
    pushes (``r > 1 + eps`` with ``A > 0``, ``r < 1 - eps`` with ``A < 0``) contributes no gradient.
    """
    ratio = torch.exp(logp - old_logp)
    return -torch.min(ratio * adv, ratio.clamp(1.0 - clip_range, 1.0 + clip_range) * adv).mean()


def ppo_loss(
    dist: HybridDistribution,
    values: torch.Tensor,
    a: torch.Tensor,
    x: torch.Tensor,
    old_logp: torch.Tensor,
    adv: torch.Tensor,
    returns: torch.Tensor,
    cfg: PAPPOConfig,
) -> tuple[torch.Tensor, dict[str, torch.Tensor]]:
    """The joint loss ``L`` of docs/algorithms.md, "PAPPO", on a minibatch, and its parts (detached) for logging."""
    logp = dist.log_prob(a, x)
    policy_loss = clipped_surrogate(logp, old_logp, adv, cfg.clip_range)
    value_loss = (values - returns).pow(2).mean()
    entropy_c = (dist.probs_d * dist.entropy_c()).sum(-1).mean()
    entropy_d = dist.entropy().mean() - entropy_c
    loss = policy_loss + cfg.vf_coef * value_loss - cfg.ent_coef_d * entropy_d - cfg.ent_coef_c * entropy_c
    with torch.no_grad():
        clipped = ((logp - old_logp).exp() - 1.0).abs() > cfg.clip_range
    parts = {
        "losses/policy_loss": policy_loss,
        "losses/value_loss": value_loss,
        "losses/entropy_d": entropy_d,
        "losses/entropy_c": entropy_c,
        "train/clip_fraction": clipped.float().mean(),
    }
    return loss, {k: v.detach() for k, v in parts.items()}


class PAPPO(OnPolicy, Algorithm):
    """PPO of the hierarchical policy. See docs/algorithms.md, "PAPPO", for the update and :class:`PAPPOConfig`."""

    config_class = PAPPOConfig
    config: PAPPOConfig
    MODULES = ("policy", "value")
    OPTIMIZERS = {"adam": "optimizer"}

    def _build(self) -> None:
        cfg = self.config
        self.policy = hybrid_policy(self)
        self.value = ValueNetwork(self.obs_dim, cfg.vf_hidden_sizes)
        self.optimizer = torch.optim.Adam([*self.policy.parameters(), *self.value.parameters()], lr=cfg.lr)
        self.loop = Rollout(self)  # a loaded model starts new episodes

    def _learn(self, data: dict[str, np.ndarray]) -> dict[str, float]:
        """:meth:`_update` on an :func:`~pamdp.algos.onpolicy.advantage_batch` (the epoch: Rollout.run_epoch)."""
        returns = torch.as_tensor(data["returns"], dtype=torch.float32, device=self.device)
        obs, a, x, adv, mask = update_tensors(data, self.device)
        return self._update(obs, a, x, adv, returns, mask)

    def _update(self, obs, a, x, adv, returns, mask=None) -> dict[str, float]:
        """``n_epochs`` passes of minibatch Adam steps on the joint loss, stopped early by ``target_kl``; ``mask``:
        the samples' allowed actions, which the policy's probabilities range over (``None``: all)."""
        cfg = self.config
        with torch.no_grad():
            old = self.policy(obs, mask).detach()
            old_logp = old.log_prob(a, x)
        params = [p for group in self.optimizer.param_groups for p in group["params"]]
        n = len(adv)
        n_minibatches = max(1, n // cfg.minibatch_size)
        sums: dict[str, float] = {}
        updates, stopped_at_kl = 0, False
        for _ in range(cfg.n_epochs):
            perm = torch.randperm(n, generator=self.torch_gen, device=self.device)
            for idx in torch.tensor_split(perm, n_minibatches):
                dist = self.policy(obs[idx], None if mask is None else mask[idx])
                if cfg.target_kl > 0:
                    with torch.no_grad():
                        stopped_at_kl = float(kl_divergence(old[idx], dist.detach()).mean()) > cfg.target_kl
                    if stopped_at_kl:
                        break
                loss, parts = ppo_loss(
                    dist, self.value(obs[idx]), a[idx], x[idx], old_logp[idx], adv[idx], returns[idx], cfg
                )
                parts["train/grad_norm"] = descend(self.optimizer, loss, params, cfg.max_grad_norm)
                for k, v in parts.items():
                    sums[k] = sums.get(k, 0.0) + float(v)
                updates += 1
            if stopped_at_kl:
                break
        stats = {k: v / updates for k, v in sums.items()}  # the first minibatch always runs: pi == pi_old there
        with torch.no_grad():
            stats["train/kl"] = float(kl_divergence(old, self.policy(obs, mask)).mean())
        stats["train/updates"] = float(updates)
        stats["train/early_stop"] = float(stopped_at_kl)
        stats["train/param_std"] = self._param_std()
        return stats
