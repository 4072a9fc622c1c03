"""Networks: the discrete policy ``pi_d``, the conditional parameter policy ``pi_c``, value functions.

The paper's architecture (Wei, Wicke & Luke 2018, section "Hierarchical Approaches in PAMDPs"): ``pi_d``
is an MLP on the state with a softmax output; ``pi_c`` is an MLP on ``[s, onehot(a)]`` with a Tanh output
of the constant size ``m = max_a m_a``, whatever the number of actions. Exploration around ``pi_c``'s mean
is Gaussian with a learned, state-independent log-std per action and parameter.

``pi_c`` can instead read the state alone and output every action's mean at once, ``K * m`` Tanh outputs of
which action ``a``'s ``m`` are its mean (``pi_c_input="state"``, P-DQN's parameter network and H-PPO's
parameter actor): still a policy conditioned on the action, through its output block instead of its input.
Every action's mean is then one pass of the network on the state, where the one-hot input takes ``K`` passes
of its hidden layers; at the thousand actions of Hard Move n = 10 that is what an update costs.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import torch
import torch.nn.functional as F
from torch import nn

from pamdp.distributions import (
    LOG_STD_MAX,
    LOG_STD_MIN,
    HybridDistribution,
    SquashedHybrid,
    draw_action,
    draw_params,
    gumbel_softmax_sample,
    masked_logits,
)
from pamdp.nn.dense import Dense, MultiPassDense
from pamdp.spaces import HybridActionSpace

__all__ = [
    "ACTIVATIONS",
    "PI_C_INPUTS",
    "EVERY_ACTION_ROWS",
    "mlp",
    "small_init_",
    "hierarchical_mlps",
    "every_action_linear",
    "every_action_mlp",
    "in_chunks",
    "LinearizedMLP",
    "HybridPolicy",
    "GumbelHybridPolicy",
    "FORMS",
    "HybridSACActor",
    "ValueNetwork",
    "TwinQ",
    "QNetwork",
    "DeterministicActor",
]

ACTIVATIONS = {"relu": nn.ReLU, "tanh": nn.Tanh, "leaky_relu": nn.LeakyReLU, "elu": nn.ELU}
PI_C_INPUTS = ("onehot", "state")
"""What ``pi_c`` reads: ``[s, onehot(a)]`` (the paper's) or ``s`` alone with a block of outputs per action."""
EVERY_ACTION_ROWS = 2**14
"""(state, action) rows of one chunk of an every-action pass without gradients (:func:`in_chunks`): small enough
that the allocator reuses its hidden activations' memory instead of mapping (and zeroing) it afresh."""


def mlp(
    in_size: int,
    hidden_sizes: Sequence[int],
    out_size: int,
    activation: str = "relu",
    output_activation: type[nn.Module] | None = None,
) -> nn.Sequential:
    """A fully connected network ``in -> hidden... -> out`` with the named hidden activation."""
    if activation not in ACTIVATIONS:
        raise ValueError(f"unknown activation {activation!r}; expected one of {', '.join(ACTIVATIONS)}")
    layers: list[nn.Module] = []
    sizes = [in_size, *hidden_sizes]
    for i, o in zip(sizes[:-1], sizes[1:]):
        layers += [nn.Linear(i, o), ACTIVATIONS[activation]()]
    layers.append(nn.Linear(sizes[-1], out_size))
    if output_activation is not None:
        layers.append(output_activation())
    return nn.Sequential(*layers)


def small_init_(*layers: nn.Linear) -> None:
    """Draw final layers' weights in ``[-3e-3, 3e-3]`` with zero biases, so that a policy starts near uniform over
    the discrete actions and near the centre of the parameter box, as rllab's and Spinning Up's policies do."""
    for layer in layers:
        nn.init.uniform_(layer.weight, -3e-3, 3e-3)
        nn.init.zeros_(layer.bias)


def hierarchical_mlps(
    obs_dim: int,
    n_actions: int,
    hidden_sizes: Sequence[int],
    activation: str,
    pi_c_size: int,
    pi_c_input: str = "onehot",
    tanh: bool = False,
) -> tuple[nn.Sequential, nn.Sequential]:
    """The hierarchical policy's two networks (Wei, Wicke & Luke 2018): ``pi_d = mlp(s)`` with K logits and
    ``pi_c = mlp([s, onehot(a)])`` (``pi_c_input="state"``: ``mlp(s)``) with ``pi_c_size`` outputs, a Tanh after
    them with ``tanh``; both final layers small (:func:`small_init_`). The heads on them are each method's:
    PATRPO's and PAPPO's Gaussian (:class:`HybridPolicy`), PASVG(0)'s Gumbel-Softmax and Tanh-squashed noise,
    Hybrid SAC's squashed Gaussian with a learned log-std per state."""
    if pi_c_input not in PI_C_INPUTS:
        raise ValueError(f"unknown pi_c_input {pi_c_input!r}; expected one of {', '.join(PI_C_INPUTS)}")
    pi_d = mlp(obs_dim, hidden_sizes, n_actions, activation)
    pi_c_in = obs_dim + n_actions if pi_c_input == "onehot" else obs_dim
    pi_c = mlp(pi_c_in, hidden_sizes, pi_c_size, activation, nn.Tanh if tanh else None)
    small_init_(pi_d[-1], pi_c[-2] if tanh else pi_c[-1])
    return pi_d, pi_c


def every_action_linear(
    obs: torch.Tensor, weight: torch.Tensor, bias: torch.Tensor | None, a: torch.Tensor | None = None
) -> torch.Tensor:
    """``F.linear(cat([obs, onehot(k)]), weight, bias)`` for every action ``k``: ``(B, K, out)``; given actions
    ``a`` ``(B,)``, for ``k = a`` only: ``(B, out)``.

    The one-hot part of the input selects column ``k`` of the weight's last ``K`` columns, so the ``B * K``
    inputs of width ``d + K`` are never built: one ``(B, out)`` product for the state plus a broadcast add,
    ``K`` times cheaper than the product over the one-hots. Linear in ``(weight, bias)``, so the same function
    maps parameter tangents (:class:`LinearizedMLP`'s ``first``).
    """
    d = obs.shape[-1]
    state = F.linear(obs, weight[:, :d], bias)
    columns = weight[:, d:].T.contiguous()  # else the sum takes the transpose's layout and the next layer copies it
    return state.unsqueeze(-2) + columns if a is None else state + columns[a]


def every_action_mlp(net: nn.Sequential, obs: torch.Tensor, a: torch.Tensor | None = None) -> torch.Tensor:
    """An :func:`mlp` on ``[s, onehot(k)]`` for every action ``k``, ``(B, K, out)``, or for ``k = a``, ``(B, out)``:
    its first layer by :func:`every_action_linear`, without building the one-hot inputs."""
    first = net[0]
    return net[1:](every_action_linear(obs, first.weight, first.bias, a))


def in_chunks(fn: Callable[..., torch.Tensor], n_actions: int, *batches: torch.Tensor) -> torch.Tensor:
    """``fn(*batches)``, an every-action pass over ``n_actions`` actions per state; without gradients, on chunks
    of at most :data:`EVERY_ACTION_ROWS` (state, action) rows concatenated (each state's rows are computed alone,
    so the result is the same)."""
    step = max(1, EVERY_ACTION_ROWS // n_actions)
    if torch.is_grad_enabled() or len(batches[0]) <= step:
        return fn(*batches)
    return torch.cat([fn(*parts) for parts in zip(*(b.split(step) for b in batches))])


def _activation_slope(module: nn.Module, pre: torch.Tensor, out: torch.Tensor) -> torch.Tensor:
    """The elementwise derivative of an activation layer at pre-activations ``pre`` (outputs ``out``)."""
    if isinstance(module, nn.ReLU):
        return (pre > 0).to(pre.dtype)
    if isinstance(module, nn.LeakyReLU):
        slope = module.negative_slope
        return (pre > 0).to(pre.dtype) * (1.0 - slope) + slope
    if isinstance(module, nn.Tanh):
        return 1.0 - out * out
    if isinstance(module, nn.ELU):
        return torch.where(pre > 0, torch.ones_like(out), out + module.alpha)
    raise TypeError(f"no derivative known for the layer {module!r}; expected Linear, ReLU, LeakyReLU, Tanh or ELU")


class LinearizedMLP:
    """An :func:`mlp` at one batch of inputs: its outputs (with their autograd graph) and its Jacobian-vector
    product in the parameters, ``J v``, by forward-mode propagation through the activations cached here.

    ``J v`` costs two matrix products a layer and reuses the forward pass, where ``torch.func.jvp`` would run
    the forward pass again on every call; a Gauss-Newton Fisher-vector product needs one per CG iteration.

    Args:
        net: a ``Sequential`` of ``Linear`` layers and elementwise activations (what :func:`mlp` builds).
        inputs: the network's input, which does not depend on its parameters.
        first: ``(weight, bias) -> pre-activation`` of the first layer, to use in place of
            ``F.linear(inputs, weight, bias)`` (the same linear map, computed another way, e.g. by
            :func:`every_action_linear`); ``inputs`` is then unused.
    """

    def __init__(self, net: nn.Sequential, inputs: torch.Tensor | None, first: Callable | None = None):
        self.steps: list[tuple[nn.Linear, torch.Tensor | None] | torch.Tensor] = []  # (layer, input) or a slope
        self.first = first
        h = inputs
        for i, module in enumerate(net):
            if i == 0 and first is not None:
                out, h = first(module.weight, module.bias), None
            else:
                out = module(h)
            if isinstance(module, nn.Linear):
                self.steps.append((module, None if h is None else h.detach()))
            else:
                self.steps.append(_activation_slope(module, h.detach(), out.detach()))
            h = out
        self.outputs = h

    def jvp(self, tangents: Sequence[torch.Tensor]) -> torch.Tensor:
        """``J v`` for parameter tangents in the order of ``net.parameters()`` (weight then bias, per layer)."""
        tangents = iter(tangents)
        dh: torch.Tensor | None = None  # the tangent of the current hidden layer (the input has none)
        with torch.no_grad():
            for step in self.steps:
                if isinstance(step, tuple):
                    layer, h = step
                    d_weight = next(tangents)
                    d_bias = next(tangents) if layer.bias is not None else None
                    dz = self.first(d_weight, d_bias) if h is None else F.linear(h, d_weight, d_bias)
                    dh = dz if dh is None else dz + F.linear(dh, layer.weight)
                else:
                    dh = step * dh
        return dh


class HybridPolicy(nn.Module):
    """``pi(a, x | s) = pi_d(a | s) * pi_c(x | s, a)``.

    Args:
        obs_dim: size of the (flat) observation.
        action_space: the hybrid action space (K actions, parameter sizes ``m_a``).
        hidden_sizes: hidden layers of both networks; the paper's PATRPO preset is ``(200, 100, 50)``.
        activation: hidden activation (``relu`` in the paper).
        init_log_std: initial log standard deviation of the parameter noise (in ``[-1, 1]`` units).
        pi_c_input: ``"onehot"`` (the paper's ``pi_c([s, onehot(a)])``) or ``"state"`` (``pi_c(s)``'s output block
            ``a``); see the module docstring.
    """

    def __init__(
        self,
        obs_dim: int,
        action_space: HybridActionSpace,
        hidden_sizes: Sequence[int] = (200, 100, 50),
        activation: str = "relu",
        init_log_std: float = 0.0,
        pi_c_input: str = "onehot",
    ):
        super().__init__()
        self.obs_dim = int(obs_dim)
        self.n_actions = action_space.n_actions
        self.param_size = action_space.max_param_size
        self.onehot_input = pi_c_input == "onehot"
        size = self.param_size if self.onehot_input else self.n_actions * self.param_size
        self.pi_d, self.pi_c = hierarchical_mlps(
            self.obs_dim, self.n_actions, hidden_sizes, activation, size, pi_c_input, tanh=True
        )
        self.log_std = nn.Parameter(torch.full((self.n_actions, self.param_size), float(init_log_std)))
        self.register_buffer("mask", torch.tensor(action_space.param_mask))

    def _blocks(self, out: torch.Tensor) -> torch.Tensor:
        """A state-input ``pi_c``'s outputs ``(..., K * m)`` as every action's mean ``(..., K, m)``."""
        return out.unflatten(-1, (self.n_actions, self.param_size))

    def every_param_mean(self, obs: torch.Tensor) -> torch.Tensor:
        """``pi_c``'s means for every action at ``obs`` ``(B, obs_dim)``: ``(B, K, m)``; with the one-hot input,
        ``pi_c`` of every one-hot in one pass (its first layer by :func:`every_action_linear`)."""
        if not self.onehot_input:
            return self._blocks(self.pi_c(obs))
        return in_chunks(lambda o: every_action_mlp(self.pi_c, o), self.n_actions, obs)

    def forward(self, obs: torch.Tensor, action_mask: torch.Tensor | None = None) -> HybridDistribution:
        """The distribution at ``obs`` ``(B, obs_dim)``, with ``pi_c`` evaluated for every action in one pass;
        ``action_mask`` (bool ``(B, K)``, True = allowed) restricts ``pi_d`` to the allowed actions."""
        means = self.every_param_mean(obs)
        return HybridDistribution(masked_logits(self.pi_d(obs), action_mask), means, self.log_std, self.mask)

    def act(
        self,
        obs: torch.Tensor,
        action_mask: torch.Tensor | None = None,
        deterministic: bool = False,
        generator: torch.Generator | None = None,
    ) -> tuple[torch.Tensor, torch.Tensor]:
        """``forward(obs, action_mask)``'s ``mode()`` or ``sample(generator)`` (the same draws), with ``pi_c`` run for
        the chosen action only: acting needs no other action's mean."""
        a = draw_action(masked_logits(self.pi_d(obs), action_mask), deterministic, generator)
        if self.onehot_input:
            mu = every_action_mlp(self.pi_c, obs, a)
        else:
            mu = self._blocks(self.pi_c(obs))[torch.arange(len(a)), a]
        return a, draw_params(mu, self.log_std[a], self.mask[a], deterministic, generator)

    def linearize(
        self, obs: torch.Tensor
    ) -> tuple[HybridDistribution, Callable[[dict[str, torch.Tensor]], tuple[torch.Tensor, ...]]]:
        """The distribution at ``obs`` (as :meth:`forward`) and the Jacobian-vector product of its raw outputs.

        The product takes parameter tangents by name (``dict(self.named_parameters())``'s keys) and returns the
        tangents of ``(logits (B, K), means (B, K, m), log_std (K, m))``, the distribution's own parameters.
        The logits are unmasked: a KL's Hessian at a masked distribution gives masked actions no weight, so a
        Fisher-vector product needs no mask beyond the old distribution's.
        """
        lin_d = LinearizedMLP(self.pi_d, obs)
        if self.onehot_input:
            lin_c = LinearizedMLP(self.pi_c, None, lambda weight, bias: every_action_linear(obs, weight, bias))
            means, blocks = lin_c.outputs, (lambda d: d)
        else:
            lin_c = LinearizedMLP(self.pi_c, obs)
            means, blocks = self._blocks(lin_c.outputs), self._blocks
        names_d = [f"pi_d.{n}" for n, _ in self.pi_d.named_parameters()]
        names_c = [f"pi_c.{n}" for n, _ in self.pi_c.named_parameters()]

        def jvp(tangents: dict[str, torch.Tensor]) -> tuple[torch.Tensor, ...]:
            d_logits = lin_d.jvp([tangents[n] for n in names_d])
            d_means = blocks(lin_c.jvp([tangents[n] for n in names_c]))
            return d_logits, d_means, tangents["log_std"]

        return HybridDistribution(lin_d.outputs, means, self.log_std, self.mask), jvp


class GumbelHybridPolicy(nn.Module):
    """``pi_d`` (logits over K actions) and ``pi_c`` (pre-Tanh means of ``m`` parameters given ``[s, a]``).

    The parameter noise has a state-independent log-std per action and parameter; parameters an action does
    not use (its entries beyond ``m_a``) are set to 0 so they carry no noise into the critic.
    """

    def __init__(self, obs_dim: int, hybrid: HybridActionSpace, hidden_sizes, activation: str, init_log_std: float):
        super().__init__()
        self.n_actions, self.param_size = hybrid.n_actions, hybrid.max_param_size
        self.pi_d, self.pi_c = hierarchical_mlps(obs_dim, self.n_actions, hidden_sizes, activation, self.param_size)
        self.log_std = nn.Parameter(torch.full((self.n_actions, self.param_size), float(init_log_std)))
        self.register_buffer("mask", torch.tensor(hybrid.param_mask, dtype=torch.float32))

    def std(self) -> torch.Tensor:
        """The parameter noise's std per action and parameter, ``(K, m)``."""
        return self.log_std.clamp(LOG_STD_MIN, LOG_STD_MAX).exp()

    def params(self, obs: torch.Tensor, index: torch.Tensor, a: torch.Tensor, eta_x: torch.Tensor) -> torch.Tensor:
        """``x = g(s, a, eta_x)``: ``pi_c``'s parameters for action ``a`` (one-hot or soft; ``index`` its argmax)."""
        return torch.tanh(self.pi_c(torch.cat([obs, a], dim=-1)) + self.std()[index] * eta_x) * self.mask[index]

    def params_all(self, obs: torch.Tensor, eta_x: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Every action's parameters for the noise ``eta_x``: ``(obs_k, onehots, x)``, each ``(B, K, .)``.

        ``obs_k`` and ``onehots`` are the critic's matching state and action inputs, so that
        ``critic(obs_k, onehots, x)`` is ``Q(s, k, x_k)`` for every ``k`` in one batched pass.
        """
        batch, K = len(obs), self.n_actions
        onehots = torch.eye(K, dtype=obs.dtype, device=obs.device).expand(batch, K, K)
        obs_k = obs.unsqueeze(-2).expand(batch, K, obs.shape[-1])
        means = every_action_mlp(self.pi_c, obs)  # without building the B * K inputs (as params would)
        return obs_k, onehots, torch.tanh(means + self.std() * eta_x.unsqueeze(-2)) * self.mask

    def forward(
        self,
        obs: torch.Tensor,
        eta_a: torch.Tensor,
        eta_x: torch.Tensor,
        temperature: float,
        hard: bool,
        mask: torch.Tensor | None = None,
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor, torch.Tensor]:
        """``(logits, index, a, x)`` for the noise ``(eta_a, eta_x)``: ``pi_d``'s logits (restricted to the actions
        ``mask`` allows), the action, the critic's action input ``a`` and the parameters ``x``, so an update runs
        ``pi_d`` once."""
        logits = masked_logits(self.pi_d(obs), mask)
        index, a = gumbel_softmax_sample(logits, eta_a, temperature, hard)
        return logits, index, a, self.params(obs, index, a, eta_x)

    def mode(self, obs: torch.Tensor, mask: torch.Tensor | None = None) -> tuple[torch.Tensor, torch.Tensor]:
        """The greedy action: the most probable (allowed) discrete action and its mean parameters."""
        index = masked_logits(self.pi_d(obs), mask).argmax(-1)
        onehot = F.one_hot(index, self.n_actions).to(obs.dtype)
        return index, torch.tanh(self.pi_c(torch.cat([obs, onehot], dim=-1))) * self.mask[index]


FORMS = ("flat", "hierarchical")
"""Hybrid SAC's policy forms (:class:`HybridSACActor`)."""


class HybridSACActor(nn.Module):
    """The policy, ``flat`` (``mlp(s) -> [logits | means | log-stds]``) or ``hierarchical`` (``pi_d = mlp(s)``,
    ``pi_c = mlp([s, onehot(a)])`` for every ``a``); ``forward(obs, mask)`` is a :class:`SquashedHybrid`."""

    def __init__(self, obs_dim: int, hybrid: HybridActionSpace, form: str, hidden_sizes, activation: str):
        super().__init__()
        if form not in FORMS:
            raise ValueError(f"form = {form!r}; expected one of {', '.join(FORMS)}")
        self.form, self.n_actions, self.m = form, hybrid.n_actions, hybrid.max_param_size
        mask = hybrid.param_mask
        self.register_buffer("param_mask", torch.tensor(mask, dtype=torch.float32))
        self.register_buffer("param_index", torch.tensor(hybrid.param_index, dtype=torch.long).view(-1))
        self.total = total = hybrid.total_param_size
        # the all-actions vector's entries in the flattened padded (K * m) layout
        self.register_buffer("flat_index", torch.tensor(np.flatnonzero(mask), dtype=torch.long))
        # every action with all m parameters (Hard Move, Platform; not Catch Point, whose second action has none):
        # the two layouts are one, no gather needed
        self.dense = bool(mask.all())
        if form == "flat":  # starts near uniform, centred, with unit noise, as the hierarchical form does
            self.net = mlp(obs_dim, hidden_sizes, self.n_actions + 2 * total, activation)
            small_init_(self.net[-1])
        else:
            self.pi_d, self.pi_c = hierarchical_mlps(obs_dim, self.n_actions, hidden_sizes, activation, 2 * self.m)

    def _padded(self, flat: torch.Tensor) -> torch.Tensor:
        """``(B, sum_a m_a)`` all-actions values as ``(B, K, m)``, zero where unused."""
        if self.dense:
            return flat.reshape(-1, self.n_actions, self.m)
        return flat[:, self.param_index].view(-1, self.n_actions, self.m) * self.param_mask

    def forward(self, obs: torch.Tensor, mask: torch.Tensor | None = None) -> SquashedHybrid:
        if self.form == "flat":
            logits, means, log_stds = self.net(obs).split([self.n_actions, self.total, self.total], dim=-1)
            mean, log_std = self._padded(means), self._padded(log_stds)
        else:
            mean, log_std = every_action_mlp(self.pi_c, obs).split(self.m, dim=-1)
            logits = self.pi_d(obs)
        log_std = log_std.clamp(LOG_STD_MIN, LOG_STD_MAX)
        param_mask = None if self.dense else self.param_mask
        return SquashedHybrid(masked_logits(logits, mask), mean, log_std, param_mask)

    def flat_params(self, x: torch.Tensor) -> torch.Tensor:
        """Every action's parameters ``(B, K, m)`` as the critics' all-actions vector ``(B, sum_a m_a)``."""
        flat = x.reshape(x.shape[0], -1)
        return flat if self.dense else flat[:, self.flat_index]


class ValueNetwork(nn.Module):
    """A state-value MLP ``V(s)``, the modern choice of baseline for PATRPO."""

    def __init__(self, obs_dim: int, hidden_sizes: Sequence[int] = (64, 64), activation: str = "tanh"):
        super().__init__()
        self.net = mlp(obs_dim, hidden_sizes, 1, activation)

    def forward(self, obs: torch.Tensor) -> torch.Tensor:
        return self.net(obs).squeeze(-1)


class TwinQ(nn.Module):
    """Critics ``Q_1, Q_2`` of the same shape on ``[s, inputs...]``, for the clipped double Q-learning of TD3
    (Fujimoto et al. 2018) and SAC: a target takes the smaller of the two target critics' values (:meth:`smaller`).
    With ``twin=False`` there is ``Q_1`` alone (``q2`` is ``None``), whose value :meth:`smaller` then is."""

    def __init__(self, in_size: int, out_size: int, hidden_sizes, activation: str, twin: bool = True):
        super().__init__()
        self.q1 = mlp(in_size, hidden_sizes, out_size, activation)
        self.q2 = mlp(in_size, hidden_sizes, out_size, activation) if twin else None

    def forward(self, obs: torch.Tensor, *inputs: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor | None]:
        inp = torch.cat([obs, *inputs], dim=-1)
        return self.q1(inp), None if self.q2 is None else self.q2(inp)

    def smaller(self, obs: torch.Tensor, *inputs: torch.Tensor) -> torch.Tensor:
        q1, q2 = self(obs, *inputs)
        return q1 if q2 is None else torch.minimum(q1, q2)


class QNetwork(nn.Module):
    """``Q(s, x)``: K action values from the state and every action's parameters.

    With ``multi_pass`` (MP-DQN), ``Q_k`` is read from a pass that sees only ``x_k``. The passes' input rows are
    never built: pass ``k``'s first layer is ``W_s s + W_k x_k + b`` and its output layer computes ``Q_k`` alone,
    the same function at ``K`` times fewer operations; the passes are one flat batch of ``K * B`` rows, pass
    ``k``'s a contiguous block (a strided layout walked memory slowly; :class:`~pamdp.nn.dense.MultiPassDense`
    differentiates it by hand).
    """

    def __init__(self, obs_dim: int, hybrid: HybridActionSpace, hidden_sizes, activation: str, multi_pass: bool):
        super().__init__()
        self.n_actions = hybrid.n_actions
        self.multi_pass = multi_pass
        self.net = mlp(obs_dim + hybrid.total_param_size, hidden_sizes, hybrid.n_actions, activation)
        index = torch.tensor(hybrid.param_index, dtype=torch.long)
        mask = torch.tensor(hybrid.param_mask, dtype=torch.float32)
        self.obs_dim = obs_dim
        self.register_buffer("param_index", index, persistent=False)
        self.register_buffer("param_mask", mask, persistent=False)
        self.register_buffer("param_order", MultiPassDense.block_order(index, mask), persistent=False)

    def forward(self, obs: torch.Tensor, params: torch.Tensor) -> torch.Tensor:
        if not self.multi_pass:
            return self.net(torch.cat([obs, params], dim=-1))
        return in_chunks(lambda o, p: self.forward_cached(o, p)[0], self.n_actions, obs, params)

    def forward_cached(self, obs: torch.Tensor, params: torch.Tensor) -> tuple[torch.Tensor, tuple]:
        """The ``(B, K)`` values by the hand-written passes of :mod:`pamdp.nn.dense` (differentiable by autograd
        too), with what :meth:`backward` needs."""
        if not self.multi_pass:
            net = Dense.of(self.net)
            q, cache = net.forward_cached(torch.cat([obs, params], dim=-1))
        else:
            net = MultiPassDense.of(self.net, self.obs_dim, self.param_index, self.param_mask, self.param_order)
            q, cache = net.forward_cached(obs, params)
        return q, (net, cache)

    def backward(self, cached: tuple, grad: torch.Tensor, weights: bool = True) -> list[torch.Tensor] | torch.Tensor:
        """From :meth:`forward_cached`'s cache and d loss / d Q ``(B, K)``: the gradients in the order of
        ``parameters()`` if ``weights``, else d loss / d params ``(B, sum_a m_a)``."""
        net, cache = cached
        if weights:
            return net.backward(cache, grad)[0]
        d_in = net.backward(cache, grad, weights=False, inputs=True)[1]
        return d_in if self.multi_pass else d_in[:, self.obs_dim :]

    def _load_from_state_dict(self, state_dict, prefix, *args, **kwargs):
        state_dict.pop(prefix + "blocks", None)  # models saved before the block table was dropped hold it
        super()._load_from_state_dict(state_dict, prefix, *args, **kwargs)


class DeterministicActor(nn.Module):
    """``mu(s)``: an :func:`mlp` whose outputs are meant to lie in ``[-1, 1]``, by a Tanh after them with ``squash``,
    else by the update's bounded gradients (acting clamps them). PADDPG's actor outputs K action scores then every
    action's parameters (``hybrid`` with ``offset = K``), P-DQN's every action's parameters (``hybrid``), HyAR's a
    latent action, which :meth:`to_latent` maps onto the latent box ``[low, high]`` (``box``).

    ``passthrough``: Bester et al.'s passthrough layer (P-DQN's ``param_passthrough``), a fixed linear map of the
    state, the rows of ``[W | b]`` flattened, added to the outputs and never trained; the output layer then starts at
    zero, so that the first ``mu`` is the map.
    """

    def __init__(
        self,
        obs_dim: int,
        out_size: int,
        hidden_sizes: Sequence[int],
        activation: str,
        squash: bool,
        hybrid: HybridActionSpace | None = None,
        offset: int = 0,
        passthrough: Sequence[float] = (),
        box: bool = False,
    ):
        super().__init__()
        self.offset = offset
        self.net = mlp(obs_dim, hidden_sizes, out_size, activation, nn.Tanh if squash else None)
        weight = bias = None
        if passthrough:
            if len(passthrough) != out_size * (obs_dim + 1):
                raise ValueError(
                    f"param_passthrough has {len(passthrough)} numbers; expected {out_size * (obs_dim + 1)} for this "
                    f"env: {out_size} parameters x ({obs_dim} observation features + 1 bias), row by row"
                )
            table = torch.tensor(passthrough, dtype=torch.float32).view(out_size, obs_dim + 1)
            weight, bias = table[:, :-1].contiguous(), table[:, -1].contiguous()
            nn.init.zeros_(self.net[-1].weight)
            nn.init.zeros_(self.net[-1].bias)
        self.register_buffer("passthrough_weight", weight)
        self.register_buffer("passthrough_bias", bias)
        if hybrid is not None:  # where action a's padded parameter i sits in the outputs (0 where unused)
            index = np.where(hybrid.param_mask, offset + hybrid.param_index, 0)
            self.register_buffer("param_index", torch.as_tensor(index, dtype=torch.long))
            self.register_buffer("param_mask", torch.tensor(hybrid.param_mask, dtype=torch.float32))
        if box:
            self.register_buffer("low", -torch.ones(out_size))
            self.register_buffer("high", torch.ones(out_size))

    def forward(self, obs: torch.Tensor) -> torch.Tensor:
        if self.passthrough_weight is None:
            return self.net(obs)
        return self.net(obs) + F.linear(obs, self.passthrough_weight, self.passthrough_bias)

    def select(self, out: torch.Tensor, a: torch.Tensor) -> torch.Tensor:
        """Action ``a``'s parameters out of the output vectors ``out``, padded with zeros to ``m = max_a m_a``."""
        return out.gather(1, self.param_index[a]) * self.param_mask[a]

    def action(self, out: torch.Tensor, mask: torch.Tensor | None = None) -> tuple[torch.Tensor, torch.Tensor]:
        """The executed action of output vectors ``out`` that start with action scores: the argmax of the scores
        (among the actions ``mask`` allows) and its parameters, clamped to ``[-1, 1]``."""
        a = masked_logits(out[:, : self.offset], mask).argmax(-1)
        return a, self.select(out, a).clamp(-1.0, 1.0)

    def to_latent(self, u: torch.Tensor) -> torch.Tensor:
        """Outputs ``u`` in ``[-1, 1]`` mapped onto the latent box ``[low, high]``."""
        return self.low + (u + 1.0) * 0.5 * (self.high - self.low)
