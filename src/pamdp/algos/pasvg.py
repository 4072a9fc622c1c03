"""PASVG(0): stochastic value gradients through a Gumbel-Softmax hierarchical policy (Wei, Wicke & Luke 2018).

Section "Parameterized Actions SVG(0)" of the paper: acting draws Gumbel noise for ``pi_d`` and Gaussian noise
for ``pi_c``, records it with the transition, and one loss ``-Q(s, f(s, eta_a), g(s, f(s, eta_a), eta_x))``
trains both policies through the relaxed sample (or, with ``discrete_gradient="expected"``, through the exact
expectation over the K actions). The maths: docs/algorithms.md, "PASVG(0)".
"""

from __future__ import annotations

import copy
import dataclasses
import math
from collections.abc import Callable

import numpy as np
import torch
import torch.nn.functional as F

from pamdp.algos.base import Algorithm
from pamdp.algos.offpolicy import OffPolicyConfig, OffPolicyLoop, Temperatures, soft_updater, uniform_actions
from pamdp.algos.settings import NON_NEGATIVE, POSITIVE, AlgoConfig, Check, at_least, interval, one_of, setting
from pamdp.distributions import LOG_STD_MAX, LOG_STD_MIN, gumbel_noise, masked_logits
from pamdp.nn.dense import Dense
from pamdp.nn.optim import apply_gradients, descend
from pamdp.policies import GumbelHybridPolicy, TwinQ, every_action_linear

__all__ = ["PASVG0", "PASVG0Config", "expected_q", "every_action_q"]


@dataclasses.dataclass(frozen=True)
class PASVG0Config(OffPolicyConfig, AlgoConfig):
    """PASVG(0)'s settings; the defaults are the paper's preset (DDPG's where the paper says nothing)."""

    hidden_sizes: tuple[int, ...] = OffPolicyConfig.shared_setting(
        "hidden_sizes", (400, 300), "pi_d, pi_c and the critic; paper: {400, 300}"
    )
    activation: str = OffPolicyConfig.shared_setting("activation", "relu", "paper: relu")
    temperature: float = setting(
        1.0, "Gumbel-Softmax temperature t (paper: 1.0, fixed); lower is less biased, higher less noisy.", POSITIVE
    )
    straight_through: bool = setting(
        True,
        "The critic sees the hard one-hot (straight-through gradient); false: the soft Gumbel-Softmax sample.",
    )
    init_log_std: float = setting(
        -0.5,
        "Initial log-std of the parameter noise, added before pi_c's Tanh (so x stays in [-1, 1]).",
        interval(LOG_STD_MIN, LOG_STD_MAX),
    )
    learn_std: bool = setting(True, "Train the parameter noise's log-std by the value gradient too (SVG); else fixed.")
    entropy_coef: float = setting(
        0.0,
        "Weight of pi_d's entropy in the policy loss (0 in the paper); keeps the discrete choice exploring. "
        "With target_entropy set, the weight's starting value.",
        NON_NEGATIVE,
    )
    target_entropy: float | None = setting(
        None,
        "If set, the entropy weight is tuned (as in SAC) to hold pi_d's mean entropy at this many nats, "
        "between 0 and ln K; None keeps entropy_coef fixed.",
        Check(lambda v: v is None or v >= 0, "None or a non-negative entropy in nats"),
    )
    entropy_lr: float = setting(
        3e-4, "Adam learning rate of the log entropy weight when target_entropy is set.", POSITIVE
    )
    explore_epsilon: float = setting(
        0.0,
        "Fraction of collected discrete actions drawn uniformly instead of from pi_d, so that every action keeps "
        "appearing in replay (the policy update never sees them; 0 in the paper).",
        interval(0, 1),
    )
    discrete_gradient: str = setting(
        "gumbel",
        "pi_d's gradient: gumbel (the paper's, through the Gumbel-Softmax sample) or expected (the exact "
        "expectation over the K actions, in the policy loss and the TD target; not in the paper).",
        one_of(("gumbel", "expected")),
    )
    twin_critics: bool = setting(
        False,
        "Two critics trained on the same TD target, taken from the smaller of their two target networks "
        "(TD3's clipped double Q, against overestimation); the policy follows the first. Not in the paper.",
    )
    policy_delay: int = setting(
        1, "Critic updates per policy update (and soft target update); TD3 uses 2. 1 in the paper.", at_least(1)
    )
    critic_lr: float = setting(1e-3, "Adam learning rate of the critic (paper: 1e-3).", POSITIVE)
    policy_lr: float = setting(
        1e-5, "Adam learning rate of pi_d and pi_c (paper: 1e-5, which learns slowly).", POSITIVE
    )
    batch_size: int = OffPolicyConfig.shared_setting("batch_size", 64, "DDPG's 64; the paper does not say")
    tau: float = OffPolicyConfig.tau_setting(0.001, "DDPG's 0.001")
    buffer_size: int = OffPolicyConfig.shared_setting("buffer_size", 10_000_000, "paper: 10^7")
    learning_starts: int = OffPolicyConfig.learning_starts_setting(10_000, "paper: 10^4")

    def __post_init__(self):
        """The checks across settings (each setting's own runs in AlgoConfig)."""
        super().__post_init__()
        if self.target_entropy is not None:
            self._check(self.entropy_coef > 0, "entropy_coef", "a positive starting weight when target_entropy is set")
        if self.discrete_gradient == "expected":
            self._check(
                self.straight_through, "straight_through", "True with discrete_gradient 'expected' (Q sees one-hots)"
            )

    PRESETS = {
        "paper": {},
        # What each choice is: docs/algorithms.md, "PASVG(0)"; how it was reached: benchmarks/pasvg_tuning.md.
        "tuned": dict(
            num_envs=64,
            hidden_sizes=(128, 128),
            discrete_gradient="expected",
            init_log_std=-1.6,
            learn_std=False,
            policy_lr=1e-4,
            entropy_coef=0.1,
            target_entropy=0.3,
            explore_epsilon=0.05,
            tau=0.005,
            batch_size=128,
            updates_per_step=0.25,
            learning_starts=5_000,
            buffer_size=1_000_000,
        ),
    }


