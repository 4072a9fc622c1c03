"""PADDPG: DDPG over a parameterized action space (Hausknecht & Stone, ICLR 2016), the seed paper's baseline.

The actor outputs K action scores and every action's parameters in one vector, kept in ``[-1, 1]`` by ``bound``
(:func:`~pamdp.algos.offpolicy.invert_gradients` by default); the critic sees the whole vector. The update is
back-propagated by hand (:mod:`pamdp.nn.dense`; ``tests/test_dense.py`` holds the autograd form it must
equal). The maths: docs/algorithms.md, "PADDPG".
"""

from __future__ import annotations

import copy
import dataclasses

import numpy as np
import torch

from pamdp.algos.base import Algorithm
from pamdp.algos.offpolicy import (
    DeterministicActorConfig,
    EpsilonSchedule,
    OffPolicyConfig,
    OffPolicyLoop,
    OUNoise,
    bounded,
    soft_updater,
)
from pamdp.algos.settings import POSITIVE, AlgoConfig, interval, setting
from pamdp.nn.dense import Dense
from pamdp.nn.optim import apply_gradients
from pamdp.policies import DeterministicActor, TwinQ

__all__ = ["PADDPG", "PADDPGConfig"]


@dataclasses.dataclass(frozen=True)
class PADDPGConfig(DeterministicActorConfig, OffPolicyConfig, AlgoConfig):
    """PADDPG's settings. The defaults are the seed paper's preset: Hausknecht & Stone's settings with the
    hidden layers {400, 300} of DDPG (the paper used {400, 300, 200} on Half Field Offense: preset
    ``paper_hfo``; Hausknecht & Stone's own 1024-512-256-128 towers: preset ``hausknecht_stone``)."""

    hidden_sizes: tuple[int, ...] = OffPolicyConfig.shared_setting("hidden_sizes", (400, 300), "paper: {400, 300}")
    activation: str = OffPolicyConfig.shared_setting(
        "activation", "leaky_relu", "Hausknecht & Stone: leaky_relu, slope 0.01"
    )
    actor_lr: float = setting(1e-5, "Adam learning rate of the actor (Hausknecht & Stone: 1e-5).", POSITIVE)
    critic_lr: float = setting(1e-3, "Adam learning rate of the critic (Hausknecht & Stone: 1e-3).", POSITIVE)
    adam_beta1: float = setting(
        0.95, "Adam's beta1 for both networks (Hausknecht & Stone: 0.95).", interval(0, 1, high_open=True)
    )
    grad_clip: float = OffPolicyConfig.shared_setting("grad_clip", 10.0, "Hausknecht & Stone: 10")
    batch_size: int = OffPolicyConfig.shared_setting("batch_size", 32, "Hausknecht & Stone: 32")
    tau: float = OffPolicyConfig.tau_setting(0.001, "DDPG's 0.001")
    buffer_size: int = OffPolicyConfig.shared_setting("buffer_size", 500_000, "Hausknecht & Stone: 500 000")
    learning_starts: int = OffPolicyConfig.learning_starts_setting(10_000, "the seed paper: 10^4")

    PRESETS = {
        "paper": {},
        "paper_hfo": dict(hidden_sizes=(400, 300, 200)),
        "hausknecht_stone": dict(hidden_sizes=(1024, 512, 256, 128)),
    }


