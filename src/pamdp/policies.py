"""Networks: the discrete policy ``pi_d``, the conditional parameter policy ``pi_c``, value functions.

The paper's architecture (Wei, Wicke & Luke 2018, section "Hierarchical Approaches in PAMDPs"): ``pi_d``
is an MLP on the state with a softmax output; ``pi_c`` is an MLP on ``[s, onehot(a)]`` with a Tanh output
of the constant size ``m = max_a m_a``, whatever the number of actions. Exploration around ``pi_c``'s mean
is Gaussian with a learned, state-independent log-std per action and parameter.
"""

from __future__ import annotations

from collections.abc import Sequence

import torch
from torch import nn

from pamdp.distributions import HybridDistribution
from pamdp.spaces import HybridActionSpace

__all__ = ["ACTIVATIONS", "mlp", "HybridPolicy", "ValueNetwork"]

ACTIVATIONS = {"relu": nn.ReLU, "tanh": nn.Tanh, "leaky_relu": nn.LeakyReLU, "elu": nn.ELU}


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


class HybridPolicy(nn.Module):
    """``pi(a, x | s) = pi_d(a | s) * pi_c(x | s, a)``.

    Args:
        obs_dim: size of the (flat) observation.
        action_space: the hybrid action space (K actions, parameter sizes ``m_a``).
        hidden_sizes: hidden layers of both networks; the paper's PATRPO preset is ``(200, 100, 50)``.
        activation: hidden activation (``relu`` in the paper).
        init_log_std: initial log standard deviation of the parameter noise (in ``[-1, 1]`` units).
    """

    def __init__(
        self,
        obs_dim: int,
        action_space: HybridActionSpace,
        hidden_sizes: Sequence[int] = (200, 100, 50),
        activation: str = "relu",
        init_log_std: float = 0.0,
    ):
        super().__init__()
        self.obs_dim = int(obs_dim)
        self.n_actions = action_space.n_actions
        self.param_size = action_space.max_param_size
        self.pi_d = mlp(self.obs_dim, hidden_sizes, self.n_actions, activation)
        self.pi_c = mlp(self.obs_dim + self.n_actions, hidden_sizes, self.param_size, activation, nn.Tanh)
        self.log_std = nn.Parameter(torch.full((self.n_actions, self.param_size), float(init_log_std)))
        self.register_buffer("mask", torch.as_tensor(action_space.param_mask))
        # Small final layers start both policies near uniform / centred, as rllab and Spinning Up do.
        for head in (self.pi_d[-1], self.pi_c[-2]):
            nn.init.uniform_(head.weight, -3e-3, 3e-3)
            nn.init.zeros_(head.bias)

    def param_means(self, obs: torch.Tensor, onehot: torch.Tensor) -> torch.Tensor:
        """``pi_c``'s mean for the (batched) one-hot actions ``onehot`` (any leading shape)."""
        return self.pi_c(torch.cat([obs, onehot], dim=-1))

    def forward(self, obs: torch.Tensor) -> HybridDistribution:
        """The distribution at ``obs`` ``(B, obs_dim)``, with ``pi_c`` evaluated for every action in one pass."""
        batch = obs.shape[0]
        eye = torch.eye(self.n_actions, dtype=obs.dtype, device=obs.device)
        obs_k = obs.unsqueeze(1).expand(batch, self.n_actions, self.obs_dim)
        means = self.param_means(obs_k, eye.expand(batch, -1, -1))
        return HybridDistribution(self.pi_d(obs), means, self.log_std, self.mask)


class ValueNetwork(nn.Module):
    """A state-value MLP ``V(s)``, the modern choice of baseline for PATRPO."""

    def __init__(self, obs_dim: int, hidden_sizes: Sequence[int] = (64, 64), activation: str = "tanh"):
        super().__init__()
        self.net = mlp(obs_dim, hidden_sizes, 1, activation)

    def forward(self, obs: torch.Tensor) -> torch.Tensor:
        return self.net(obs).squeeze(-1)
