"""Trust-region machinery shared by the TRPO-family algorithms (Schulman et al. 2015, appendix C).

Each piece is a small function with its own unit test: flat parameter vectors, the Fisher-vector product
by double back-propagation of the KL (TRPO's, and the paper's), the same product in Gauss-Newton form for a
KL whose Hessian is known in closed form (faster: ``benchmarks/fvp_speed.md``), conjugate gradient, and the
backtracking line search.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import torch

if TYPE_CHECKING:
    from pamdp.distributions import HybridDistribution
    from pamdp.policies import HybridPolicy

__all__ = [
    "flat_params",
    "set_flat_params",
    "split_flat",
    "flat_grad",
    "FisherVectorProduct",
    "GaussNewtonFVP",
    "hybrid_gauss_newton_fvp",
    "conjugate_gradient",
    "LineSearchResult",
    "backtracking_line_search",
]


def flat_params(params: Sequence[torch.Tensor]) -> torch.Tensor:
    """All parameters as one detached vector."""
    return torch.cat([p.detach().reshape(-1) for p in params])


def split_flat(flat: torch.Tensor, params: Sequence[torch.Tensor]) -> list[torch.Tensor]:
    """A flat vector as views shaped like ``params``, in order (the inverse of :func:`flat_params`)."""
    views, offset = [], 0
    for p in params:
        views.append(flat[offset : offset + p.numel()].view_as(p))
        offset += p.numel()
    if offset != flat.numel():
        raise ValueError(f"flat vector has {flat.numel()} entries, the parameters {offset}")
    return views


def set_flat_params(params: Sequence[torch.Tensor], flat: torch.Tensor) -> None:
    """Write a flat vector back into the parameters, in place."""
    views = split_flat(flat, params)
    with torch.no_grad():
        for p, v in zip(params, views):
            p.copy_(v)


def flat_grad(
    output: torch.Tensor | Sequence[torch.Tensor],
    params: Sequence[torch.Tensor],
    create_graph: bool = False,
    retain_graph: bool | None = None,
    grad_outputs: Sequence[torch.Tensor] | None = None,
) -> torch.Tensor:
    """``d output / d params`` as one vector (zeros for parameters the output does not depend on); for several
    outputs, the vector-Jacobian product with ``grad_outputs``."""
    grads = torch.autograd.grad(
        output, params, grad_outputs, create_graph=create_graph, retain_graph=retain_graph, allow_unused=True
    )
    return torch.cat([(torch.zeros_like(p) if g is None else g).reshape(-1) for g, p in zip(grads, params)])


class FisherVectorProduct:
    """``v -> (H + damping I) v``, with ``H`` the Hessian of the mean KL at the current parameters.

    The KL's gradient is built once with ``create_graph=True``; each product is then one more backward pass
    of ``grad(KL) . v`` (double back-propagation). The old distribution inside ``kl`` must be detached, so
    that at the current parameters the gradient is zero and the Hessian is the Fisher information.
    """

    def __init__(self, kl: torch.Tensor, params: Sequence[torch.Tensor], damping: float):
        self.params = list(params)
        self.damping = float(damping)
        self.grad_kl = flat_grad(kl, self.params, create_graph=True)

    def __call__(self, v: torch.Tensor) -> torch.Tensor:
        return flat_grad(self.grad_kl @ v, self.params, retain_graph=True) + self.damping * v


class GaussNewtonFVP:
    """``v -> (J^T M J + damping I) v``: the Fisher-vector product as a Gauss-Newton product, for a KL whose
    Hessian ``M`` in the distribution's own parameters is known in closed form (``J``: the Jacobian of the
    distribution's parameters in the network's). One forward-mode product, ``M``, one backward pass: why it is
    exact and what it saves, docs/algorithms.md, "PATRPO".

    Args:
        outputs: the distribution's parameters, computed from ``params`` with their autograd graph.
        params: the network's parameters; products are flat vectors over them, in this order.
        jvp: parameter tangents (shaped as ``params``) -> the tangents of ``outputs``.
        metric: tangents of ``outputs`` -> ``M`` times them (cotangents, shaped as ``outputs``).
        damping: added times ``v``.
    """

    def __init__(
        self,
        outputs: Sequence[torch.Tensor],
        params: Sequence[torch.Tensor],
        jvp: Callable[[list[torch.Tensor]], Sequence[torch.Tensor]],
        metric: Callable[..., Sequence[torch.Tensor]],
        damping: float,
    ):
        self.outputs = list(outputs)
        self.params = list(params)
        self.jvp, self.metric = jvp, metric
        self.damping = float(damping)

    def __call__(self, v: torch.Tensor) -> torch.Tensor:
        cotangents = self.metric(*self.jvp(split_flat(v, self.params)))
        return flat_grad(self.outputs, self.params, retain_graph=True, grad_outputs=cotangents) + self.damping * v


def hybrid_gauss_newton_fvp(
    policy: HybridPolicy, old: HybridDistribution, obs: torch.Tensor, a: torch.Tensor, estimator: str, damping: float
) -> GaussNewtonFVP:
    """:class:`GaussNewtonFVP` of the mean ``kl_divergence(old, policy(obs), estimator, a)`` (a chain estimator):
    the product :class:`FisherVectorProduct` gives for that KL, from the policy's hand-linearised forward pass
    (:meth:`~pamdp.policies.HybridPolicy.linearize`) and the KL's closed-form Hessian in the distribution's
    parameters (:meth:`~pamdp.distributions.HybridDistribution.kl_hessian_product`)."""
    named = [(n, p) for n, p in policy.named_parameters() if p.requires_grad]
    names, params = [n for n, _ in named], [p for _, p in named]
    new, jvp = policy.linearize(obs)

    def metric(d_logits, d_means, d_log_std):
        return old.kl_hessian_product(d_logits, d_means, d_log_std, estimator, a)

    outputs = (new.logits, new.means, policy.log_std)
    return GaussNewtonFVP(outputs, params, lambda ts: jvp(dict(zip(names, ts))), metric, damping)


def conjugate_gradient(
    matvec: Callable[[torch.Tensor], torch.Tensor],
    b: torch.Tensor,
    iters: int = 10,
    residual_tol: float = 1e-10,
) -> torch.Tensor:
    """Approximately solve ``A x = b`` for symmetric positive-definite ``A`` given only ``x -> A x``."""
    x = torch.zeros_like(b)
    r = b.clone()
    p = b.clone()
    rr = r @ r
    for _ in range(iters):
        if rr < residual_tol:
            break
        Ap = matvec(p)
        alpha = rr / (p @ Ap)
        x += alpha * p
        r -= alpha * Ap
        rr_new = r @ r
        p = r + (rr_new / rr) * p
        rr = rr_new
    return x


@dataclass
class LineSearchResult:
    """Outcome of :func:`backtracking_line_search`.

    Attributes:
        success: whether a step was accepted (otherwise the parameters were restored).
        backtracks: how many times the step was shrunk (the accepted one's index, or the maximum tried).
        improvement: surrogate gain of the accepted step (0 if none).
        kl: KL after the step (0 if none).
    """

    success: bool
    backtracks: int
    improvement: float
    kl: float


def backtracking_line_search(
    params: Sequence[torch.Tensor],
    full_step: torch.Tensor,
    evaluate: Callable[[], tuple[torch.Tensor | float, torch.Tensor | float]],
    before: float,
    max_kl: float,
    backtrack_ratio: float = 0.8,
    max_backtracks: int = 15,
) -> LineSearchResult:
    """Try ``theta + ratio^k * full_step`` for ``k = 0, 1, ...``; keep the first that improves the surrogate
    and keeps the KL within ``max_kl`` (rllab's rule), else restore ``theta``.

    ``evaluate()`` gives the objective (to maximise) and the KL at the current parameters, so that both can come
    from one forward pass; ``before`` is the objective at ``theta`` (the caller has it from the gradient).
    """
    params = list(params)
    theta = flat_params(params)
    with torch.no_grad():
        for k in range(max_backtracks):
            set_flat_params(params, theta + backtrack_ratio**k * full_step)
            objective, kl_value = (float(v) for v in evaluate())
            gain = objective - before
            if gain > 0 and kl_value <= max_kl:
                return LineSearchResult(True, k, gain, kl_value)
        set_flat_params(params, theta)
    return LineSearchResult(False, max_backtracks, 0.0, 0.0)