class PADDPG(EpsilonSchedule, Algorithm):
    """Parameterized-action DDPG with inverting gradients (Hausknecht & Stone). See :class:`PADDPGConfig`."""

    config_class = PADDPGConfig
    config: PADDPGConfig
    MODULES = ("actor", "critic", "actor_target", "critic_target")
    OPTIMIZERS = {"actor": "actor_optimizer", "critic": "critic_optimizer"}

    def _build(self) -> None:
        cfg, h = self.config, self.hybrid
        self.out_size = h.n_actions + h.total_param_size
        # mu(s): K scores then every action's parameters
        squash = cfg.bound == "squash"
        self.actor = DeterministicActor(
            self.obs_dim, self.out_size, cfg.hidden_sizes, cfg.activation, squash, h, h.n_actions
        )
        # Q(s, mu) on the state and the actor's whole output vector
        self.critic = TwinQ(self.obs_dim + self.out_size, 1, cfg.hidden_sizes, cfg.activation, twin=False)
        self.actor_target = copy.deepcopy(self.actor).requires_grad_(False)
        self.critic_target = copy.deepcopy(self.critic).requires_grad_(False)
        self._bind_networks()
        betas = (cfg.adam_beta1, 0.999)
        self.actor_optimizer = torch.optim.Adam(self.actor.parameters(), lr=cfg.actor_lr, betas=betas, fused=True)
        self.critic_optimizer = torch.optim.Adam(self.critic.parameters(), lr=cfg.critic_lr, betas=betas, fused=True)
        self.loop = OffPolicyLoop(
            self,
            mc_returns=cfg.beta > 0,
            tail_value=self._target_value,
            out=((self.out_size,), np.float32),  # the output vector the critic sees (after exploration)
        )
        self.replay = self.loop.buffer
        self._ou = OUNoise(cfg.ou_theta, cfg.ou_sigma)

    def _bind_networks(self) -> None:
        """The update's hand-written passes (:mod:`pamdp.nn.dense`) over the modules' own tensors; called
        again by whoever replaces a module."""
        self._dense = {name: Dense.of(getattr(self, name).net) for name in ("actor", "actor_target")}
        self._dense.update({name: Dense.of(getattr(self, name).q1) for name in ("critic", "critic_target")})
        self._soft_update = soft_updater(((self.actor_target, self.actor), (self.critic_target, self.critic)))

    def _act(self, obs, deterministic, mask=None):
        out = self.actor(obs).clamp(-1.0, 1.0)
        if not deterministic:  # one epsilon-greedy draw at the final exploration rate
            out = self._epsilon_greedy(out, self.config.epsilon_end)
        return self.actor.action(out, mask)

    def _masked(self, out: torch.Tensor, mask: torch.Tensor | None) -> torch.Tensor:
        """Output vectors as the critic sees them: the scores of the actions ``mask`` forbids at the lower bound
        -1, so that a stored or target vector says which action it executes."""
        if mask is None:
            return out
        k = self.hybrid.n_actions
        return torch.cat([torch.where(mask, out[:, :k], -1.0), out[:, k:]], dim=-1)

    def _epsilon_greedy(self, out: torch.Tensor, eps: float) -> torch.Tensor:
        random = self.np_rng.random(len(out)) < eps
        uniform = self.np_rng.uniform(-1.0, 1.0, size=out.shape).astype(np.float32)
        return torch.where(self._from_numpy(random)[:, None], self._from_numpy(uniform), out)

    def _explore(self, obs: torch.Tensor, step: int, episode_start: np.ndarray, mask: torch.Tensor | None):
        cfg = self.config
        out = self.actor(obs)
        if cfg.ou_sigma > 0:
            ou = self._ou((len(obs), self.out_size - self.hybrid.n_actions), episode_start, self.np_rng)
            noise = np.concatenate([np.zeros((len(obs), self.hybrid.n_actions)), ou], axis=1)
            out = out + self._from_numpy(noise.astype(np.float32))
        out = self._masked(self._epsilon_greedy(out.clamp(-1.0, 1.0), self.epsilon(step)), mask)
        a, x = self.actor.action(out, mask)
        return a, x, {"out": out.cpu().numpy()}

    def _target_value(self, obs: torch.Tensor, mask: torch.Tensor | None) -> torch.Tensor:
        """``Q'(s, mu'(s))``, the bootstrap of a truncated episode's Monte-Carlo return."""
        return self.critic_target.smaller(obs, self._masked(self.actor_target(obs).clamp(-1.0, 1.0), mask)).squeeze(-1)

    def _update(self) -> dict[str, torch.Tensor]:
        """One critic step on the mixed target and one actor step along the bounded ``dQ/dmu``, back-propagated
        by hand through the :mod:`~pamdp.nn.dense` views of the networks."""
        cfg = self.config
        b = self.replay.sample(cfg.batch_size, self.np_rng)
        obs, next_obs = b["obs"], b["next_obs"]
        batch, nets = len(obs), self._dense
        actor, critic = nets["actor"], nets["critic"]
        with torch.no_grad():
            out_next = self._masked(nets["actor_target"](next_obs).clamp(-1.0, 1.0), b.get("next_mask"))
            q_next = nets["critic_target"](torch.cat([next_obs, out_next], dim=-1)).squeeze(-1)
            y = self.loop.td_target(b, q_next)  # mixed with the Monte-Carlo return with beta > 0
            q, error = critic.regression_step(
                self.critic_optimizer, torch.cat([obs, b["out"]], dim=-1), y, cfg.grad_clip
            )
            # actor: ascend on Q(s, mu(s)) with the critic just updated, dQ/dmu edited at the bounds
            out, actor_cache = actor.forward_cached(obs)
            q_mu, q_cache = critic.forward_cached(torch.cat([obs, self._masked(out, b.get("mask"))], dim=-1))
            _, dq_dx = critic.backward(q_cache, torch.ones_like(q_mu), weights=False, inputs=True)
            dq_dp = bounded(dq_dx[:, self.obs_dim :], out, cfg.bound)
            if "mask" in b:  # a forbidden action's score is held at -1: no gradient reaches it
                k = self.hybrid.n_actions
                dq_dp = torch.cat([dq_dp[:, :k] * b["mask"], dq_dp[:, k:]], dim=-1)
            apply_gradients(self.actor_optimizer, actor.backward(actor_cache, -dq_dp / batch)[0], cfg.grad_clip)
            self._soft_update(cfg.tau)
        return {  # tensors, read once an epoch by the loop
            "losses/critic_loss": error.square().mean(),
            "losses/actor_loss": -q_mu.mean(),
            "train/q_mean": q.mean(),
            "train/outputs_out_of_bounds": (out.abs() > 1.0).float().mean(),
        }
