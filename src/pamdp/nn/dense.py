"""Hand-written forward and backward passes of :func:`~pamdp.policies.mlp` networks, for the off-policy updates:
plain ``addmm`` products and ATen's own activation derivatives, autograd's gradients (``tests/test_dense.py``) in
a fraction of the calls (why it pays: docs/performance.md; the times: ``benchmarks/offpolicy_speed.md``).

    net = Dense.of(critic.net)                      # the module's own parameter tensors, no copies
    q, cache = net.forward_cached(x)
    grads, dx = net.backward(cache, dloss_dq, inputs=True)   # in the order of critic.net.parameters()
"""

from __future__ import annotations

from dataclasses import dataclass

import torch
from torch import nn

from pamdp.nn.optim import apply_gradients

__all__ = ["Dense", "MultiPassDense"]

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

    def regression_step(
        self, optimizer: torch.optim.Optimizer, x: torch.Tensor, y: torch.Tensor, max_norm: float = 0.0
    ) -> tuple[torch.Tensor, torch.Tensor]:
        """One step of ``optimizer`` (over this network's parameters, in order) down ``mean (f(x) - y)^2`` of a
        network of one output, its gradient's norm clipped to ``max_norm`` (a critic's TD step); returns ``f(x)``
        ``(B,)`` and the errors ``f(x) - y``."""
        q, cache = self.forward_cached(x)
        q = q.squeeze(-1)
        error = q - y
        apply_gradients(optimizer, self.backward(cache, error * (2.0 / len(q)))[0], max_norm)
        return q, error


@dataclass(frozen=True)
class MultiPassDense:
    """MP-DQN's multi-pass Q-network (:class:`~pamdp.policies.QNetwork` with ``multi_pass``) applied and
    differentiated by hand, the same function as the module's own passes.

    Pass ``k`` sees the state and action ``k``'s parameters only and gives ``Q_k`` alone, so its first layer is
    ``W_s s + b + W_k x_k`` (``W_k``: the columns of ``x_k``) and its last layer the row ``k`` of the output
    weights; the layers between are :class:`Dense` over the ``K * B`` rows of all passes, pass ``k``'s ``B`` rows
    a contiguous block.
    """

    net: Dense
    """The whole network; its first and last layers are applied per pass."""
    middle: Dense
    """The layers between, applied as they are to the ``K * B`` rows."""
    obs_dim: int
    param_index: torch.Tensor
    """``(K, m)``: where action ``k``'s padded parameter ``j`` sits in the all-actions vector (0 where unused)."""
    param_mask: torch.Tensor
    """``(K, m)`` float: 1 where action ``k`` uses padded parameter ``j``."""
    order: torch.Tensor
    """``(n,)``: for parameter ``i`` of the all-actions vector, its position ``k * m + j`` among the padded blocks."""

    @staticmethod
    def block_order(param_index: torch.Tensor, param_mask: torch.Tensor) -> torch.Tensor:
        """:attr:`order` for the blocks ``param_index`` and ``param_mask``."""
        used = torch.nonzero(param_mask.flatten() > 0).squeeze(1)
        return torch.empty_like(used).index_copy_(0, param_index.flatten()[used], used)

    @classmethod
    def of(
        cls, net: nn.Sequential, obs_dim: int, param_index: torch.Tensor, param_mask: torch.Tensor, order: torch.Tensor
    ) -> MultiPassDense:
        """The network's own parameter tensors (updates to them show through), with its blocks' tables."""
        whole = Dense.of(net)
        middle = Dense(whole.weights[1:-1], whole.biases[1:-1], whole.acts[1:-1])
        return cls(whole, middle, obs_dim, param_index, param_mask, order)

    def forward_cached(self, obs: torch.Tensor, params: torch.Tensor) -> tuple[torch.Tensor, tuple]:
        """``(B, K)`` values, ``Q_k`` from pass ``k``, with what :meth:`backward` needs."""
        n, d, k = self.net, self.obs_dim, len(self.param_index)
        w_blocks = n.weights[0][:, d:].t()[self.param_index] * self.param_mask.unsqueeze(-1)  # (K, m, h): W_k^T
        xs = params.t()[self.param_index].transpose(1, 2)  # (K, B, m): x_k
        base = torch.addmm(n.biases[0], obs, n.weights[0][:, :d].t())  # W_s s + b
        if xs.shape[-1] == 1:  # one parameter an action: an outer product, which addcmul makes faster than bmm
            z = torch.addcmul(base, xs, w_blocks).view(-1, base.shape[-1])  # (K * B, h)
        else:
            z = torch.baddbmm(base, xs, w_blocks).view(-1, base.shape[-1])
        h = _apply(*n.acts[0], z) if n.acts[0] is not None else z
        hidden, middle = self.middle.forward_cached(h)
        hidden = hidden.view(k, -1, hidden.shape[-1])  # (K, B, h')
        # Q_k = w_k . h of pass k, as (1, h') x (h', B) products: bmm's matrix-vector form is several times slower
        q = torch.baddbmm(n.biases[-1][:, None, None], n.weights[-1].unsqueeze(1), hidden.transpose(1, 2)).view(k, -1)
        return q.t(), (obs, xs, w_blocks, z, h, middle, hidden)

    def backward(
        self, cache: tuple, grad: torch.Tensor, weights: bool = True, inputs: bool = False
    ) -> tuple[list[torch.Tensor] | None, torch.Tensor | None]:
        """Back-propagate ``grad`` (d loss / d Q, ``(B, K)``) through the cached passes: the parameter gradients in
        the order of ``net.parameters()`` (``None`` unless ``weights``) and d loss / d params, ``(B, sum_a m_a)``
        (``None`` unless ``inputs``)."""
        obs, xs, w_blocks, z, h, middle, hidden = cache
        n, k, batch = self.net, len(self.param_index), len(obs)
        g_q = grad.t().contiguous().unsqueeze(-1)  # (K, B, 1)
        g = (g_q * n.weights[-1].unsqueeze(1)).view(-1, hidden.shape[-1])  # d/d hidden, (K * B, h')
        mid_grads, g = self.middle.backward(middle, g, weights=weights, inputs=True)
        if n.acts[0] is not None:
            g = _slope_times(*n.acts[0], g, z, h)
        g = g.view(k, batch, -1)  # d/d z of pass k, (K, B, h)
        grads = None
        if weights:
            g_s = g.sum(0)
            w_k = torch.bmm(xs.transpose(1, 2), g).view(-1, g.shape[-1])[self.order]  # (n, h): rows of W_x^T
            first = torch.cat([torch.mm(g_s.t(), obs), w_k.t()], dim=1)
            last = torch.bmm(g_q.transpose(1, 2), hidden).squeeze(1)  # (K, h'): row k from pass k
            grads = [first, g_s.sum(0), *mid_grads, last, grad.sum(0)]
        dparams = None
        if inputs:  # pass k's d/d x_k, (K, B, m), to the all-actions vector
            dparams = torch.bmm(g, w_blocks.transpose(1, 2)).transpose(0, 1).reshape(batch, -1)[:, self.order]
        return grads, dparams
