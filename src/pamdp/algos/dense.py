"""Hand-written forward and backward passes of :func:`~pamdp.policies.mlp` networks, for the off-policy updates.

An off-policy update with the paper's {400, 300} networks and a batch of 32 is a few dozen small matrix
products, where the calls through ``nn.Module`` and the autograd engine cost more than the arithmetic.
:class:`Dense` applies a network's layers as plain products (``addmm``) and back-propagates by hand with ATen's
own activation derivatives, so the gradients are autograd's (``tests/test_dense.py``) in a fraction of the
calls (the times: ``benchmarks/offpolicy_speed.md``).

    net = Dense.of(critic.net)                      # the module's own parameter tensors, no copies
    q, cache = net.forward_cached(x)
    grads, dx = net.backward(cache, dloss_dq, inputs=True)   # in the order of critic.net.parameters()
"""

from __future__ import annotations

from dataclasses import dataclass

import torch
from torch import nn

__all__ = ["Dense"]

_aten = torch.ops.aten


def _activation(module: nn.Module) -> tuple[str, float]:
    """An activation layer as (kind, its constant)."""
    if isinstance(module, nn.ReLU):
        return "relu", 0.0
    if isinstance(module, nn.LeakyReLU):
        return "leaky_relu", float(module.negative_slope)
    if isinstance(module, nn.Tanh):
        return "tanh", 0.0
    if isinstance(module, nn.ELU):
        return "elu", float(module.alpha)
    raise TypeError(f"Dense cannot apply the layer {module!r}; expected Linear, ReLU, LeakyReLU, Tanh or ELU")


def _apply(kind: str, c: float, z: torch.Tensor) -> torch.Tensor:
    if kind == "relu":
        return torch.relu(z)
    if kind == "leaky_relu":
        return torch.nn.functional.leaky_relu(z, c)
    if kind == "tanh":
        return torch.tanh(z)
    return torch.nn.functional.elu(z, c)


def _slope_times(kind: str, c: float, g: torch.Tensor, z: torch.Tensor, y: torch.Tensor) -> torch.Tensor:
    """``g * act'(z)``, with ``y = act(z)``: ATen's backward kernels, so exactly autograd's numbers."""
    if kind == "relu":
        return _aten.threshold_backward(g, y, 0)
    if kind == "leaky_relu":
        return _aten.leaky_relu_backward(g, z, c, False)
    if kind == "tanh":
        return _aten.tanh_backward(g, y)
    return _aten.elu_backward(g, c, 1, 1, False, z)


@dataclass(frozen=True)
class Dense:
    """An ``mlp``'s linear layers and activations, applied and differentiated by hand (no autograd graph).

    ``weights[i]`` is ``(out, in)`` as ``nn.Linear`` stores it; ``acts[i]`` is the activation after linear layer
    ``i`` (``None`` for none), as ``(kind, constant)``.
    """

    weights: tuple[torch.Tensor, ...]
    biases: tuple[torch.Tensor, ...]
    acts: tuple[tuple[str, float] | None, ...]

    @classmethod
    def of(cls, net: nn.Sequential) -> Dense:
        """The network's own parameter tensors (updates to them show through)."""
        weights, biases, acts = [], [], []
        for layer in net:
            if isinstance(layer, nn.Linear):
                if layer.bias is None:
                    raise TypeError("Dense needs linear layers with a bias, as mlp builds them")
                weights.append(layer.weight)
                biases.append(layer.bias)
                acts.append(None)
            elif not acts or acts[-1] is not None:
                raise TypeError(f"Dense expects one activation after a linear layer; got {net!r}")
            else:
                acts[-1] = _activation(layer)
        return cls(tuple(weights), tuple(biases), tuple(acts))

    def _linear(self, i: int, h: torch.Tensor) -> torch.Tensor:
        return torch.addmm(self.biases[i], h, self.weights[i].t())

    def __call__(self, x: torch.Tensor) -> torch.Tensor:
        """The network's outputs for inputs ``x`` of any leading shape."""
        h = x.reshape(-1, x.shape[-1])
        for i, act in enumerate(self.acts):
            h = self._linear(i, h)
            if act is not None:
                h = _apply(*act, h)
        return h.reshape(*x.shape[:-1], h.shape[-1])

    def forward_cached(self, x: torch.Tensor) -> tuple[torch.Tensor, list[torch.Tensor]]:
        """Outputs as :meth:`__call__`, with what :meth:`backward` needs (each layer's input and output)."""
        h = x.reshape(-1, x.shape[-1])
        cache = [h]
        for i, act in enumerate(self.acts):
            z = self._linear(i, h)
            cache.append(z)
            if act is not None:
                h = _apply(*act, z)
                cache.append(h)
            else:
                h = z
        return h.reshape(*x.shape[:-1], h.shape[-1]), cache

    def backward(
        self, cache: list[torch.Tensor], grad: torch.Tensor, weights: bool = True, inputs: bool = False
    ) -> tuple[list[torch.Tensor] | None, torch.Tensor | None]:
        """Back-propagate ``grad`` (d loss / d outputs, the outputs' shape) through the cached pass.

        Returns the parameter gradients in the order of ``net.parameters()`` (weight then bias per layer; ``None``
        unless ``weights``) and d loss / d inputs (``None`` unless ``inputs``), shaped as the flattened inputs.
        """
        g = grad.reshape(cache[-1].shape)
        pairs: list[tuple[torch.Tensor, torch.Tensor]] = []  # (weight, bias) gradients, last layer first
        pos = len(cache) - 1
        for i in reversed(range(len(self.acts))):
            act = self.acts[i]
            if act is not None:
                g = _slope_times(*act, g, cache[pos - 1], cache[pos])  # (pre-activation, output)
                pos -= 2
            else:
                pos -= 1
            h = cache[pos]  # the layer's input
            if weights:
                pairs.append((torch.mm(g.t(), h), g.sum(0)))
            if i > 0 or inputs:
                g = torch.mm(g, self.weights[i])
        grads = [t for pair in reversed(pairs) for t in pair] if weights else None
        return grads, (g if inputs else None)
