"""Hybrid SAC: soft actor-critic over parameterized actions (Delalleau, Peter, Alonso & Logut 2019, arXiv
1912.11077), with a flat or a hierarchical ``pi_c``, twin critics with one output per discrete action, and one
tuned temperature for each part of the policy. The maths: docs/algorithms.md, "Hybrid SAC".
"""

from __future__ import annotations

import copy
import dataclasses
import math

import numpy as np
import torch
import torch.nn.functional as F

from pamdp.algos.base import Algorithm
from pamdp.algos.offpolicy import OffPolicyConfig, OffPolicyLoop, Temperatures, soft_updater
from pamdp.algos.settings import NON_NEGATIVE, POSITIVE, AlgoConfig, Check, interval, one_of, setting
from pamdp.distributions import MASKED, SquashedHybrid
from pamdp.nn.optim import descend
from pamdp.policies import FORMS, HybridSACActor, TwinQ

__all__ = ["HybridSAC", "HybridSACConfig"]


@dataclasses.dataclass(frozen=True)
class HybridSACConfig(OffPolicyConfig, AlgoConfig):
    """Hybrid SAC's settings. The defaults are the ``paper`` preset: Delalleau et al.'s structure (flat form, two
    temperatures tuned automatically) with soft actor-critic's published settings (Haarnoja et al. 2018), since
    the text of Delalleau et al.'s appendix was not at hand; values taken from SAC or set here are marked."""

    form: str = setting(
        "flat",
        "pi_c's form: flat (one network outputs every action's parameters, Delalleau et al.) or hierarchical "
        "(pi_c(x|s,a) on [s, onehot(a)], the seed paper's).",
        one_of(FORMS),
    )
    hidden_sizes: tuple[int, ...] = OffPolicyConfig.shared_setting(
        "hidden_sizes", (256, 256), "SAC's: 256-256; assumed"
    )
    actor_lr: float = setting(3e-4, "Adam learning rate of the policy (SAC: 3e-4; assumed).", POSITIVE)
    critic_lr: float = setting(3e-4, "Adam learning rate of the twin critics (SAC: 3e-4; assumed).", POSITIVE)
    alpha_lr: float = setting(
        3e-4,
        "Adam learning rate of the two log-temperatures (SAC: 3e-4; assumed); 0 keeps them at their initial values.",
        NON_NEGATIVE,
    )
    init_alpha_d: float = setting(1.0, "Initial temperature of pi_d's entropy (SAC: 1; assumed).", POSITIVE)
    init_alpha_c: float = setting(1.0, "Initial temperature of pi_c's entropy (SAC: 1; assumed).", POSITIVE)
    target_entropy_d: float = setting(
        0.98,
        "pi_d's target entropy as a fraction of the uniform distribution's over the allowed actions, log(allowed) "
        "(SAC-discrete, Christodoulou 2019: 0.98; assumed).",
        interval(0, 1),
    )
    target_entropy_c: float = setting(
        -1.0,
        "pi_c's target entropy in nats per parameter of the chosen action (SAC: -1 per action dimension; assumed).",
        Check(lambda v: v < math.log(2.0), "a number below log 2 (the uniform's entropy on [-1, 1])"),
    )
    tau: float = OffPolicyConfig.tau_setting(0.005, "of the critics; SAC: 0.005")
    batch_size: int = OffPolicyConfig.shared_setting("batch_size", 256, "SAC: 256; assumed")
    learning_starts: int = OffPolicyConfig.learning_starts_setting(10_000, "SAC: 10 000; assumed")

    # "tuned" (the command line's default): docs/algorithms.md, "Hybrid SAC"; benchmarks/hsac_platform.md.
    PRESETS = {
        "paper": {},
        "tuned": dict(
            num_envs=64,
            hidden_sizes=(64, 64),
            batch_size=128,
            updates_per_step=0.1,
            target_entropy_d=0.5,
            learning_starts=2_000,
            buffer_size=200_000,
            init_alpha_d=0.1,
            init_alpha_c=0.1,
            actor_lr=1e-3,
            critic_lr=1e-3,
            alpha_lr=1e-3,
            tau=0.01,
        ),
    }


