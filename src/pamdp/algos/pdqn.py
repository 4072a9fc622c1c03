"""P-DQN and MP-DQN: Q-learning over parameterized actions with a deterministic parameter actor.

P-DQN (Xiong et al. 2018, arXiv 1810.06394) acts by ``argmax_k Q_k(s, x(s))`` with an actor ``x(s)`` of every
action's parameters; MP-DQN (Bester, James & Konidaris 2019, arXiv 1905.04388; ``multi_pass = True``) reads
``Q_k`` from a pass that sees only ``x_k``. The update is back-propagated by hand (:mod:`pamdp.nn.dense`;
``tests/test_pdqn.py`` holds the autograd form it must equal). The maths: docs/algorithms.md, "P-DQN and MP-DQN".
"""

from __future__ import annotations

import copy
import dataclasses
import math

import numpy as np
import torch
import torch.nn.functional as F

from pamdp.algos.base import Algorithm
from pamdp.algos.offpolicy import (
    DeterministicActorConfig,
    EpsilonSchedule,
    OffPolicyConfig,
    OffPolicyLoop,
    OUNoise,
    bounded,
    soft_updater,
    uniform_actions,
)
from pamdp.algos.settings import POSITIVE, AlgoConfig, Check, setting
from pamdp.distributions import masked_logits
from pamdp.nn.dense import Dense
from pamdp.nn.optim import apply_gradients
from pamdp.policies import DeterministicActor, QNetwork

__all__ = ["PDQN", "PDQNConfig"]


@dataclasses.dataclass(frozen=True)
class PDQNConfig(DeterministicActorConfig, OffPolicyConfig, AlgoConfig):
    """P-DQN's and MP-DQN's settings. The defaults are the ``paper`` preset: Bester et al.'s Platform settings,
    recalled from their paper rather than checked against its text (provisional); values it does not give are
    marked as assumptions in the help."""

    multi_pass: bool = setting(
        False, "MP-DQN: Q_k from a pass that sees only action k's parameters; false: P-DQN's joint input."
    )
    hidden_sizes: tuple[int, ...] = OffPolicyConfig.shared_setting(
        "hidden_sizes", (128,), "Bester et al. on Platform: one layer of 128"
    )
    param_passthrough: tuple[float, ...] = setting(
        (),
        "A fixed linear start of the parameters (Bester et al.'s passthrough layer, how their Goal runs start from "
        "Masson's hand-set weights): a map from the observation to every action's parameters, in [-1, 1] units, "
        "added to the actor's output and never trained. One row per parameter of the all-actions vector, each the "
        "observation's weights then a bias, flattened row by row; with it the actor's output layer starts at zero, "
        "so the first policy is the map. Empty: none. Needs bound invert or zero.",
        Check(
            lambda v: not v or (len(v) >= 2 and all(math.isfinite(x) for x in v)),
            "none, or finite numbers in rows of the observation's weights and a bias",
        ),
    )
    q_lr: float = setting(1e-3, "Adam learning rate of the Q-network (Bester et al.: 1e-3).", POSITIVE)
    actor_lr: float = setting(
        1e-4, "Adam learning rate of the parameter actor (Bester et al. on Platform: 1e-4).", POSITIVE
    )
    grad_clip: float = OffPolicyConfig.shared_setting("grad_clip", 10.0, "assumed: 10")
    batch_size: int = OffPolicyConfig.shared_setting("batch_size", 128, "Bester et al.: 128")
    gamma: float = OffPolicyConfig.shared_setting("gamma", 0.9, "Bester et al. on Platform: 0.9")
    tau_q: float = OffPolicyConfig.tau_setting(0.1, "of the Q-network; Bester et al.: 0.1")
    tau_actor: float = OffPolicyConfig.tau_setting(0.001, "of the actor; Bester et al.: 0.001")
    beta: float = OffPolicyConfig.shared_setting("beta", 0.0, "0 on Platform")
    epsilon_end: float = OffPolicyConfig.shared_setting("epsilon_end", 0.01, "Bester et al.: 0.01")
    epsilon_steps: int = OffPolicyConfig.shared_setting(
        "epsilon_steps", 5_000, "Bester et al.: 1000 episodes; Platform's early episodes last 2 to 5 steps"
    )
    explore_params: bool = setting(
        False,
        "With an epsilon draw, also draw that action's parameters uniformly in [-1, 1] (Xiong et al.); false "
        "keeps the actor's, noise included (assumed for Bester et al.).",
    )
    ou_sigma: float = OffPolicyConfig.shared_setting("ou_sigma", 0.0001, "Bester et al.: 1e-4")
    buffer_size: int = OffPolicyConfig.shared_setting("buffer_size", 10_000, "Bester et al. on Platform: 10 000")
    learning_starts: int = OffPolicyConfig.learning_starts_setting(500, "assumed: 500")

    def __post_init__(self):
        super().__post_init__()
        # The map is added to an unbounded output, as the original's (which has no Tanh version): a Tanh before it
        # would no longer keep the parameters in [-1, 1].
        if self.param_passthrough and self.bound == "squash":
            raise ValueError(
                "PDQNConfig.param_passthrough is set with bound = 'squash'; expected bound 'invert' or 'zero', "
                "or no passthrough"
            )

    # Both presets: docs/algorithms.md, "P-DQN and MP-DQN"; how "tuned" learns: benchmarks/later_platform.md.
    PRESETS = {
        "paper": {},
        "tuned": dict(
            num_envs=64,
            hidden_sizes=(64,),
            batch_size=64,
            updates_per_step=0.25,
            epsilon_steps=10_000,
            learning_starts=1_000,
            buffer_size=20_000,
        ),
    }


