"""HyAR-TD3: TD3 in a learned latent space of hybrid actions (Li et al., ICLR 2022, arXiv 2109.05490).

A table of discrete-action embeddings and a conditional VAE of the parameters (with a dynamics head) turn the
hybrid action space into a box; TD3 acts in the box, within the latent space constraint, and replayed latents
are relabelled when the representation has moved. The maths, the schedule, the options beyond the paper and
how the ``cpu`` preset came about: docs/algorithms.md, "HyAR-TD3".
"""

from __future__ import annotations

import copy
import dataclasses

import numpy as np
import torch
import torch.nn.functional as F
from torch import nn

from pamdp.algos.base import Algorithm
from pamdp.algos.offpolicy import (
    EpsilonSchedule,
    OffPolicyConfig,
    OffPolicyLoop,
    backprop_actor,
    linear_epsilon,
    soft_updater,
    uniform_actions,
)
from pamdp.algos.settings import LAYERS, NON_NEGATIVE, POSITIVE, AlgoConfig, at_least, interval, one_of, setting
from pamdp.distributions import LOG_STD_MAX, LOG_STD_MIN, masked_logits
from pamdp.nn.optim import apply_gradients, descend
from pamdp.policies import ACTIVATIONS, DeterministicActor, TwinQ, mlp
from pamdp.spaces import HybridActionSpace

__all__ = ["HyAR", "HyARConfig", "ActionRepresentation", "latent_bounds"]

RELABEL = ("invalid", "all", "none")


