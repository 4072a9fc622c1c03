"""The hierarchical (hybrid) action distribution ``pi(a, x | s) = pi_d(a | s) * pi_c(x | s, a)``.

``pi_d`` is a categorical distribution over the K discrete actions. ``pi_c(. | s, a)`` is a diagonal
Gaussian over the padded parameter vector ``x`` in ``[-1, 1]^m``, of which only the first ``m_a`` entries
belong to action ``a`` (``mask[a]``); the others are ignored everywhere (sampled as zero, no
log-probability, no entropy, no KL). The distribution holds the parameter means of *every* action, so that
the chain-rule KL can be summed over actions without samples (the paper's preferred estimator).

KL estimators, all of ``KL(old || new)`` per state (Wei, Wicke & Luke 2018, "Parameterized Actions TRPO"):

- ``joint_sample``: ``log pi_old(a_t, x_t | s) - log pi_new(a_t, x_t | s)`` at the sampled action.
- ``chain_sample``: ``KL(pi_d_old || pi_d_new)(s) + KL(pi_c_old(.|s,a_t) || pi_c_new(.|s,a_t))``.
- ``chain_analytic``: ``KL(pi_d_old || pi_d_new)(s) + sum_a pi_d_old(a|s) KL(pi_c_old(.|s,a) || pi_c_new(.|s,a))``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import torch
import torch.nn.functional as F

__all__ = [
    "Categorical",
    "HybridDistribution",
    "KL_ESTIMATORS",
    "LOG_STD_MIN",
    "LOG_STD_MAX",
    "MASKED",
    "SquashedHybrid",
    "draw_action",
    "draw_params",
    "gumbel_noise",
    "gumbel_softmax_sample",
    "kl_divergence",
    "masked_logits",
]

KL_ESTIMATORS = ("joint_sample", "chain_sample", "chain_analytic")
_LOG_2PI = math.log(2.0 * math.pi)
# What a masked action's logit (or Q-value) becomes: finite, so that softmax gives it probability 0 exactly and
# p * log p stays 0 (not 0 * -inf = NaN), and far below any logit or return the networks produce.
MASKED = -1e9
LOG_STD_MIN, LOG_STD_MAX = -5.0, 2.0
"""The range a learned log standard deviation is clamped to where a network or a free parameter outputs it (the
off-policy policies and HyAR's encoder), as Spinning Up's and SAC's reference code clamp theirs: wide enough for
any useful noise, narrow enough that ``exp`` neither vanishes nor explodes."""


def masked_logits(logits: torch.Tensor, mask: torch.Tensor | None) -> torch.Tensor:
    """``logits`` ``(B, K)`` with the actions that ``mask`` (bool ``(B, K)``, True = allowed) forbids set to
    :data:`MASKED`; ``None`` allows everything (``logits`` itself is returned).

    Softmax, log-softmax, entropies and KLs of the result are those of the categorical restricted to the allowed
    actions, with no NaN and no gradient into the masked entries; ``argmax`` and ``max`` pick among the allowed
    (so the same function masks Q-values). A row allowing nothing is left as it is (every action allowed).
    """
    if mask is None:
        return logits
    mask = mask.to(torch.bool)
    mask = mask | ~mask.any(dim=-1, keepdim=True)
    return torch.where(mask, logits, torch.full_like(logits, MASKED))


def draw_action(logits: torch.Tensor, deterministic: bool, generator: torch.Generator | None = None) -> torch.Tensor:
    """``a ~ softmax(logits)`` ``(B,)``, or its argmax when ``deterministic``: the first draw of an action."""
    if deterministic:
        return logits.argmax(dim=-1)
    return torch.multinomial(F.softmax(logits, dim=-1), 1, generator=generator).squeeze(-1)


def draw_params(
    mu: torch.Tensor,
    log_std: torch.Tensor | None,
    mask: torch.Tensor,
    deterministic: bool,
    generator: torch.Generator | None = None,
) -> torch.Tensor:
    """``x ~ N(mu, exp(log_std)^2)`` for the chosen actions (``mu`` ``(B, m)``), or ``mu`` when ``deterministic``;
    entries outside ``mask`` zero: the second draw of an action, after :func:`draw_action`."""
    if not deterministic:
        mu = mu + log_std.exp() * torch.randn(mu.shape, generator=generator, dtype=mu.dtype, device=mu.device)
    return mu * mask


def gumbel_noise(shape: tuple[int, ...], generator: torch.Generator) -> torch.Tensor:
    """Standard Gumbel samples ``-log(-log U)`` from ``generator`` (torch's own sampler uses the global RNG)."""
    u = torch.rand(shape, generator=generator, device=generator.device).clamp_(1e-10, 1.0 - 1e-7)
    return -torch.log(-torch.log(u))


def gumbel_softmax_sample(
    logits: torch.Tensor, eta: torch.Tensor, temperature: float, hard: bool
) -> tuple[torch.Tensor, torch.Tensor]:
    """The Gumbel-Softmax sample for noise ``eta``: ``(index, sample)``.

    ``index = argmax(logits + eta)`` is an exact draw from ``softmax(logits)`` (the Gumbel-max trick).
    ``sample`` is ``softmax((logits + eta) / temperature)``, or with ``hard`` the one-hot of ``index`` in the
    forward pass carrying the softmax's gradient in the backward pass (straight-through).
    """
    z = logits.log_softmax(-1) + eta
    soft = torch.softmax(z / temperature, dim=-1)
    index = z.argmax(-1)
    if not hard:
        return index, soft
    onehot = F.one_hot(index, logits.shape[-1]).to(soft.dtype)
    return index, onehot - soft.detach() + soft


@dataclass
class Categorical:
    """``pi_d(a | s)``, the categorical part of a hybrid distribution, and what both hybrid distributions below
    compute from it alone.

    Attributes:
        logits: ``(B, K)`` unnormalised log-probabilities of ``pi_d`` (masked actions at :data:`MASKED`).
    """

    logits: torch.Tensor

    @property
    def log_probs_d(self) -> torch.Tensor:
        """``(B, K)`` normalised ``log pi_d(a | s)``."""
        return F.log_softmax(self.logits, dim=-1)

    @property
    def probs_d(self) -> torch.Tensor:
        return F.softmax(self.logits, dim=-1)

    def entropy_d(self) -> torch.Tensor:
        """``(B,)`` the entropy of ``pi_d`` (masked actions contribute nothing)."""
        return -(self.probs_d * self.log_probs_d).sum(-1)


@dataclass
class HybridDistribution(Categorical):
    """A batch of hybrid action distributions with Gaussian parameters (PATRPO's and PAPPO's).

    Attributes:
        logits: ``(B, K)`` unnormalised log-probabilities of ``pi_d``.
        means: ``(B, K, m)`` parameter means of ``pi_c(. | s, a)`` for every action ``a``.
        log_std: ``(K, m)`` or ``(B, K, m)`` log standard deviations of ``pi_c``.
        mask: ``(K, m)`` boolean, which padded entries each action uses.
    """

    means: torch.Tensor
    log_std: torch.Tensor
    mask: torch.Tensor

    def __post_init__(self):
        self.log_std = self.log_std.expand_as(self.means)
        self.mask = self.mask.to(self.means.dtype)

    # -- pieces ------------------------------------------------------------------------------
    def _at(self, tensor: torch.Tensor, a: torch.Tensor) -> torch.Tensor:
        """Select action ``a``'s row of a ``(B, K, m)`` tensor: ``(B, m)``."""
        return tensor.gather(1, a.long().view(-1, 1, 1).expand(-1, 1, tensor.shape[-1])).squeeze(1)

    # -- sampling ----------------------------------------------------------------------------
    def sample(self, generator: torch.Generator | None = None) -> tuple[torch.Tensor, torch.Tensor]:
        """Draw ``a ~ pi_d`` then ``x ~ pi_c(. | s, a)``; unused parameter entries are zero."""
        a = draw_action(self.logits, False, generator)
        return a, draw_params(self._at(self.means, a), self._at(self.log_std, a), self.mask[a], False, generator)

    def mode(self) -> tuple[torch.Tensor, torch.Tensor]:
        """The greedy action: ``argmax_a pi_d(a | s)`` with its mean parameters."""
        a = draw_action(self.logits, True)
        return a, draw_params(self._at(self.means, a), None, self.mask[a], True)

    # -- densities ---------------------------------------------------------------------------
    def log_prob(self, a: torch.Tensor, x: torch.Tensor) -> torch.Tensor:
        """``log pi_d(a | s) + log pi_c(x | s, a)``, counting only action ``a``'s parameters."""
        a = a.long()
        mu, log_std = self._at(self.means, a), self._at(self.log_std, a)
        z = (x - mu) / log_std.exp()
        log_pc = (-0.5 * z.pow(2) - log_std - 0.5 * _LOG_2PI) * self.mask[a]
        return self.log_probs_d.gather(1, a.view(-1, 1)).squeeze(1) + log_pc.sum(-1)

    def entropy_c(self) -> torch.Tensor:
        """``(B, K)``: the differential entropy of ``pi_c(. | s, a)`` for every action."""
        return ((self.log_std + 0.5 * (1.0 + _LOG_2PI)) * self.mask).sum(-1)

    def entropy(self) -> torch.Tensor:
        """Exact joint entropy by the chain rule: ``H(pi_d) + sum_a pi_d(a) H(pi_c(. | s, a))``."""
        p, logp = self.probs_d, self.log_probs_d  # p once: its gradient gathers both terms', as it always did
        return -(p * logp).sum(-1) + (p * self.entropy_c()).sum(-1)

    # -- divergences -------------------------------------------------------------------------
    def kl_d(self, new: HybridDistribution) -> torch.Tensor:
        """``(B,)``: ``KL(pi_d_self || pi_d_new)`` in closed form."""
        return (self.probs_d * (self.log_probs_d - new.log_probs_d)).sum(-1)

    def kl_c(self, new: HybridDistribution) -> torch.Tensor:
        """``(B, K)``: the Gaussian ``KL(pi_c_self(. | s, a) || pi_c_new(. | s, a))`` for every action."""
        var_ratio = (2.0 * (self.log_std - new.log_std)).exp()
        mean_term = ((self.means - new.means) / new.log_std.exp()).pow(2)
        per_dim = 0.5 * (var_ratio + mean_term - 1.0) - (self.log_std - new.log_std)
        return (per_dim * self.mask).sum(-1)

    def kl_hessian_product(
        self,
        d_logits: torch.Tensor,
        d_means: torch.Tensor,
        d_log_std: torch.Tensor,
        estimator: str = "chain_analytic",
        a: torch.Tensor | None = None,
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """The Hessian of the batch-mean ``KL(self || new)`` in ``new``'s ``(logits, means, log_std)``, at
        ``new = self``, times the tangent ``(d_logits, d_means, d_log_std)``: the Fisher information of the
        estimator in the distribution's own parameters.

        Exact for the closed-form estimators: ``chain_analytic`` weighs action ``a``'s Gaussian by
        ``pi_d(a | s)``, ``chain_sample`` counts the sampled action ``a``'s only. Per state and parameter the
        blocks are ``diag(p) - p p^T`` for the logits, ``1 / sigma^2`` for a mean and ``2`` for a log-std, with
        no cross terms at ``new = self``. ``d_log_std`` may be ``(K, m)`` (shared by the batch) or per state;
        the result has the tangents' shapes. (``joint_sample`` has no such closed form: its Hessian depends on
        the sampled parameters, so Fisher-vector products for it go through double back-propagation.)
        """
        p = self.probs_d.detach()
        batch = p.shape[0]
        if estimator == "chain_analytic":
            weight = p
        elif estimator == "chain_sample":
            if a is None:
                raise ValueError("the 'chain_sample' KL estimator needs the sampled actions (a)")
            weight = F.one_hot(a.long(), p.shape[-1]).to(p.dtype)
        else:
            raise ValueError(
                f"no closed-form Fisher for the KL estimator {estimator!r}; expected chain_analytic or chain_sample"
            )
        u_logits = p * (d_logits - (p * d_logits).sum(-1, keepdim=True)) / batch
        w = weight.unsqueeze(-1) * self.mask / batch
        u_means = w * d_means * torch.exp(-2.0 * self.log_std.detach())
        u_log_std = 2.0 * w * d_log_std
        if d_log_std.dim() < u_log_std.dim():  # shared by the batch: its entries collect every state's term
            u_log_std = u_log_std.sum(0)
        return u_logits, u_means, u_log_std

    def detach(self) -> HybridDistribution:
        return HybridDistribution(self.logits.detach(), self.means.detach(), self.log_std.detach(), self.mask)

    def __getitem__(self, index) -> HybridDistribution:
        """A sub-batch (the state dimension only)."""
        log_std = self.log_std[index]
        return HybridDistribution(self.logits[index], self.means[index], log_std, self.mask)


@dataclass
class SquashedHybrid(Categorical):
    """A batch of hybrid distributions with tanh-squashed Gaussian parameters, every action's at once: Hybrid
    SAC's policy (Delalleau et al. 2019), ``x = tanh(u)``, ``u ~ N(mean, exp(log_std))``, so that

        log pi_c(x | s, a) = sum_i [ log N(u_i; mean_i, sigma_i) - log(1 - tanh(u_i)^2) ]

    over the ``m_a`` parameters of action ``a`` (the change of variables of SAC's squashed Gaussian, Haarnoja et
    al. 2018, appendix C).

    Attributes:
        logits: ``(B, K)`` logits of ``pi_d``, masked actions already at :data:`~pamdp.distributions.MASKED`.
        mean: ``(B, K, m)`` means of the pre-squash Gaussians ``u``, per action and padded parameter.
        log_std: ``(B, K, m)`` their log standard deviations.
        param_mask: ``(K, m)`` float, 1 where action ``a`` uses padded parameter ``i``; ``None`` where every action
            uses all ``m`` (nothing to mask).
    """

    mean: torch.Tensor
    log_std: torch.Tensor
    param_mask: torch.Tensor | None

    def rsample(self, generator: torch.Generator | None = None) -> tuple[torch.Tensor, torch.Tensor]:
        """Reparameterised pre-squash ``u`` and parameters ``x = tanh(u)`` of every action, ``(B, K, m)`` each;
        unused entries are zero."""
        noise = torch.randn(self.mean.shape, generator=generator, dtype=self.mean.dtype, device=self.mean.device)
        u = self.mean + self.log_std.exp() * noise
        if self.param_mask is not None:
            u = u * self.param_mask
        return u, torch.tanh(u)

    def log_prob_c(self, u: torch.Tensor) -> torch.Tensor:
        """``(B, K)``: ``log pi_c(tanh(u_a) | s, a)`` for every action, over its own ``m_a`` parameters only.

        ``log(1 - tanh(u)^2) = 2 (log 2 - u - softplus(-2 u))``, which stays finite where ``tanh(u)`` rounds to 1.
        """
        z = (u - self.mean) * torch.exp(-self.log_std)
        gaussian = -0.5 * z.pow(2) - self.log_std - 0.5 * _LOG_2PI
        log_det = 2.0 * (math.log(2.0) - u - F.softplus(-2.0 * u))
        log_p = gaussian - log_det
        return (log_p if self.param_mask is None else log_p * self.param_mask).sum(-1)

    def sample_discrete(self, generator: torch.Generator | None = None) -> torch.Tensor:
        """``(B,)`` actions drawn from ``pi_d``."""
        return draw_action(self.logits, False, generator)

    def mode(self) -> tuple[torch.Tensor, torch.Tensor]:
        """The greedy action: ``argmax_a pi_d(a | s)`` and ``tanh`` of its Gaussian's mean, ``(B,)`` and ``(B, m)``."""
        a = self.logits.argmax(-1)
        x = torch.tanh(self.mean[torch.arange(len(a), device=a.device), a])
        return a, x if self.param_mask is None else x * self.param_mask[a]


def kl_divergence(
    old: HybridDistribution,
    new: HybridDistribution,
    estimator: str = "chain_analytic",
    a: torch.Tensor | None = None,
    x: torch.Tensor | None = None,
) -> torch.Tensor:
    """Per-state estimate ``(B,)`` of ``KL(old || new)`` by the named estimator.

    ``a`` and ``x`` are the actions sampled from ``old`` (needed by the sample-based estimators).
    """
    if estimator == "chain_analytic":
        return old.kl_d(new) + (old.probs_d * old.kl_c(new)).sum(-1)
    if a is None or (estimator == "joint_sample" and x is None):
        if estimator in KL_ESTIMATORS:
            raise ValueError(f"the {estimator!r} KL estimator needs the sampled actions (a and x)")
    if estimator == "chain_sample":
        return old.kl_d(new) + old.kl_c(new).gather(1, a.long().view(-1, 1)).squeeze(1)
    if estimator == "joint_sample":
        return old.log_prob(a, x) - new.log_prob(a, x)
    raise ValueError(f"unknown KL estimator {estimator!r}; expected one of {', '.join(KL_ESTIMATORS)}")