class HybridSAC(Algorithm):
    """Hybrid SAC (Delalleau et al. 2019), flat or hierarchical (``form``). See docs/algorithms.md, "Hybrid SAC"."""

    config_class = HybridSACConfig
    config: HybridSACConfig
    MODULES = ("actor", "critic", "critic_target", "temperatures")
    OPTIMIZERS = {"actor": "actor_optimizer", "critic": "critic_optimizer", "temperatures": "alpha_optimizer"}

    def _build(self) -> None:
        cfg, h = self.config, self.hybrid
        self.actor = HybridSACActor(self.obs_dim, h, cfg.form, cfg.hidden_sizes, cfg.activation)
        # Q_i(s, x_all) with one output per discrete action, Q_i(s, a, x_all)
        self.critic = TwinQ(self.obs_dim + h.total_param_size, h.n_actions, cfg.hidden_sizes, cfg.activation)
        self.critic_target = copy.deepcopy(self.critic).requires_grad_(False)
        self.temperatures = Temperatures(alpha_d=cfg.init_alpha_d, alpha_c=cfg.init_alpha_c)
        self.actor_optimizer = torch.optim.Adam(self.actor.parameters(), lr=cfg.actor_lr, fused=True)
        self.critic_optimizer = torch.optim.Adam(self.critic.parameters(), lr=cfg.critic_lr, fused=True)
        self.alpha_optimizer = torch.optim.Adam(self.temperatures.parameters(), lr=cfg.alpha_lr, fused=True)
        self._actor_params, self._critic_params = list(self.actor.parameters()), list(self.critic.parameters())
        self.param_sizes = torch.as_tensor(h.param_sizes, dtype=torch.float32, device=self.device)
        # every action's drawn parameters: what the critics saw
        self.loop = OffPolicyLoop(self, params=((h.total_param_size,), np.float32))
        self.replay = self.loop.buffer
        self._soft_update = soft_updater([(self.critic_target, self.critic)])

    @property
    def alphas(self) -> tuple[float, float]:
        """The current temperatures ``(alpha_d, alpha_c)``."""
        return tuple(float(alpha) for alpha in self.temperatures.alphas())

    # -- acting ----------------------------------------------------------------------------------
    def _act(self, obs, deterministic, mask=None):
        dist = self.actor(obs, mask)
        if deterministic:
            return dist.mode()
        a, x, _ = self._sample(dist)
        return a, x

    def _sample(self, dist: SquashedHybrid):
        """``a ~ pi_d``, every action's ``x ~ pi_c``: the chosen action's parameters ``(B, m)`` and all of them."""
        a = dist.sample_discrete(self.torch_gen)
        _, x_all = dist.rsample(self.torch_gen)
        return a, x_all[torch.arange(len(a), device=a.device), a], x_all

    def _explore(self, obs: torch.Tensor, step: int, episode_start: np.ndarray, mask=None):
        a, x, x_all = self._sample(self.actor(obs, mask))
        return a, x, {"params": self.actor.flat_params(x_all).cpu().numpy()}

    # -- learning --------------------------------------------------------------------------------
    def _epoch_stats(self, step: int) -> dict[str, float]:
        return dict(zip(("train/alpha_d", "train/alpha_c"), self.alphas))

    def soft_value(self, dist: SquashedHybrid, critic: TwinQ, obs: torch.Tensor, alpha_d, alpha_c):
        """Per state and discrete action, ``min_i Q_i(s, x_all)_a - alpha_c log pi_c(x_a|s,a) - alpha_d log
        pi_d(a|s)`` at a reparameterised draw of ``x_all``, ``(B, K)``, with ``log pi_c`` ``(B, K)``."""
        u, x_all = dist.rsample(self.torch_gen)
        log_pc = dist.log_prob_c(u)
        q = critic.smaller(obs, self.actor.flat_params(x_all))
        return q - alpha_c * log_pc - alpha_d * dist.log_probs_d, log_pc

    @torch.no_grad()
    def target_value(self, next_obs: torch.Tensor, next_mask: torch.Tensor | None = None) -> torch.Tensor:
        """``V(s')`` ``(B,)``: the soft value under the target critics, exact over the next discrete action
        (masked ones weigh nothing), at one draw of every action's parameters."""
        dist = self.actor(next_obs, next_mask)
        soft_q, _ = self.soft_value(dist, self.critic_target, next_obs, *self.temperatures.alphas())
        return (dist.probs_d * soft_q).sum(-1)

    def _update(self) -> dict[str, float]:
        """One soft Q step of both critics, one policy step, one step of each temperature, the target update."""
        cfg = self.config
        b = self.replay.sample(cfg.batch_size, self.np_rng)
        obs, next_obs = b["obs"], b["next_obs"]
        mask, next_mask = b.get("mask"), b.get("next_mask")  # with the action_mask setting only
        alpha_d, alpha_c = self.temperatures.alphas()
        y = self.loop.td_target(b, self.target_value(next_obs, next_mask))
        a = b["a"][:, None]
        q1, q2 = (q.gather(1, a).squeeze(1) for q in self.critic(obs, b["params"]))
        critic_loss = F.mse_loss(q1, y) + F.mse_loss(q2, y)
        descend(self.critic_optimizer, critic_loss, self._critic_params, cfg.grad_clip)

        dist = self.actor(obs, mask)
        soft_q, log_pc = self.soft_value(dist, self.critic, obs, alpha_d, alpha_c)
        p = dist.probs_d
        actor_loss = -(p * soft_q).sum(-1).mean()
        descend(self.actor_optimizer, actor_loss, self._actor_params, cfg.grad_clip)  # the critics' get none

        with torch.no_grad():
            entropy_d = dist.entropy_d()
            allowed = (dist.logits > MASKED / 2).sum(-1) if mask is not None else self.hybrid.n_actions
            target_d = cfg.target_entropy_d * torch.as_tensor(allowed, dtype=p.dtype).log()
            p = p.detach()
            entropy_c = -(p * log_pc.detach()).sum(-1)  # of the expected action's parameters
            target_c = cfg.target_entropy_c * (p * self.param_sizes).sum(-1)
        self.temperatures.step(self.alpha_optimizer, (entropy_d, target_d), (entropy_c, target_c))
        self._soft_update(cfg.tau)
        return {
            "losses/critic_loss": float(critic_loss.detach()),
            "losses/actor_loss": float(actor_loss.detach()),
            "train/q_mean": float(q1.detach().mean()),
            "train/entropy_d": float(entropy_d.mean()),
            "train/entropy_c": float(entropy_c.mean()),
        }