@dataclasses.dataclass(frozen=True)
class HyARConfig(OffPolicyConfig, AlgoConfig):
    """HyAR-TD3's settings. The defaults are the ``paper`` preset: the paper's schedule, with TD3's published
    settings (Fujimoto et al. 2018) where the text available here gives none; assumptions are marked."""

    embed_dim: int = setting(6, "Size of a discrete action's embedding, d1 (assumed: 6).", at_least(1))
    latent_dim: int = setting(6, "Size of the parameters' latent z, d2 (assumed: 6).", at_least(1))
    vae_hidden_sizes: tuple[int, ...] = setting(
        (256, 256), "Hidden layers of the VAE's encoder and decoder (assumed).", LAYERS
    )
    hidden_sizes: tuple[int, ...] = OffPolicyConfig.shared_setting("hidden_sizes", (256, 256), "TD3's: 256-256")
    bound: str = setting(
        "squash",
        "Keeping the actor's output in [-1, 1]: squash (Tanh, the paper) or invert (a linear output and Hausknecht "
        "& Stone's inverting gradients, which do not stall where Tanh saturates).",
        one_of(("squash", "invert")),
    )
    kl_weight: float = setting(1.0, "Weight of the VAE's KL term (the paper's loss: 1).", NON_NEGATIVE)
    dynamics_weight: float = setting(
        1.0, "Weight of the state-change prediction loss, beta (assumed: 1).", NON_NEGATIVE
    )
    vae_lr: float = setting(1e-4, "Adam learning rate of the embedding table and the VAE (assumed: 1e-4).", POSITIVE)
    vae_batch_size: int = setting(64, "Transitions per representation update (assumed: 64).", at_least(1))
    warmup_steps: int = setting(
        11_000,
        "Samples of uniformly random actions before learning (the paper: 5000 episodes; ~11 000 on Platform).",
        at_least(1),
    )
    warmup_updates: int = setting(
        5_000, "Representation updates on the warm-up data before TD3 starts (assumed).", at_least(0)
    )
    vae_interval: int = setting(
        1_000, "Samples between rounds of representation training during TD3 (assumed).", at_least(1)
    )
    vae_updates: int = setting(10, "Representation updates per round (assumed).", at_least(0))
    lsc_percent: float = setting(
        96.0,
        "Latent space constraint: the central percentage of replayed latents the actor may reach (assumed: 96).",
        interval(0, 100, low_open=True),
    )
    lsc_samples: int = setting(5_000, "Replayed transitions encoded to compute the latent bounds.", at_least(1))
    lsc_remap: bool = setting(
        False,
        "When a representation round moves the latent box, rescale the actor's linear output layer so that its "
        "latents stay where they were, instead of moving with the box (needs bound='invert'; not in the paper).",
    )
    relabel: str = setting(
        "invalid",
        "Representation shift correction: invalid (re-encode stale latents), all (every one) or none.",
        one_of(RELABEL),
    )
    relabel_tolerance: float = setting(
        0.1,
        "A replayed latent is stale if its decoded parameters differ by more than this, in [-1, 1] units (assumed).",
        NON_NEGATIVE,
    )
    actor_lr: float = setting(3e-4, "Adam learning rate of the actor (TD3: 3e-4).", POSITIVE)
    critic_lr: float = setting(3e-4, "Adam learning rate of the critics (TD3: 3e-4).", POSITIVE)
    batch_size: int = OffPolicyConfig.shared_setting("batch_size", 128, "assumed: 128")
    tau: float = OffPolicyConfig.tau_setting(0.005, "TD3: 0.005")
    exploration_noise: float = setting(
        0.1,
        "Std of the Gaussian noise on the actor's [-1, 1] output (TD3: 0.1); with exploration_noise_steps, the std "
        "the schedule ends at.",
        NON_NEGATIVE,
    )
    exploration_noise_start: float = setting(
        1.0,
        "Std of that noise when TD3 starts, falling linearly to exploration_noise over exploration_noise_steps "
        "(HyAR's scripts: 1.0 to 0.1 over 1000 episodes, on the embedding and the parameters' latent alike).",
        NON_NEGATIVE,
    )
    exploration_noise_steps: int = setting(
        0,
        "Samples after the warm-up over which the noise's std falls from exploration_noise_start to "
        "exploration_noise; 0: no schedule, the std is exploration_noise throughout.",
        at_least(0),
    )
    epsilon_start: float = setting(
        0.0,
        "Chance at the start of replacing the actor's embedding by a uniformly drawn action's (not in the paper: 0).",
        interval(0, 1),
    )
    epsilon_end: float = setting(0.0, "That chance after epsilon_steps samples (falling linearly).", interval(0, 1))
    epsilon_steps: int = setting(
        50_000, "Samples over which the embedding's epsilon falls to epsilon_end.", at_least(1)
    )
    beta: float = OffPolicyConfig.shared_setting("beta", 0.0, "not in HyAR: 0, TD3's target")
    target_noise: float = setting(
        0.2, "Std of the target policy smoothing noise, [-1, 1] units (TD3: 0.2).", NON_NEGATIVE
    )
    target_noise_clip: float = setting(0.5, "Clip of the target policy smoothing noise (TD3: 0.5).", NON_NEGATIVE)
    policy_delay: int = setting(2, "Critic updates per actor and target update (TD3: 2).", at_least(1))
    td3_replay: int = setting(
        0,
        "TD3's minibatches come only from the newest td3_replay samples taken after the representation's "
        "pre-training, as HyAR's scripts keep TD3's replay (1e5 samples; 1e6 on Hard Move) apart from the "
        "representation's, which holds the warm-up and the whole run; 0: TD3 samples the whole replay, the "
        "warm-up's random actions included.",
        at_least(0),
    )
    save_replay: bool = OffPolicyConfig.shared_setting(
        "save_replay", True, "true here: it is the representation's training data"
    )

    def __post_init__(self):
        """The checks across settings (each setting's own runs in AlgoConfig)."""
        super().__post_init__()
        self._check(
            not self.lsc_remap or self.bound == "invert",
            "lsc_remap",
            "False with bound='squash' (a Tanh output cannot be rescaled exactly)",
        )
        self._check(self.buffer_size >= self.warmup_steps, "buffer_size", f">= warmup_steps ({self.warmup_steps})")
        self._check(self.td3_replay <= self.buffer_size, "td3_replay", f"<= buffer_size ({self.buffer_size})")

    @property
    def learning_starts(self) -> int:
        """The samples before the first update (:class:`~pamdp.algos.offpolicy.OffPolicyLoop`): the warm-up's."""
        return self.warmup_steps

    # "cpu" (the command line's default), sized for a laptop CPU, not tuned: docs/algorithms.md, "HyAR-TD3".
    PRESETS = {
        "cpu": dict(
            num_envs=64,
            embed_dim=3,
            latent_dim=2,
            kl_weight=0.01,
            hidden_sizes=(128, 128),
            vae_hidden_sizes=(128, 128),
            updates_per_step=0.25,
            vae_interval=2_000,
            vae_updates=20,
            warmup_updates=2_000,
            buffer_size=200_000,
            bound="invert",
            epsilon_start=0.5,
            epsilon_end=0.05,
            epsilon_steps=50_000,
        ),
        "paper": {},
    }


