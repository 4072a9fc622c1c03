"""One way to step an optimizer, for every update: gradients in a network's parameters (``torch.autograd.grad``, or
computed by hand in :mod:`pamdp.nn.dense`), their norm clipped, then the optimizer's step.

PyTorch's own idiom, ``zero_grad(); loss.backward(); clip_grad_norm_(...); step()``, computes gradients for every
parameter the loss reaches (the critic's, inside an actor's loss) and spends more time in Python bookkeeping than
in arithmetic on the small networks of these algorithms; :func:`descend` does the same arithmetic without either
(the measured times: ``benchmarks/offpolicy_speed.md``). The off-policy algorithms build their Adams ``fused``:
one kernel per step instead of a dozen foreach passes.
"""

from __future__ import annotations

from collections.abc import Sequence

import torch

__all__ = ["descend", "apply_gradients", "clip_grads", "optimizer_step"]


def clip_grads(grads: Sequence[torch.Tensor], max_norm: float) -> torch.Tensor | None:
    """``nn.utils.clip_grad_norm_`` on gradient tensors themselves (0: no clipping), in place; the total norm
    before clipping (``None`` without)."""
    if max_norm <= 0:
        return None
    total = torch.linalg.vector_norm(torch.stack(torch._foreach_norm(list(grads))))
    torch._foreach_mul_(list(grads), (max_norm / (total + 1e-6)).clamp(max=1.0))
    return total


def optimizer_step(optimizer: torch.optim.Optimizer, grads: Sequence[torch.Tensor]) -> None:
    """``optimizer.step()`` with ``grads``, in the order of its one parameter group.

    A fused ``Adam`` whose state exists gets one ``torch._fused_adam_`` call, the kernel its own ``step`` ends
    in, without the Python bookkeeping around it; any other optimizer gets the gradients as ``.grad`` and its
    own ``step``.
    """
    group = optimizer.param_groups[0]
    params = group["params"]
    state = optimizer.state
    fast = (
        len(optimizer.param_groups) == 1
        and group.get("fused")
        and not (group["amsgrad"] or group["maximize"] or group["capturable"] or group["differentiable"])
        and not group.get("decoupled_weight_decay", False)
        and all(p in state for p in params)
    )
    if not fast:
        for p, g in zip(params, grads, strict=True):
            p.grad = g
        optimizer.step()
        return
    steps = [state[p]["step"] for p in params]
    torch._foreach_add_(steps, 1)
    beta1, beta2 = group["betas"]
    torch._fused_adam_(
        params,
        list(grads),
        [state[p]["exp_avg"] for p in params],
        [state[p]["exp_avg_sq"] for p in params],
        [],
        steps,
        amsgrad=False,
        lr=float(group["lr"]),
        beta1=float(beta1),
        beta2=float(beta2),
        weight_decay=float(group["weight_decay"]),
        eps=float(group["eps"]),
        maximize=False,
        grad_scale=None,
        found_inf=None,
    )


def apply_gradients(
    optimizer: torch.optim.Optimizer, grads: Sequence[torch.Tensor], max_norm: float = 0.0
) -> torch.Tensor | None:
    """A step of ``optimizer`` on gradients in the order of its one parameter group: their total norm clipped to
    ``max_norm`` (0: none), then :func:`optimizer_step`; returns the norm before clipping (``None`` without).
    The step of the hand-written updates (:mod:`pamdp.nn.dense`), which compute their gradients themselves."""
    total = clip_grads(grads, max_norm)
    optimizer_step(optimizer, grads)
    return total


def descend(
    optimizer: torch.optim.Optimizer, loss: torch.Tensor, params: Sequence[torch.Tensor], max_norm: float = 0.0
) -> torch.Tensor | None:
    """One step of ``optimizer`` down the gradient of ``loss`` in ``params`` (its parameter group, in order), its
    norm clipped to ``max_norm`` (0: none): the one step of every autograd update.

    The gradient comes from ``torch.autograd.grad`` in ``params`` alone, so no other network (a critic inside an
    actor's loss) computes or keeps one, and nothing needs zeroing; :func:`apply_gradients` takes the step.
    """
    return apply_gradients(optimizer, torch.autograd.grad(loss, params), max_norm)