def expected_q(
    policy: GumbelHybridPolicy,
    critic: Callable,
    obs: torch.Tensor,
    eta_x: torch.Tensor,
    mask: torch.Tensor | None = None,
) -> tuple[torch.Tensor, torch.Tensor]:
    """``(logits, E_{k ~ pi_d}[Q(s, k, g(s, k, eta_x))])``: the value the Gumbel-Softmax sample estimates, exactly.

    Differentiable in both policies: in ``pi_d`` through the probabilities, in ``pi_c`` through every
    action's parameters, each weighted by its probability. With ``mask``, ``pi_d`` ranges over the allowed actions.
    """
    logits = masked_logits(policy.pi_d(obs), mask)
    q_all = critic(*policy.params_all(obs, eta_x))
    return logits, (logits.softmax(-1) * q_all).sum(-1)


def every_action_q(critic: TwinQ, smaller: bool = False) -> Callable:
    """:func:`expected_q`'s ``critic`` for a :class:`~pamdp.policies.TwinQ` on ``[s, a, x]``: ``Q_1(s, k, x_k)`` of
    every ``k`` (``(B, K)``; with ``smaller``, the smaller of both critics' values), the first layer's one-hot part by
    :func:`~pamdp.policies.every_action_linear` and the parameters' by one product, from the states' first copy."""
    nets = (critic.q1,) if not smaller or critic.q2 is None else (critic.q1, critic.q2)

    def q_all(obs_k: torch.Tensor, onehots: torch.Tensor, x: torch.Tensor) -> torch.Tensor:
        obs, split = obs_k[:, 0], obs_k.shape[-1] + x.shape[-2]
        values = []
        for net in nets:
            first = net[0]
            pre = every_action_linear(obs, first.weight[:, :split], first.bias) + F.linear(x, first.weight[:, split:])
            values.append(net[1:](pre).squeeze(-1))
        return values[0] if len(values) == 1 else torch.minimum(*values)

    return q_all