class ActionRepresentation(nn.Module):
    """The embedding table and the conditional VAE with its state-change head (docs/algorithms.md, "HyAR-TD3").

    Parameters ``x`` are padded to ``m = max_a m_a`` in ``[-1, 1]`` units; the unused slots of an action are
    zero on the way in and masked out of the reconstruction loss.
    """

    def __init__(
        self, obs_dim: int, hybrid: HybridActionSpace, embed_dim: int, latent_dim: int, hidden_sizes, activation: str
    ):
        super().__init__()
        self.param_size = hybrid.max_param_size
        self.latent_dim = latent_dim
        self.embedding = nn.Parameter(torch.empty(hybrid.n_actions, embed_dim).uniform_(-1.0, 1.0))
        self.encoder = mlp(obs_dim + self.param_size + embed_dim, hidden_sizes, 2 * latent_dim, activation)
        # The decoder's trunk; the parameter head reads it, the state-change head is stacked on top of it.
        self.decoder = mlp(obs_dim + latent_dim + embed_dim, hidden_sizes[:-1], hidden_sizes[-1], activation)
        self.act = ACTIVATIONS[activation]()
        self.param_head = nn.Linear(hidden_sizes[-1], self.param_size)
        self.dynamics_head = mlp(hidden_sizes[-1], hidden_sizes[-1:], obs_dim, activation)
        self.register_buffer("mask", torch.tensor(hybrid.param_mask, dtype=torch.float32))

    def encode(self, obs: torch.Tensor, a: torch.Tensor, x: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """Mean and log-std of ``q(z | x, s, e_a)``."""
        out = self.encoder(torch.cat([obs, x * self.mask[a], self.embedding[a]], dim=-1))
        mean, log_std = out.split(self.latent_dim, dim=-1)
        return mean, log_std.clamp(LOG_STD_MIN, LOG_STD_MAX)

    def _trunk(self, obs: torch.Tensor, a: torch.Tensor, z: torch.Tensor) -> torch.Tensor:
        return self.act(self.decoder(torch.cat([obs, z, self.embedding[a]], dim=-1)))

    def decode_params(self, obs: torch.Tensor, a: torch.Tensor, z: torch.Tensor) -> torch.Tensor:
        """Action ``a``'s parameters for latent ``z``, in ``[-1, 1]``, zero in the unused slots."""
        return torch.tanh(self.param_head(self._trunk(obs, a, z))) * self.mask[a]

    def nearest_action(self, e: torch.Tensor, mask: torch.Tensor | None = None) -> torch.Tensor:
        """The discrete action whose embedding is nearest to ``e`` (Euclidean distance), among those ``mask``
        allows."""
        distance = torch.cdist(e, self.embedding)
        return distance.argmin(-1) if mask is None else masked_logits(-distance, mask).argmax(-1)

    def decode(
        self, obs: torch.Tensor, latent: torch.Tensor, mask: torch.Tensor | None = None
    ) -> tuple[torch.Tensor, torch.Tensor]:
        """The hybrid action ``(a, x)`` of latent actions ``(e, z)``, concatenated in ``latent`` (``a`` among the
        actions ``mask`` allows)."""
        e, z = latent.split([self.embedding.shape[1], self.latent_dim], dim=-1)
        a = self.nearest_action(e, mask)
        return a, self.decode_params(obs, a, z)

    def snap(self, latent: torch.Tensor, mask: torch.Tensor | None) -> torch.Tensor:
        """Latent actions whose nearest embedding is a forbidden action, with ``e`` moved onto the embedding of
        the allowed action they decode to: the critic then sees which action each one executes."""
        if mask is None:
            return latent
        d = self.embedding.shape[1]
        e = latent[:, :d]
        a = self.nearest_action(e, mask)
        moved = torch.where((a != self.nearest_action(e))[:, None], self.embedding[a], e)
        return torch.cat([moved, latent[:, d:]], dim=-1)

    def latent(self, obs: torch.Tensor, a: torch.Tensor, x: torch.Tensor) -> torch.Tensor:
        """The current (deterministic) latent action of ``(a, x)``: ``(e_a, mu(x, s, e_a))``."""
        return torch.cat([self.embedding[a], self.encode(obs, a, x)[0]], dim=-1)

    def loss(self, obs, a, x, next_obs, kl_weight: float, dynamics_weight: float, generator=None):
        """The representation loss on a batch, and its three terms (reconstruction, KL, state change) as floats."""
        mean, log_std = self.encode(obs, a, x)
        std = log_std.exp()
        eps = torch.randn(mean.shape, generator=generator, dtype=mean.dtype, device=mean.device)
        h = self._trunk(obs, a, mean + std * eps)
        mask = self.mask[a]
        recon = ((torch.tanh(self.param_head(h)) - x) ** 2 * mask).sum(-1).mean()
        kl = (0.5 * (mean**2 + std**2 - 1.0) - log_std).sum(-1).mean()
        dynamics = ((self.dynamics_head(h) - (next_obs - obs)) ** 2).mean(-1).mean()
        total = recon + kl_weight * kl + dynamics_weight * dynamics
        return total, {"recon": float(recon.detach()), "kl": float(kl.detach()), "dynamics": float(dynamics.detach())}


def latent_bounds(latents: torch.Tensor, percent: float) -> tuple[torch.Tensor, torch.Tensor]:
    """Per dimension, the ``(50 -+ percent / 2)``-th percentiles of ``latents`` (N, D): the central ``percent`` %."""
    q = torch.tensor([0.5 - percent / 200.0, 0.5 + percent / 200.0], dtype=latents.dtype, device=latents.device)
    low, high = torch.quantile(latents, q, dim=0)
    return low, torch.maximum(high, low + 1e-6)


class HyAR(EpsilonSchedule, Algorithm):
    """HyAR-TD3 (Li et al. 2022): TD3 in a learned hybrid action representation. See :class:`HyARConfig`."""

    config_class = HyARConfig
    config: HyARConfig
    MODULES = ("rep", "actor", "critic", "actor_target", "critic_target")
    OPTIMIZERS = {"rep": "rep_optimizer", "actor": "actor_optimizer", "critic": "critic_optimizer"}

    def _build(self) -> None:
        cfg, h = self.config, self.hybrid
        self.latent_size = cfg.embed_dim + cfg.latent_dim
        self.rep = ActionRepresentation(
            self.obs_dim, h, cfg.embed_dim, cfg.latent_dim, cfg.vae_hidden_sizes, cfg.activation
        )
        squash = cfg.bound == "squash"
        # u(s) in [-1, 1]^(d1 + d2), mapped onto the latent box
        self.actor = DeterministicActor(
            self.obs_dim, self.latent_size, cfg.hidden_sizes, cfg.activation, squash, box=True
        )
        self.critic = TwinQ(self.obs_dim + self.latent_size, 1, cfg.hidden_sizes, cfg.activation)  # Q_i(s, e, z)
        self.actor_target = copy.deepcopy(self.actor).requires_grad_(False)
        self.critic_target = copy.deepcopy(self.critic).requires_grad_(False)
        self._rep_params, self._actor_params = list(self.rep.parameters()), list(self.actor.net.parameters())
        self._critic_params = list(self.critic.parameters())
        self.rep_optimizer = torch.optim.Adam(self._rep_params, lr=cfg.vae_lr, fused=True)
        self.actor_optimizer = torch.optim.Adam(self._actor_params, lr=cfg.actor_lr, fused=True)
        self.critic_optimizer = torch.optim.Adam(self._critic_params, lr=cfg.critic_lr, fused=True)
        self._soft_update = soft_updater([(self.critic_target, self.critic), (self.actor_target.net, self.actor.net)])
        # the latent action that was decoded and executed
        self.loop = OffPolicyLoop(self, mc_returns=cfg.beta > 0, latent=((self.latent_size,), np.float32))
        self.replay = self.loop.buffer
        self.pretrained = False  # the warm-up round of representation training is done
        self.n_updates = 0  # TD3 updates so far (the policy delay and the representation rounds count them)
        self.rl_start = 0  # the replay's insertion counter at the representation's pre-training (td3_replay)

    def _extra_state(self):
        return {"pretrained": self.pretrained, "n_updates": self.n_updates, "rl_start": self.rl_start}

    def _load_extra_state(self, state):
        self.pretrained, self.n_updates = bool(state["pretrained"]), int(state["n_updates"])
        self.rl_start = int(state.get("rl_start", self.config.warmup_steps))  # checkpoints from before td3_replay
        if self.pretrained and len(self.replay) == 0:  # resumed without the replay: warm up again on new data
            self.pretrained = False

    # -- acting ----------------------------------------------------------------------------------
    def _act(self, obs, deterministic, mask=None):
        u = self.actor(obs).clamp(-1.0, 1.0)
        if not deterministic:
            u = self._noisy(u, self.num_timesteps)
        return self.rep.decode(obs, self.actor.to_latent(u), mask)

    def noise_std(self, step: int) -> float:
        """The std of the actor's exploration noise after ``step`` samples (warm-up included): exploration_noise,
        or with a schedule, linear from exploration_noise_start at the end of the warm-up to exploration_noise."""
        cfg = self.config
        if cfg.exploration_noise_steps == 0:
            return cfg.exploration_noise
        rl_steps = max(step - cfg.warmup_steps, 0)
        return linear_epsilon(rl_steps, cfg.exploration_noise_start, cfg.exploration_noise, cfg.exploration_noise_steps)

    def _noisy(self, u: torch.Tensor, step: int) -> torch.Tensor:
        noise = self.np_rng.normal(0.0, self.noise_std(step), size=u.shape).astype(np.float32)
        return (u + self._from_numpy(noise)).clamp(-1.0, 1.0)

    def _explore(self, obs: torch.Tensor, step: int, episode_start: np.ndarray, mask: torch.Tensor | None):
        if step < self.config.warmup_steps:  # uniformly random hybrid actions; latents are filled in after warm-up
            n, h = len(obs), self.hybrid
            a = uniform_actions(n, h.n_actions, mask, self.np_rng, self.device)
            x = self.np_rng.uniform(-1.0, 1.0, size=(n, h.max_param_size)).astype(np.float32)
            x = self._from_numpy(x) * self.rep.mask[a]
            return a, x, {"latent": np.zeros((n, self.latent_size), dtype=np.float32)}
        latent = self.actor.to_latent(self._noisy(self.actor(obs).clamp(-1.0, 1.0), step))
        eps = self.epsilon(step)
        if eps > 0:  # a uniformly drawn action's embedding in place of the actor's, the parameters' latent kept
            drawn = self._from_numpy(self.np_rng.random(len(obs)) < eps)
            k = uniform_actions(len(obs), self.hybrid.n_actions, mask, self.np_rng, self.device)
            e = torch.where(drawn[:, None], self.rep.embedding[k], latent[:, : self.config.embed_dim])
            latent = torch.cat([e, latent[:, self.config.embed_dim :]], dim=-1)
        latent = self.rep.snap(latent, mask)
        a, x = self.rep.decode(obs, latent, mask)
        return a, x, {"latent": latent.cpu().numpy()}

    # -- learning --------------------------------------------------------------------------------
    def _epoch_stats(self, step: int) -> dict[str, float]:
        return {
            "train/latent_box_width": float((self.actor.high - self.actor.low).mean()),
            "train/epsilon": self.epsilon(step),
            "train/noise_std": self.noise_std(step),
        }

    def train_representation(self, updates: int) -> dict[str, float]:
        """``updates`` steps of the representation loss on replayed batches, then new latent bounds."""
        cfg = self.config
        sums = {"recon": 0.0, "kl": 0.0, "dynamics": 0.0}
        with torch.enable_grad():
            for _ in range(updates):
                b = self.replay.sample(cfg.vae_batch_size, self.np_rng)
                loss, terms = self.rep.loss(
                    b["obs"], b["a"], b["x"], b["next_obs"], cfg.kl_weight, cfg.dynamics_weight, self.torch_gen
                )
                descend(self.rep_optimizer, loss, self._rep_params)
                for k, v in terms.items():
                    sums[k] += v
        self.update_bounds(remap=self.config.lsc_remap and self.pretrained)
        return {f"losses/vae_{k}": v / max(updates, 1) for k, v in sums.items()}

    @torch.no_grad()
    def update_bounds(self, remap: bool = False) -> None:
        """The latent space constraint: the central ``lsc_percent`` % of the latents of replayed actions.

        With ``remap`` the actors' linear output layers are rescaled so that every output maps to the same latent
        in the new box as in the old: ``u' = u * w / w' + 2 (low - low') / w' + w / w' - 1`` per dimension
        (``w = high - low``); outputs that land outside ``[-1, 1]`` are pushed back by the inverting gradients.
        """
        b = self.replay.sample(min(self.config.lsc_samples, len(self.replay)), self.np_rng)
        low, high = latent_bounds(self.rep.latent(b["obs"], b["a"], b["x"]), self.config.lsc_percent)
        for actor in (self.actor, self.actor_target):
            if remap:
                width, new_width = actor.high - actor.low, high - low
                scale = width / new_width
                shift = 2.0 * (actor.low - low) / new_width + scale - 1.0
                out = actor.net[-1]
                out.weight.mul_(scale[:, None])
                out.bias.mul_(scale).add_(shift)
            actor.low.copy_(low)
            actor.high.copy_(high)

    @torch.no_grad()
    def _reencode_replay(self) -> None:
        """Write the current latents of every stored action into the replay (the warm-up's random actions)."""
        n, data = len(self.replay), self.replay.data
        for start in range(0, n, 4096):
            s = slice(start, min(n, start + 4096))
            data["latent"][s] = self.rep.latent(data["obs"][s], data["a"][s], data["x"][s])

    @torch.no_grad()
    def relabel(self, b: dict[str, torch.Tensor]) -> tuple[torch.Tensor, float]:
        """The batch's latent actions after representation shift correction, and the fraction replaced."""
        mode, latent = self.config.relabel, b["latent"]
        if mode == "none":
            return latent, 0.0
        current = self.rep.latent(b["obs"], b["a"], b["x"])
        if mode == "all":
            return current, 1.0
        a, x = self.rep.decode(b["obs"], latent, b.get("mask"))
        stale = (a != b["a"]) | ((x - b["x"] * self.rep.mask[b["a"]]).abs().amax(-1) > self.config.relabel_tolerance)
        return torch.where(stale[:, None], current, latent), float(stale.float().mean())

    def _q1(self, obs: torch.Tensor, u: torch.Tensor) -> torch.Tensor:
        """The first critic at the actor's output ``u`` (in ``[-1, 1]`` units)."""
        return self.critic.q1(torch.cat([obs, self.actor.to_latent(u)], dim=-1)).squeeze(-1)

    def _update(self) -> dict[str, float]:
        """One TD3 critic step (on relabelled latents), a delayed actor step, and representation rounds when due."""
        cfg = self.config
        stats: dict[str, float] = {}  # what this update computed; the loop averages each figure over its own steps
        if not self.pretrained:
            stats.update(self.train_representation(cfg.warmup_updates))
            self._reencode_replay()
            self.pretrained = True
            self.rl_start = self.replay.added  # all held so far was taken before the representation was trained
        first = 0
        if cfg.td3_replay:
            first = max(self.rl_start, self.replay.added - cfg.td3_replay)
            if self.replay.added - first < cfg.batch_size:  # HyAR's TD3 waits for a batch of its own samples
                return stats
        self.n_updates += 1
        every = max(1, round(cfg.vae_interval * cfg.updates_per_step))
        if self.n_updates % every == 0 and cfg.vae_updates > 0:
            stats.update(self.train_representation(cfg.vae_updates))

        b = self.replay.sample(cfg.batch_size, self.np_rng, first)
        obs, next_obs = b["obs"], b["next_obs"]
        latent, relabelled = self.relabel(b)
        with torch.no_grad():
            u_next = self.actor_target(next_obs).clamp(-1.0, 1.0)
            noise = torch.randn(u_next.shape, generator=self.torch_gen, device=self.device) * cfg.target_noise
            u_next = (u_next + noise.clamp(-cfg.target_noise_clip, cfg.target_noise_clip)).clamp(-1.0, 1.0)
            latent_next = self.rep.snap(self.actor_target.to_latent(u_next), b.get("next_mask"))
            q_next = self.critic_target.smaller(next_obs, latent_next).squeeze(-1)
            y = self.loop.td_target(b, q_next)
        q1, q2 = (q.squeeze(-1) for q in self.critic(obs, latent))
        critic_loss = F.mse_loss(q1, y) + F.mse_loss(q2, y)
        descend(self.critic_optimizer, critic_loss, self._critic_params, cfg.grad_clip)
        stats.update(
            {
                "losses/critic_loss": float(critic_loss.detach()),
                "train/q_mean": float(q1.detach().mean()),
                "train/relabelled": relabelled,
            }
        )
        if self.n_updates % cfg.policy_delay == 0:
            bound = "invert" if cfg.bound == "invert" else "none"
            _, q_mu, grads = backprop_actor(self.actor, self._q1, obs, bound, self._actor_params)
            apply_gradients(self.actor_optimizer, grads, cfg.grad_clip)
            self._soft_update(cfg.tau)
            stats["losses/actor_loss"] = float(-q_mu.mean())
        return stats
