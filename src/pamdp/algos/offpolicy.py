"""What the off-policy algorithms share: their loop settings, the collect-and-learn loop over a replay buffer,
target networks, twin critics, the entropy temperature rule, and the bounded-gradient tricks of deterministic
actors. How the loop treats autoreset, truncation and Monte-Carlo returns: docs/algorithms.md, "The off-policy
family".
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from collections.abc import Callable, Sequence

import numpy as np
import torch
from torch import nn

from pamdp.algos.replay import ReplayBuffer, transition_fields
from pamdp.algos.settings import LAYERS, NON_NEGATIVE, POSITIVE, at_least, interval, one_of, redeclared, setting
from pamdp.distributions import masked_logits
from pamdp.envs.stepping import Step, VectorStepper
from pamdp.nn.optim import apply_gradients
from pamdp.nn.subnormals import subnormals_flushed
from pamdp.policies import ACTIVATIONS

__all__ = [
    "OffPolicyConfig",
    "DeterministicActorConfig",
    "OffPolicyLoop",
    "Temperatures",
    "temperature_gradient",
    "OUNoise",
    "soft_updater",
    "linear_epsilon",
    "EpsilonSchedule",
    "uniform_actions",
    "mixed_target",
    "discounted_returns",
    "BOUNDS",
    "invert_gradients",
    "zero_gradients",
    "bounded",
    "backprop_actor",
]

BOUNDS = ("invert", "squash", "zero")

#: An epoch's mean critic value (its ``train/q_mean``) beyond this many times the largest discounted return the
#: replay's rewards allow, ``max |r| / (1 - gamma)``, is taken for a diverged critic (:meth:`OffPolicyLoop.run_epoch`).
DIVERGED = 10.0


@dataclasses.dataclass(frozen=True)
class OffPolicyConfig:
    """The settings of the collect-and-learn loop and its replay, declared once for every off-policy algorithm.

    An algorithm's config inherits it beside :class:`~pamdp.algos.settings.AlgoConfig`
    (``class PADDPGConfig(OffPolicyConfig, AlgoConfig)``) and declares its own ``learning_starts``; a setting
    whose paper gives another default is declared again with :meth:`shared_setting`.
    """

    num_envs: int = setting(
        8,
        "Copies of the env stepped together; learning per sample is set by updates_per_step, not by this.",
        at_least(1),
    )
    batch_size: int = setting(64, "Transitions per gradient update.", at_least(1))
    gamma: float = setting(0.99, "Discount factor.", interval(0, 1))
    grad_clip: float = setting(
        0.0, "Clip each network's gradient norm to this before a step; 0 turns clipping off.", NON_NEGATIVE
    )
    buffer_size: int = setting(
        1_000_000, "Replay capacity; memory grows with the contents, not the capacity.", at_least(1)
    )
    updates_per_step: float = setting(1.0, "Update-to-data ratio: gradient updates per environment sample.", POSITIVE)
    epoch_steps: int = setting(
        10_000, "Samples per epoch, the unit of logging and checkpoints (paper: 10 000).", at_least(1)
    )
    save_replay: bool = setting(
        False, "Store the replay contents in checkpoints (large); otherwise a resumed run refills the buffer."
    )
    reward_scale: float = setting(
        1.0,
        "Rewards are multiplied by this before they are stored, so the critics learn scaled values (MP-DQN's Goal "
        "script: 1/50); logged returns and evaluations stay the env's.",
        POSITIVE,
    )
    hidden_sizes: tuple[int, ...] = setting(
        (256, 256), "Hidden layers of the actor (or policy) and the critics.", LAYERS
    )
    activation: str = setting("relu", "Hidden activation: relu, leaky_relu, tanh or elu.", one_of(ACTIVATIONS))

    # How an algorithm's config declares its own values of the family's settings; methods of the family config, so
    # that an algorithm imports its family's names once.
    @staticmethod
    def shared_setting(name: str, default, source: str | None = None):
        """The family's setting ``name`` (of :class:`OffPolicyConfig` or :class:`DeterministicActorConfig`) declared
        again with an algorithm's own ``default``, its help and check kept (:func:`~pamdp.algos.settings.redeclared`).
        """
        base = OffPolicyConfig if name in OffPolicyConfig.__dataclass_fields__ else DeterministicActorConfig
        return redeclared(base, name, default, source)

    @staticmethod
    def learning_starts_setting(default: int, source: str) -> int:
        """The ``learning_starts`` setting of an algorithm's config, with its ``default`` and where the value comes
        from (HyAR's is no setting: its warm-up, ``warmup_steps``)."""
        return setting(default, f"Samples in the replay buffer before the first update ({source}).", at_least(0))

    @staticmethod
    def tau_setting(default: float, source: str) -> float:
        """A soft target-update rate (:func:`soft_updater`'s ``tau``), with its ``default`` and where it comes from."""
        help = f"Soft target-update rate, target <- tau * online + (1 - tau) * target ({source})."
        return setting(default, help, interval(0, 1, low_open=True))


@dataclasses.dataclass(frozen=True)
class DeterministicActorConfig:
    """The settings of a deterministic actor with outputs in ``[-1, 1]`` (PADDPG's and P-DQN's), declared once as
    :class:`OffPolicyConfig`'s are: how the outputs are kept in bounds, the Monte-Carlo part of the target, and
    the exploration, epsilon-greedy with Ornstein-Uhlenbeck noise. The defaults are PADDPG's, Hausknecht & Stone's.
    """

    bound: str = setting(
        "invert",
        "Keeping outputs in [-1, 1]: invert (Hausknecht & Stone's inverting gradients), squash (Tanh) or zero.",
        one_of(BOUNDS),
    )
    beta: float = setting(
        0.2,
        "Weight of the Monte-Carlo return in the target (H&S: 0.2 to 0.5); 0 gives DDPG's pure TD target.",
        interval(0, 1),
    )
    epsilon_start: float = setting(
        1.0, "Exploration rate at the start: the chance of a uniformly random action.", interval(0, 1)
    )
    epsilon_end: float = setting(0.1, "Exploration rate after the annealing.", interval(0, 1))
    epsilon_steps: int = setting(
        100_000, "Environment samples over which epsilon falls linearly to epsilon_end.", at_least(1)
    )
    ou_sigma: float = setting(
        0.0,
        "Scale of Ornstein-Uhlenbeck noise on the actor's parameters, in [-1, 1] units; 0 turns it off.",
        NON_NEGATIVE,
    )
    ou_theta: float = setting(
        0.15,
        "Mean reversion of the Ornstein-Uhlenbeck noise (DDPG's 0.15); 1 gives i.i.d. Gaussian noise.",
        interval(0, 1, low_open=True),
    )


# act(obs (N, d) tensor, global step, episode_start (N,) bool, mask (N, K) bool tensor or None)
#     -> (a (N,), x (N, m) in [-1, 1], extra fields); mask: the allowed actions, with the action_mask setting only
ActFn = Callable[
    [torch.Tensor, int, np.ndarray, torch.Tensor | None], tuple[torch.Tensor, torch.Tensor, dict[str, np.ndarray]]
]
# update() -> the figures it computed; an epoch's stats average each one over the updates that returned it, so a
# figure computed every few updates (a delayed actor step, a representation round) is the mean of those steps. A
# figure may be a one-element tensor: the loop sums it on the tensor and reads it once an epoch.
UpdateFn = Callable[[], dict[str, float | torch.Tensor]]


def soft_updater(pairs: Sequence[tuple[nn.Module, nn.Module]]) -> Callable[[float], None]:
    """Polyak averaging of target networks, as DDPG's, ``theta' <- tau * theta + (1 - tau) * theta'``, for every
    ``(target, source)`` pair in one foreach call (not a kernel per tensor), the parameter lists gathered once (a
    module's ``parameters()`` walk costs more than the update itself at these sizes)."""
    targets = [p for target, _ in pairs for p in target.parameters()]
    sources = [p for _, source in pairs for p in source.parameters()]

    def update(tau: float) -> None:
        with torch.no_grad():
            torch._foreach_lerp_(targets, sources, tau)

    return update


class Temperatures(nn.Module):
    """Entropy temperatures ``alpha = exp(log alpha)``, one parameter ``log_<name>`` per keyword (its initial
    ``alpha``), tuned by SAC's rule (Haarnoja et al. 2018, "Soft Actor-Critic Algorithms and Applications"):
    descent along :func:`temperature_gradient`. PASVG(0) has one, for ``pi_d``; Hybrid SAC one per part."""

    def __init__(self, **initial: float):
        super().__init__()
        for name, alpha in initial.items():
            self.register_parameter(f"log_{name}", nn.Parameter(torch.tensor(math.log(alpha), dtype=torch.float32)))

    def alphas(self) -> tuple[torch.Tensor, ...]:
        """Each ``alpha``, detached, in the order of the keywords."""
        return tuple(p.detach().exp() for p in self.parameters())

    def step(self, optimizer: torch.optim.Optimizer, *entropies: tuple[torch.Tensor, torch.Tensor | float]) -> None:
        """One step of ``optimizer`` (over these parameters) on each ``log alpha`` along :func:`temperature_gradient`
        of its ``(entropy estimates, target)``, computed in the estimates' precision."""
        grads = [temperature_gradient(h, target).to(p.dtype) for (h, target), p in zip(entropies, self.parameters())]
        apply_gradients(optimizer, grads)


def temperature_gradient(entropy: torch.Tensor, target: torch.Tensor | float) -> torch.Tensor:
    """The gradient in ``log alpha`` of SAC's temperature loss ``mean(log alpha * (H - target))``, the entropy
    estimates ``H`` held fixed: ``mean(H - target)`` (why: docs/algorithms.md, "The off-policy family")."""
    return (entropy - target).mean()


class OUNoise:
    """Ornstein-Uhlenbeck exploration noise, one process per env copy: ``n <- n - theta n + sigma N(0, 1)``.

    A copy's process restarts at 0 with each of its episodes. ``theta = 1`` gives independent Gaussian noise
    of standard deviation ``sigma`` at every step. The state is not checkpointed.
    """

    def __init__(self, theta: float, sigma: float):
        self.theta, self.sigma = theta, sigma
        self.state: np.ndarray | None = None

    def __call__(self, shape: tuple[int, int], episode_start: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """The next noise ``(num_envs, size)``; ``episode_start`` marks the copies whose episode just began."""
        if self.state is None or self.state.shape != shape:
            self.state = np.zeros(shape)
        self.state[episode_start] = 0.0
        self.state += -self.theta * self.state + self.sigma * rng.standard_normal(shape)
        return self.state


def linear_epsilon(step: int, start: float, end: float, steps: int) -> float:
    """An exploration rate falling linearly from ``start`` to ``end`` over ``steps`` samples, then held."""
    return start + min(step / steps, 1.0) * (end - start)


class EpsilonSchedule:
    """An algorithm's ``epsilon(step)``: its config's ``epsilon_start`` falling linearly to ``epsilon_end`` over
    ``epsilon_steps`` samples (PADDPG's and P-DQN's exploration rate, HyAR's chance of a drawn embedding), and
    ``train/epsilon`` at the end of each epoch; a base beside :class:`~pamdp.algos.base.Algorithm`."""

    def epsilon(self, step: int) -> float:
        """The exploration rate after ``step`` samples: linear from epsilon_start to epsilon_end."""
        cfg = self.config
        return linear_epsilon(step, cfg.epsilon_start, cfg.epsilon_end, cfg.epsilon_steps)

    def _epoch_stats(self, step: int) -> dict[str, float]:
        return {"train/epsilon": self.epsilon(step)}


def uniform_actions(
    n: int, n_actions: int, mask: torch.Tensor | None, rng: np.random.Generator | torch.Generator, device
) -> torch.Tensor:
    """``n`` discrete actions drawn uniformly among those ``mask`` allows (bool ``(n, K)``; ``None``: all K), on
    ``device``, from ``rng`` (NumPy's or torch's). Without a mask the draw is ``rng``'s integers in ``[0, K)``,
    as before masks existed; with one, the argmax of uniform scores over the allowed actions."""
    if isinstance(rng, torch.Generator):
        if mask is None:
            return torch.randint(n_actions, (n,), generator=rng, device=device)
        scores = torch.rand((n, n_actions), generator=rng, device=device)
    else:
        if mask is None:
            return torch.from_numpy(rng.integers(n_actions, size=n)).to(device)
        scores = torch.from_numpy(rng.random((n, n_actions))).to(device)
    return masked_logits(scores, mask).argmax(-1)


def mixed_target(y: torch.Tensor, mc: torch.Tensor, beta: float) -> torch.Tensor:
    """Hausknecht & Stone's mixed target ``beta * MC + (1 - beta) * y`` where the Monte-Carlo return is known.

    ``mc`` is NaN for transitions whose episode has not ended yet; those keep the TD target ``y``.
    """
    return torch.where(torch.isnan(mc), y, beta * mc.nan_to_num() + (1 - beta) * y)


def discounted_returns(rewards: np.ndarray, gamma: float, tail: float = 0.0) -> np.ndarray:
    """Return-to-go ``G_t = r_t + gamma G_{t+1}`` of one episode, with ``G_T = tail`` after its last step."""
    out = np.empty(len(rewards))
    g = tail
    for t in range(len(rewards) - 1, -1, -1):
        g = rewards[t] + gamma * g
        out[t] = g
    return out


def invert_gradients(grad: torch.Tensor, p: torch.Tensor, low: float = -1.0, high: float = 1.0) -> torch.Tensor:
    """Hausknecht & Stone's inverting gradients, for an ascent direction ``grad = dQ/dp`` at outputs ``p``.

    Components that would increase ``p`` are scaled by ``(high - p) / (high - low)``, those that would
    decrease it by ``(p - low) / (high - low)``: 0 at the bound being approached, 1 at the far bound, and
    negative (pushing back) once ``p`` is past it.
    """
    width = high - low
    return grad * torch.where(grad > 0, (high - p) / width, (p - low) / width)


def zero_gradients(grad: torch.Tensor, p: torch.Tensor, low: float = -1.0, high: float = 1.0) -> torch.Tensor:
    """Zero the components of the ascent direction ``grad`` that push an output at or past a bound further out."""
    leaving = ((grad > 0) & (p >= high)) | ((grad < 0) & (p <= low))
    return torch.where(leaving, torch.zeros_like(grad), grad)


def bounded(dq_dp: torch.Tensor, p: torch.Tensor, bound: str) -> torch.Tensor:
    """``dQ/dp`` at outputs ``p`` edited by ``bound`` (:data:`BOUNDS`; ``squash``, a Tanh layer, keeps it)."""
    if bound == "invert":
        return invert_gradients(dq_dp, p)
    if bound == "zero":
        return zero_gradients(dq_dp, p)
    return dq_dp


def backprop_actor(
    actor: Callable[[torch.Tensor], torch.Tensor],
    critic: Callable[[torch.Tensor, torch.Tensor], torch.Tensor],
    obs: torch.Tensor,
    bound: str,
    params: Sequence[torch.Tensor],
) -> tuple[torch.Tensor, torch.Tensor, tuple[torch.Tensor, ...]]:
    """Back-propagate ``-mean_s Q(s, mu(s))`` into the actor's ``params``, with ``dQ/dmu`` edited by ``bound`` on
    the way (for :func:`~pamdp.nn.optim.apply_gradients`).

    ``Q`` is summed over its last axis if it has one (P-DQN's K values). The critic's weights get no gradient.
    Returns the actor's outputs and ``Q(s, mu(s))``, detached, and the gradients in ``params``.
    """
    out = actor(obs)
    p = out.detach().requires_grad_(True)
    q = critic(obs, p)
    (dq_dp,) = torch.autograd.grad(q.sum(), p)  # per-sample dQ/dp, the ascent direction
    grads = torch.autograd.grad(out, params, -bounded(dq_dp, p.detach(), bound) / len(out))  # descend on -mean Q
    return out.detach(), q.detach(), grads


class OffPolicyLoop:
    """Collect-and-learn epochs of an off-policy algorithm over its replay buffer (docs/algorithms.md, "The off-policy
    family").

    The loop receives the algorithm and reads from it what it needs: the settings (an :class:`OffPolicyConfig`
    with ``learning_starts`` and ``flush_denormal``; the updates, not the env steps, flush subnormal floats to
    zero), the env (``vec_env``), the random stream (``np_rng``), the device, and the two methods of the loop,
    ``_explore`` (:data:`ActFn`) and ``_update`` (:data:`UpdateFn`). It builds the replay buffer, :attr:`buffer`,
    with the fields every off-policy algorithm stores, the algorithm's ``fields`` and ``mc`` with ``mc_returns``.

    Args:
        algo: the algorithm.
        mc_returns: compute Monte-Carlo returns (discounted by ``config.gamma``) when episodes end.
        tail_value: with ``mc_returns``, the value of a truncated episode's final observations
            ``(B, d)`` with their action masks (``(B, K)`` bool, or ``None``) ``-> (B,)``, tensors on the
            algorithm's device, which bootstraps its Monte-Carlo return; ``None`` treats the cut as an end.
        fields: the algorithm's own fields, ``name=(shape, dtype)``.

    With the ``action_mask`` setting the loop reads the env's ``info["action_mask"]`` at every step, passes the
    current state's to ``_explore`` and stores both states' in the buffer's ``mask`` and ``next_mask`` fields.
    Its checkpoint state (:meth:`state_dict`) is the buffer's and the update credit.
    """

    def __init__(
        self,
        algo,
        mc_returns: bool = False,
        tail_value: Callable[[torch.Tensor, torch.Tensor | None], torch.Tensor] | None = None,
        **fields,
    ):
        cfg, hybrid = algo.config, algo.hybrid
        self.algo, self.config, self.hybrid = algo, cfg, hybrid
        masks = hybrid.n_actions if cfg.action_mask else 0
        spec = transition_fields(algo.obs_dim, hybrid.max_param_size, mc_returns=mc_returns, masks=masks, **fields)
        self.buffer = ReplayBuffer(cfg.buffer_size, spec, algo.device)
        self.mc_returns = mc_returns
        self.tail_value = tail_value
        self.update_credit = 0.0
        self.stepper: VectorStepper | None = None  # the env's copies, from the first epoch on
        self.diverged_warned = False  # the warning of a diverged critic is given once a model

    def td_target(self, batch: dict[str, torch.Tensor], next_value: torch.Tensor) -> torch.Tensor:
        """``y = r + gamma V(s')`` of a replayed batch, with no bootstrap after a termination; where the loop keeps
        Monte-Carlo returns (``mc_returns``: PADDPG's and P-DQN's ``beta > 0``), :func:`mixed_target` with ``beta``."""
        y = batch["reward"] + self.config.gamma * (~batch["terminated"]).float() * next_value
        return mixed_target(y, batch["mc"], self.config.beta) if self.mc_returns else y

    def budget_note(self, total: int) -> str | None:
        """Why ``total`` more samples make no gradient update (the replay would not reach ``learning_starts``), or
        ``None``."""
        held, starts = len(self.buffer), self.config.learning_starts
        if held + total >= starts:
            return None
        name = "warmup_steps" if hasattr(self.config, "warmup_steps") else "learning_starts"
        return (
            f"total_timesteps = {total:,} makes no gradient update: the first comes once the replay holds {name} = "
            f"{starts:,} samples and it holds {held:,}; give at least {starts - held:,} steps to train"
        )

    def run_epoch(self, budget: int | None = None) -> dict[str, float]:
        """Collect at least ``config.epoch_steps`` valid transitions (``budget`` where fewer are left), updating as
        they arrive; returns the epoch's stats with the algorithm's ``_epoch_stats`` at its end (``_explore`` gets
        the running count of samples)."""
        cfg, algo, n_actions = self.config, self.algo, self.hybrid.n_actions
        act, update, start_step, device = algo._explore, algo._update, algo.num_timesteps, algo.device
        if self.stepper is None:
            env = algo.vec_env
            self.stepper = VectorStepper(env, n_actions, cfg.action_mask, int(algo.np_rng.integers(2**31 - 1)))
            self.episode_start = np.ones(env.num_envs, dtype=bool)
            self._pending: list[tuple[list[int], list[float]]] = [([], []) for _ in range(env.num_envs)]
        stepper = self.stepper
        counts = np.zeros(n_actions, dtype=np.int64)
        sums: dict[str, float] = {}
        reported: dict[str, int] = {}  # per key: the updates that computed it (some run every few updates only)
        n_updates = n_valid = 0
        limit = cfg.epoch_steps if budget is None else min(cfg.epoch_steps, budget)
        while n_valid < limit:
            obs = torch.from_numpy(np.asarray(stepper.obs, dtype=np.float32))
            mask = None if stepper.masks is None else torch.from_numpy(stepper.masks).to(device)
            with torch.no_grad():  # the observations to the algorithm's device, the actions back
                a, x, extras = act(obs.to(device), start_step + n_valid, self.episode_start, mask)
            a, x = a.cpu().numpy(), x.cpu().numpy()
            step = stepper.step(self.hybrid.to_env_batch(a, x))
            valid = step.valid
            self.episode_start = ~valid
            if not valid.any():
                continue
            row = {
                "obs": obs.numpy()[valid],
                "a": a[valid],
                "x": x[valid],
                "reward": (np.asarray(step.reward, dtype=np.float64) * cfg.reward_scale).astype(np.float32)[valid],
                "next_obs": np.asarray(step.next_obs, dtype=np.float32)[valid],
                "terminated": step.terminated[valid],
                **{k: v[valid] for k, v in extras.items()},
            }
            if self.mc_returns:
                row["mc"] = np.full(int(valid.sum()), np.nan, dtype=np.float32)
            if step.masks is not None:
                row["mask"], row["next_mask"] = step.masks[valid], step.next_masks[valid]
            counters = self.buffer.add(**row)
            if self.mc_returns:
                self._finish_returns(counters, step)
            counts += np.bincount(a[valid], minlength=n_actions)
            n = int(valid.sum())
            n_valid += n
            if len(self.buffer) >= cfg.learning_starts:
                self.update_credit += cfg.updates_per_step * n
                with subnormals_flushed(cfg.flush_denormal):
                    while self.update_credit >= 1.0:
                        self.update_credit -= 1.0
                        for k, v in update().items():
                            sums[k] = sums.get(k, 0.0) + v
                            reported[k] = reported.get(k, 0) + 1
                        n_updates += 1
        stats = {k: float(v) / reported[k] for k, v in sums.items()}  # tensors read once an epoch, not per update
        stats["train/updates"] = float(n_updates)
        stats["train/buffer_size"] = float(len(self.buffer))
        stats.update({f"train/action_freq_{k}": float(c) / n_valid for k, c in enumerate(counts)})
        stats.update(stepper.episodes.pop())
        stats["steps"] = n_valid
        stats.update(algo._epoch_stats(start_step + n_valid))
        self._check_critic(stats, start_step + n_valid)
        return stats

    def _check_critic(self, stats: dict[str, float], step: int) -> None:
        """Log ``train/q_bound``, the largest discounted return the replay's rewards allow (``max |r| / (1 -
        gamma)``, on the critics' scale), and warn once, with a ``RuntimeWarning``, where the epoch's mean critic
        value is not finite or lies beyond :data:`DIVERGED` times it (times 1 where it is smaller, the scale of an
        untrained network's outputs): a diverged critic, whose greedy policy's figures would otherwise look like
        those of a run that merely learned little."""
        q, gamma = stats.get("train/q_mean"), self.config.gamma
        if q is None or len(self.buffer) == 0:
            return
        largest = float(self.buffer.data["reward"][: len(self.buffer)].abs().max())
        bound = stats["train/q_bound"] = largest / (1.0 - gamma) if gamma < 1 else math.inf
        limit = DIVERGED * max(bound, 1.0)
        if (math.isfinite(q) and abs(q) <= limit) or self.diverged_warned:
            return
        self.diverged_warned = True
        warnings.warn(
            f"the critics have likely diverged: their mean value in the epoch ending at step {step:,} is {q:.4g}, "
            f"beyond {limit:.4g}, {DIVERGED:g} times the largest discounted return the replay's rewards allow "
            f"(max |reward| {largest:.4g} after reward_scale, gamma {gamma:g}: {bound:.4g}; 1 where smaller); "
            "the greedy policy's figures mean little from here on. A smaller critic learning rate, a slower target "
            "(tau) or grad_clip may hold them.",
            RuntimeWarning,
            stacklevel=2,
        )

    def _finish_returns(self, counters: np.ndarray, step: Step) -> None:
        """Queue this step's transitions per env copy; write their Monte-Carlo returns when episodes end."""
        ended = step.ended
        tails = np.zeros(len(step.done))
        cut = [i for i in ended if not step.terminated[i]]
        if cut and self.tail_value is not None:
            device = self.algo.device
            obs = torch.from_numpy(np.asarray(step.next_obs, dtype=np.float32)[cut]).to(device)
            masks = None if step.next_masks is None else torch.from_numpy(step.next_masks[cut]).to(device)
            with torch.no_grad():
                tails[cut] = self.tail_value(obs, masks).cpu().numpy()
        for c, i in zip(counters, np.flatnonzero(step.valid)):
            self._pending[i][0].append(int(c))
            self._pending[i][1].append(float(step.reward[i]) * self.config.reward_scale)  # on the critics' scale
        for i in ended:
            stored, rewards = self._pending[i]
            returns = discounted_returns(np.asarray(rewards), self.config.gamma, float(tails[i]))
            self.buffer.write("mc", np.asarray(stored), returns.astype(np.float32))
            self._pending[i] = ([], [])

    def state_dict(self, include_buffer: bool) -> dict:
        return {"buffer": self.buffer.state_dict(include_buffer), "update_credit": float(self.update_credit)}

    def load_state_dict(self, state: dict) -> None:
        self.buffer.load_state_dict(state["buffer"])
        self.update_credit = float(state["update_credit"])