class PASVG0(Algorithm):
    """Parameterized Actions SVG(0). See docs/algorithms.md, "PASVG(0)", for the update and :class:`PASVG0Config`."""

    config_class = PASVG0Config
    config: PASVG0Config
    MODULES = ("policy", "critic", "policy_target", "critic_target", "entropy_weight")  # the last: target_entropy
    OPTIMIZERS = {"policy": "policy_optimizer", "critic": "critic_optimizer", "entropy_weight": "entropy_optimizer"}

    def _build(self) -> None:
        cfg, h = self.config, self.hybrid
        self.policy = GumbelHybridPolicy(self.obs_dim, h, cfg.hidden_sizes, cfg.activation, cfg.init_log_std)
        self.policy.log_std.requires_grad_(cfg.learn_std)
        # Q(s, a, x), the discrete action a one-hot (or the soft sample); with twin_critics a second one
        in_size = self.obs_dim + h.n_actions + h.max_param_size
        self.critic = TwinQ(in_size, 1, cfg.hidden_sizes, cfg.activation, twin=cfg.twin_critics)
        self.policy_target = copy.deepcopy(self.policy).requires_grad_(False)
        self.critic_target = copy.deepcopy(self.critic).requires_grad_(False)
        self.critic_params = list(self.critic.parameters())
        self.critic_updates = 0  # for policy_delay
        self.policy_params = [p for p in self.policy.parameters() if p.requires_grad]
        self.policy_optimizer = torch.optim.Adam(self.policy_params, lr=cfg.policy_lr, fused=True)
        self.critic_optimizer = torch.optim.Adam(self.critic_params, lr=cfg.critic_lr, fused=True)
        self.entropy_weight = self.entropy_optimizer = None
        if cfg.target_entropy is not None:
            if cfg.target_entropy > math.log(h.n_actions):
                raise ValueError(
                    f"PASVG0Config.target_entropy = {cfg.target_entropy!r}; expected at most ln K = "
                    f"{math.log(h.n_actions):.4f} nats for this env's K = {h.n_actions} actions"
                )
            self.entropy_weight = Temperatures(alpha=cfg.entropy_coef)  # pi_d's, tuned by SAC's rule
            self.entropy_optimizer = torch.optim.Adam(self.entropy_weight.parameters(), lr=cfg.entropy_lr)
        K, m = h.n_actions, h.max_param_size
        self.loop = OffPolicyLoop(
            self,
            a_in=((K,), np.float32),  # the critic's action input: one-hot, or the soft sample
            eta_a=((K,), np.float32),
            eta_x=((m,), np.float32),
        )
        self.replay = self.loop.buffer
        self._bind_networks()

    def _bind_networks(self) -> None:
        """The soft target update over the modules' own tensors and, with the paper's settings, the hand-written
        update's views of the networks (:mod:`pamdp.nn.dense`). Called again by whoever replaces a module."""
        self._soft_update = soft_updater([(self.critic_target, self.critic), (self.policy_target, self.policy)])
        cfg = self.config
        self._dense = None
        # The paper's settings: the Gumbel-Softmax gradient, one critic, no policy delay, a fixed entropy weight.
        paper = cfg.discrete_gradient == "gumbel" and not cfg.twin_critics and cfg.policy_delay == 1
        if paper and cfg.target_entropy is None:
            self._dense = {
                "pi_d": Dense.of(self.policy.pi_d),
                "pi_c": Dense.of(self.policy.pi_c),
                "critic": Dense.of(self.critic.q1),
            }

    def _extra_state(self):
        return {"critic_updates": self.critic_updates}

    def _load_extra_state(self, state):
        self.critic_updates = int(state.get("critic_updates", 0))  # absent from checkpoints before policy_delay

    def _noise(self, batch: int) -> tuple[torch.Tensor, torch.Tensor]:
        eta_a = gumbel_noise((batch, self.hybrid.n_actions), self.torch_gen)
        eta_x = torch.randn((batch, self.hybrid.max_param_size), generator=self.torch_gen, device=self.device)
        return eta_a, eta_x

    def _act(self, obs, deterministic, mask=None):
        if deterministic:
            return self.policy.mode(obs, mask)
        _, index, _, x = self.policy(obs, *self._noise(len(obs)), self.config.temperature, True, mask)
        return index, x

    def _explore(self, obs: torch.Tensor, step: int, episode_start: np.ndarray, mask: torch.Tensor | None):
        cfg = self.config
        eta_a, eta_x = self._noise(len(obs))
        _, index, a_in, x = self.policy(obs, eta_a, eta_x, cfg.temperature, cfg.straight_through, mask)
        if cfg.explore_epsilon > 0:  # drawn only when on, so that the paper's preset keeps its random stream
            n, K = len(obs), self.hybrid.n_actions
            flip = torch.rand(n, generator=self.torch_gen, device=self.device) < cfg.explore_epsilon
            uniform = uniform_actions(n, K, mask, self.torch_gen, self.device)
            onehot = F.one_hot(uniform, K).to(a_in.dtype)
            index = torch.where(flip, uniform, index)
            a_in = torch.where(flip[:, None], onehot, a_in)
            x = torch.where(flip[:, None], self.policy.params(obs, uniform, onehot, eta_x), x)
        return index, x, {"a_in": a_in.cpu().numpy(), "eta_a": eta_a.cpu().numpy(), "eta_x": eta_x.cpu().numpy()}

    def _q1(self, obs: torch.Tensor, a: torch.Tensor, x: torch.Tensor) -> torch.Tensor:
        """The first critic's ``Q(s, a, x)`` ``(B,)``, which the policy follows."""
        return self.critic.q1(torch.cat([obs, a, x], dim=-1)).squeeze(-1)

    @torch.no_grad()
    def _td_target(self, b: dict[str, torch.Tensor]) -> torch.Tensor:
        """``y = r + gamma Q'(s', a', x')``, the next action drawn from the target policy with fresh noise (or,
        with ``discrete_gradient="expected"``, ``E_{k ~ pi_d'}[Q'(s', k, x'_k)]``); no bootstrap after a
        termination."""
        cfg = self.config
        next_obs, mask = b["next_obs"], b.get("next_mask")
        eta_a, eta_x = self._noise(len(next_obs))
        if cfg.discrete_gradient == "expected":
            _, q_next = expected_q(self.policy_target, every_action_q(self.critic_target, True), next_obs, eta_x, mask)
        else:
            *_, a_next, x_next = self.policy_target(next_obs, eta_a, eta_x, cfg.temperature, cfg.straight_through, mask)
            q_next = self.critic_target.smaller(next_obs, a_next, x_next).squeeze(-1)
        return self.loop.td_target(b, q_next)

    def _update(self) -> dict[str, float]:
        """One critic TD step and (every ``policy_delay``-th call) one value-gradient step of both policies."""
        cfg = self.config
        b = self.replay.sample(cfg.batch_size, self.np_rng)
        y = self._td_target(b)
        if self._dense is not None:
            return self._update_by_hand(b, y)
        obs = b["obs"]
        q, q2 = self.critic(obs, b["a_in"], b["x"])
        q = q.squeeze(-1)
        critic_loss = F.mse_loss(q, y) if q2 is None else F.mse_loss(q, y) + F.mse_loss(q2.squeeze(-1), y)
        descend(self.critic_optimizer, critic_loss, self.critic_params, cfg.grad_clip)
        self.critic_updates += 1
        stats = {"losses/critic_loss": float(critic_loss.detach()), "train/q_mean": float(q.detach().mean())}
        if self.critic_updates % cfg.policy_delay == 0:
            stats.update(self._policy_update(b))
        return stats

    def _policy_update(self, b: dict[str, torch.Tensor]) -> dict[str, float]:
        """The value-gradient step of pi_d and pi_c, the entropy weight's step and the soft target updates."""
        cfg = self.config
        obs = b["obs"]
        # The recorded noise, pushed through the current policy: a = f(s, eta_a), x = g(s, a, eta_x).
        mask = b.get("mask")
        if cfg.discrete_gradient == "expected":
            logits, q_pi = expected_q(self.policy, every_action_q(self.critic), obs, b["eta_x"], mask)
        else:
            logits, _, a, x = self.policy(obs, b["eta_a"], b["eta_x"], cfg.temperature, cfg.straight_through, mask)
            q_pi = self._q1(obs, a, x)
        entropy = -(logits.softmax(-1) * logits.log_softmax(-1)).sum(-1).mean()
        alpha = cfg.entropy_coef if self.entropy_weight is None else float(self.entropy_weight.alphas()[0])
        actor_loss = -q_pi.mean() - alpha * entropy
        # The policy loss differentiates Q in (a, x) only: asking for the policy's gradients alone skips the
        # critic's weight gradients, which backward() would compute and the critic must not receive.
        descend(self.policy_optimizer, actor_loss, self.policy_params, cfg.grad_clip)
        if self.entropy_weight is not None:
            # in double, as the loss log_alpha * (float(H) - target) it replaced: the same step
            self.entropy_weight.step(self.entropy_optimizer, (entropy.detach().double(), cfg.target_entropy))
        self._soft_update(cfg.tau)
        return self._policy_stats(actor_loss.detach(), q_pi, entropy.detach(), alpha)

    def _policy_stats(self, actor_loss, q_pi, entropy, alpha) -> dict[str, float]:
        return {
            "losses/actor_loss": float(actor_loss),
            "train/q_pi_mean": float(q_pi.detach().mean()),
            "train/entropy": float(entropy),
            "train/entropy_coef": alpha,
            "train/param_std": float(self.policy.std().detach()[self.policy.mask.bool()].mean()),
        }

    @torch.no_grad()
    def _update_by_hand(self, b: dict[str, torch.Tensor], y: torch.Tensor) -> dict[str, float]:
        """:meth:`_update`'s two steps with the paper's settings, back-propagated by hand: the same gradients as
        autograd's (``tests/test_dense.py``) in fewer calls (``benchmarks/offpolicy_speed.md``).

        The straight-through one-hot carries the softmax's gradient, ``pi_c`` sees the action, and ``log_std``
        gets its rows' share through ``exp`` and the clamp."""
        cfg, nets, policy = self.config, self._dense, self.policy
        obs, eta_x = b["obs"], b["eta_x"]
        batch, d, K = obs.shape[0], obs.shape[1], policy.n_actions
        temperature, hard = cfg.temperature, cfg.straight_through
        critic = nets["critic"]
        q, error = critic.regression_step(
            self.critic_optimizer, torch.cat([obs, b["a_in"], b["x"]], dim=-1), y, cfg.grad_clip
        )
        self.critic_updates += 1

        # policy: descend on -mean Q(s, a, x) - alpha * mean H(pi_d), with the recorded noise
        logits, d_cache = nets["pi_d"].forward_cached(obs)
        # a forbidden action's probability is 0 exactly, so the gradient below is 0 at its logit
        log_p = masked_logits(logits, b.get("mask")).log_softmax(-1)
        z = log_p + b["eta_a"]
        soft_a = torch.softmax(z / temperature, dim=-1)
        index = z.argmax(-1)
        a = F.one_hot(index, K).to(soft_a.dtype) if hard else soft_a
        std = policy.std()[index]
        pre, c_cache = nets["pi_c"].forward_cached(torch.cat([obs, a], dim=-1))
        t = torch.tanh(pre + std * eta_x)
        rows = policy.mask[index]
        q_pi, q_cache = critic.forward_cached(torch.cat([obs, a, t * rows], dim=-1))
        _, d_in = critic.backward(q_cache, torch.full_like(q_pi, -1.0 / batch), weights=False, inputs=True)
        d_u = torch.ops.aten.tanh_backward(d_in[:, d + K :] * rows, t)  # through x = tanh(u) * mask
        pc_grads, d_pc_in = nets["pi_c"].backward(c_cache, d_u, inputs=True)
        d_a = d_in[:, d : d + K] + d_pc_in[:, d:]
        # a carries softmax(z / t)'s gradient (straight-through, or the soft sample itself), z = log pi_d + eta_a
        d_z = soft_a * (d_a - (d_a * soft_a).sum(-1, keepdim=True)) / temperature
        p = log_p.exp()
        d_logits = d_z - p * d_z.sum(-1, keepdim=True)
        entropy = -(p * log_p).sum(-1)
        alpha = cfg.entropy_coef
        if alpha:
            d_logits = d_logits + (alpha / batch) * p * (log_p + entropy.unsqueeze(-1))
        pd_grads, _ = nets["pi_d"].backward(d_cache, d_logits)
        grads = pd_grads + pc_grads
        if policy.log_std.requires_grad:  # the policy's own parameter, so first in its parameters()
            # u = mu + exp(clamp(log_std))[a] * eta_x: each row's share, summed over the samples of its action
            d_table = F.one_hot(index, K).to(d_u.dtype).t() @ (d_u * eta_x * std)
            inside = (policy.log_std >= LOG_STD_MIN) & (policy.log_std <= LOG_STD_MAX)
            grads.insert(0, d_table * inside)
        apply_gradients(self.policy_optimizer, grads, cfg.grad_clip)
        self._soft_update(cfg.tau)
        q_pi = q_pi.squeeze(-1)
        entropy = entropy.mean()
        stats = {"losses/critic_loss": float(error.square().mean()), "train/q_mean": float(q.mean())}
        stats.update(self._policy_stats(-q_pi.mean() - alpha * entropy, q_pi, entropy, alpha))
        return stats