class PDQN(EpsilonSchedule, Algorithm):
    """P-DQN (Xiong et al. 2018) and, with ``multi_pass``, MP-DQN (Bester et al. 2019). See :class:`PDQNConfig`."""

    config_class = PDQNConfig
    config: PDQNConfig
    MODULES = ("actor", "q_net", "actor_target", "q_target")
    OPTIMIZERS = {"actor": "actor_optimizer", "q_net": "q_optimizer"}

    def _build(self) -> None:
        cfg, h = self.config, self.hybrid
        # x(s): every action's parameters, concatenated
        squash, n = cfg.bound == "squash", h.total_param_size
        self.actor = DeterministicActor(
            self.obs_dim, n, cfg.hidden_sizes, cfg.activation, squash, h, passthrough=cfg.param_passthrough
        )
        self.q_net = QNetwork(self.obs_dim, h, cfg.hidden_sizes, cfg.activation, cfg.multi_pass)
        self.actor_target = copy.deepcopy(self.actor).requires_grad_(False)
        self.q_target = copy.deepcopy(self.q_net).requires_grad_(False)
        self.actor_optimizer = torch.optim.Adam(self.actor.parameters(), lr=cfg.actor_lr, fused=True)
        self.q_optimizer = torch.optim.Adam(self.q_net.parameters(), lr=cfg.q_lr, fused=True)
        self._bind_networks()
        self.blocks = torch.tensor(h.param_blocks, device=self.device)
        self.loop = OffPolicyLoop(
            self,
            mc_returns=cfg.beta > 0,
            tail_value=self._next_value,
            params=((h.total_param_size,), np.float32),  # every action's, after exploration: what Q learns on
        )
        self.replay = self.loop.buffer
        self._ou = OUNoise(cfg.ou_theta, cfg.ou_sigma)

    # -- acting ----------------------------------------------------------------------------------
    def _act(self, obs, deterministic, mask=None):
        params = self.actor(obs).clamp(-1.0, 1.0)
        a = masked_logits(self.q_net(obs, params), mask).argmax(-1)
        if not deterministic:  # one epsilon-greedy draw at the final exploration rate
            a, params = self._epsilon_greedy(a, params, self.config.epsilon_end, mask)
        return a, self.actor.select(params, a)

    def _epsilon_greedy(self, a: torch.Tensor, params: torch.Tensor, eps: float, mask: torch.Tensor | None):
        """With probability ``eps`` a uniform discrete action among the allowed (with ``explore_params``, uniform
        parameters for it)."""
        random = self._from_numpy(self.np_rng.random(len(a)) < eps)
        a = torch.where(random, uniform_actions(len(a), self.hybrid.n_actions, mask, self.np_rng, self.device), a)
        if self.config.explore_params:
            uniform = self._from_numpy(self.np_rng.uniform(-1.0, 1.0, size=params.shape).astype(np.float32))
            params = torch.where(random[:, None] & self.blocks[a], uniform, params)
        return a, params

    def _explore(self, obs: torch.Tensor, step: int, episode_start: np.ndarray, mask: torch.Tensor | None):
        cfg = self.config
        params = self.actor(obs)
        a = masked_logits(self.q_net(obs, params.clamp(-1.0, 1.0)), mask).argmax(-1)  # greedy, before any noise
        if cfg.ou_sigma > 0:
            noise = self._ou(tuple(params.shape), episode_start, self.np_rng)
            params = params + self._from_numpy(noise.astype(np.float32))
        a, params = self._epsilon_greedy(a, params.clamp(-1.0, 1.0), self.epsilon(step), mask)
        return a, self.actor.select(params, a), {"params": params.cpu().numpy()}

    def _next_value(self, obs: torch.Tensor, mask: torch.Tensor | None) -> torch.Tensor:
        """``max_k Q'_k(s, x'(s))`` of the target networks, over the actions ``mask`` allows: the TD target's
        bootstrap, and a truncated episode's Monte-Carlo return's."""
        return masked_logits(self.q_target(obs, self.actor_target(obs).clamp(-1.0, 1.0)), mask).max(-1).values

    # -- learning --------------------------------------------------------------------------------
    def _bind_networks(self) -> None:
        """The actor's hand-written passes (:mod:`pamdp.nn.dense`) over its own tensors, and the soft updates;
        called again by whoever replaces a module."""
        self._dense_actor = Dense.of(self.actor.net)
        self._soft_update_q = soft_updater([(self.q_target, self.q_net)])
        self._soft_update_actor = soft_updater([(self.actor_target, self.actor)])

    def _update(self) -> dict[str, torch.Tensor]:
        """One TD step of the Q-network, one actor step along the bounded ``d sum_k Q_k / dx``, soft target updates;
        back-propagated by hand through the :mod:`~pamdp.nn.dense` views of the networks. The figures stay
        tensors, read once an epoch."""
        cfg = self.config
        b = self.replay.sample(cfg.batch_size, self.np_rng)
        obs, next_obs, batch = b["obs"], b["next_obs"], len(b["obs"])
        with torch.no_grad():
            q_next = self._next_value(next_obs, b.get("next_mask"))
            y = self.loop.td_target(b, q_next)  # mixed with the Monte-Carlo return with beta > 0
            # Q: descend on mean (Q_a - y)^2, the gradient reaching Q_a of the replayed action only
            q_all, cache = self.q_net.forward_cached(obs, b["params"])
            a = b["a"][:, None]
            error = q_all.gather(1, a).squeeze(1) - y
            grad = torch.zeros_like(q_all).scatter_(1, a, (error * (2.0 / batch)).unsqueeze(1))
            apply_gradients(self.q_optimizer, self.q_net.backward(cache, grad), cfg.grad_clip)
            # actor: ascend on sum_k Q_k(s, x(s)) with Q just updated, dQ/dx edited at the bounds
            x, actor_cache = self._dense_actor.forward_cached(obs)
            if self.actor.passthrough_weight is not None:
                x = x + F.linear(obs, self.actor.passthrough_weight, self.actor.passthrough_bias)
            q_x, cache = self.q_net.forward_cached(obs, x)
            dq_dx = bounded(self.q_net.backward(cache, torch.ones_like(q_x), weights=False), x, cfg.bound)
            grads = self._dense_actor.backward(actor_cache, -dq_dx / batch)[0]
            apply_gradients(self.actor_optimizer, grads, cfg.grad_clip)
            self._soft_update_q(cfg.tau_q)
            self._soft_update_actor(cfg.tau_actor)
        return {
            "losses/critic_loss": error.square().mean(),
            "losses/actor_loss": -q_x.sum(-1).mean(),
            "train/q_mean": q_all.gather(1, a).mean(),
            "train/outputs_out_of_bounds": (x.abs() > 1.0).float().mean(),
        }
