"""What the on-policy algorithms (PATRPO, PAPPO) share: sampling the hierarchical policy
(:meth:`Rollout.collect`), GAE from a baseline (:func:`advantage_batch`), the baselines. What differs, the policy
update, lives in each algorithm's file.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np
import torch

from pamdp.algos.settings import LAYERS, at_least, interval, one_of, setting
from pamdp.envs.stepping import VectorStepper
from pamdp.nn.subnormals import subnormals_flushed
from pamdp.policies import ACTIVATIONS, PI_C_INPUTS, HybridPolicy

__all__ = [
    "OnPolicyConfig",
    "OnPolicy",
    "hybrid_policy",
    "Rollout",
    "gae",
    "advantage_batch",
    "update_tensors",
    "LinearFeatureBaseline",
]


@dataclasses.dataclass(frozen=True)
class OnPolicyConfig:
    """The settings of the hierarchical policy, its sampling and its advantages, declared once for PATRPO and
    PAPPO; an algorithm's config inherits it beside :class:`~pamdp.algos.settings.AlgoConfig` (as the off-policy
    ones inherit :class:`~pamdp.algos.offpolicy.OffPolicyConfig`) and declares a setting whose default it changes
    again with :func:`~pamdp.algos.settings.redeclared`. The defaults are the common PPO ones."""

    num_envs: int = setting(
        64, "Copies of the env stepped together; the samples are on-policy, so more is just faster.", at_least(1)
    )
    hidden_sizes: tuple[int, ...] = setting((64, 64), "Hidden layers of pi_d and pi_c, each its own network.", LAYERS)
    activation: str = setting(
        "tanh", "Hidden activation of the policies: tanh (PPO's usual), relu, leaky_relu or elu.", one_of(ACTIVATIONS)
    )
    init_log_std: float = setting(0.0, "Initial log-std of the parameter noise, in [-1, 1] units.")
    pi_c_input: str = setting(
        "onehot",
        "What pi_c reads: onehot ([s, onehot(a)], the paper's) or state (s alone, a block of K * m outputs, one "
        "per action: every action's mean in one pass, for large K such as Hard Move's).",
        one_of(PI_C_INPUTS),
    )
    batch_size: int = setting(
        4096, "Samples per epoch, collected with the current policy before its update.", at_least(1)
    )
    gamma: float = setting(0.99, "Discount factor.", interval(0, 1))
    gae_lambda: float = setting(
        0.95, "GAE lambda: lower trades bias for less variance in the advantages.", interval(0, 1)
    )
    normalize_advantages: bool = setting(True, "Standardise advantages within the batch.")
    vf_hidden_sizes: tuple[int, ...] = setting((64, 64), "Hidden layers of the value network.", LAYERS)


class OnPolicy:
    """What PATRPO and PAPPO do alike as algorithms, a base beside :class:`~pamdp.algos.base.Algorithm` (as
    :class:`~pamdp.algos.offpolicy.EpsilonSchedule` is for off-policy ones): their hierarchical ``policy`` acts,
    their ``value`` network is the baseline, and ``train/param_std`` is their parameter noise's."""

    def _act(self, obs, deterministic, mask=None):
        return self.policy.act(obs, mask, deterministic, self.torch_gen)

    def _values(self, obs: np.ndarray, t: np.ndarray) -> np.ndarray:
        """The value network's ``V(s)`` of a batch of observations (computed on the algorithm's device), as float64
        for GAE."""
        with torch.no_grad():
            return self.value(self._obs_tensor(obs)).double().cpu().numpy()

    def _param_std(self) -> float:
        """``train/param_std``: the parameter noise's std, averaged over the parameters the actions have."""
        return float(self.policy.log_std.detach().exp()[self.policy.mask].mean())


def hybrid_policy(algo) -> HybridPolicy:
    """The hierarchical policy that ``algo``'s :class:`OnPolicyConfig` describes, for its env."""
    cfg = algo.config
    return HybridPolicy(algo.obs_dim, algo.hybrid, cfg.hidden_sizes, cfg.activation, cfg.init_log_std, cfg.pi_c_input)


def gae(
    rewards: np.ndarray,
    values: np.ndarray,
    next_values: np.ndarray,
    terminated: np.ndarray,
    done: np.ndarray,
    gamma: float,
    lam: float,
) -> np.ndarray:
    """Generalised advantage estimates over ``(T, N)`` arrays of ``N`` env copies stepped ``T`` times.

    ``next_values[t]`` is the value of the observation returned by step ``t``: it is bootstrapped unless the
    step ``terminated``; ``done`` (terminated or truncated) cuts the sum. The last row is always cut (the end
    of the epoch acts as a truncation).
    """
    adv = np.zeros_like(rewards, dtype=np.float64)
    last = np.zeros(rewards.shape[1])
    for t in range(rewards.shape[0] - 1, -1, -1):
        delta = rewards[t] + gamma * (1.0 - terminated[t]) * next_values[t] - values[t]
        last = delta + gamma * lam * (1.0 - done[t]) * last
        adv[t] = last
    return adv


class Rollout:
    """On-policy sampling of a :class:`~pamdp.policies.HybridPolicy` in a vector env.

    Episodes run on across epochs (an epoch's last step bootstraps from the baseline), so no partial
    episode is thrown away; a new ``Rollout`` (as after loading a model) starts new episodes. Gymnasium's
    vector envs reset a finished copy on the *next* step, ignoring its action: those autoreset steps are
    marked invalid and carry no sample.
    """

    KEYS = ("obs", "a", "x", "reward", "terminated", "done", "valid", "next_obs", "t")

    def __init__(self, algo):
        """``algo``: the algorithm, whose ``policy`` (a :class:`~pamdp.policies.HybridPolicy`) acts in its
        ``vec_env`` on its device, from its random streams. With the ``action_mask`` setting the policy samples
        among the actions each state's ``info["action_mask"]`` allows, and the batch records those masks
        (``"mask"``, bool ``(T, N, K)``) for the update's probabilities."""
        self.algo = algo
        self.action_mask = algo.config.action_mask
        self.stepper: VectorStepper | None = None  # the env's copies, from the first epoch on

    def collect(self, n_samples: int, exact: bool = False) -> dict[str, np.ndarray]:
        """Step the env with ``(a, x) ~ policy`` until ``n_samples`` valid samples; ``(T, N, ...)`` arrays of
        :attr:`KEYS` (``t``: the step within the episode; ``terminated`` and ``done`` are false at autoreset
        steps, which are not valid), and ``mask`` with ``action_mask``. With ``exact`` the last step's samples past
        ``n_samples`` are marked not valid too (the end of a budget): they are not trained on, but their rewards
        still reach the advantages of the steps before them.

        The policy runs on the algorithm's device and the env on the CPU: a step moves the observations there and
        the actions back, nothing else.
        """
        algo = self.algo
        if self.stepper is None:
            env = algo.vec_env
            seed = int(algo.np_rng.integers(2**31 - 1))
            self.stepper = VectorStepper(env, algo.hybrid.n_actions, self.action_mask, seed)
            self.t_ep = np.zeros(env.num_envs, dtype=np.int64)
        stepper, device = self.stepper, algo.device
        rows: dict[str, list] = {k: [] for k in self.KEYS + (("mask",) if self.action_mask else ())}
        n_valid = 0
        while n_valid < n_samples:
            with torch.no_grad():
                mask = None if stepper.masks is None else torch.from_numpy(stepper.masks).to(device)
                obs_t = torch.as_tensor(np.asarray(stepper.obs, dtype=np.float32), device=device)
                a, x = algo.policy.act(obs_t, mask, False, algo.torch_gen)
            a, x = a.cpu().numpy(), x.cpu().numpy()
            step = stepper.step(algo.hybrid.to_env_batch(a, x))
            row = (step.obs, a, x, step.reward, step.terminated, step.done, step.valid, step.next_obs, self.t_ep)
            for k, v in zip(self.KEYS, row):
                rows[k].append(np.array(v))
            if step.masks is not None:
                rows["mask"].append(step.masks)
            n_valid += int(step.valid.sum())
            self.t_ep = np.where(step.valid, self.t_ep + 1, 0)
        if exact and n_valid > n_samples:
            rows["valid"][-1][np.flatnonzero(rows["valid"][-1])[n_samples - n_valid :]] = False
        return {k: np.stack(v) for k, v in rows.items()}

    def budget_note(self, total: int) -> None:
        """None: any budget trains (its last epoch is cut to the samples left, down to part of one vector step)."""

    def run_epoch(self, budget: int | None = None) -> dict[str, float]:
        """One epoch: :meth:`collect` ``batch_size`` samples (exactly ``budget`` where no more are left), their
        :func:`advantage_batch` from the algorithm's baseline (``_values(obs, t)``), then its ``_learn`` of the batch
        (subnormals flushed with ``flush_denormal``). Returns ``_learn``'s stats with the baseline's explained
        variance, the discrete actions' frequencies, the episodes completed in the epoch, and ``steps``."""
        algo, cfg = self.algo, self.algo.config
        last = budget is not None and budget <= cfg.batch_size
        batch = self.collect(budget if last else cfg.batch_size, exact=last)
        data, explained_var = advantage_batch(batch, algo._values, cfg.gamma, cfg.gae_lambda, cfg.normalize_advantages)
        with subnormals_flushed(cfg.flush_denormal):
            stats = algo._learn(data)
        a = data["a"]
        freq = np.bincount(a, minlength=algo.hybrid.n_actions) / len(a)
        stats["train/explained_variance"] = explained_var
        stats.update({f"train/action_freq_{k}": float(f) for k, f in enumerate(freq)})
        stats.update(self.stepper.episodes.pop())
        stats["steps"] = len(a)
        return stats


def advantage_batch(
    batch: dict[str, np.ndarray],
    values_fn: Callable[[np.ndarray, np.ndarray], np.ndarray],
    gamma: float,
    lam: float,
    normalize: bool,
) -> tuple[dict[str, np.ndarray], float]:
    """GAE over a :meth:`Rollout.collect` batch, flattened to its valid samples.

    ``values_fn(obs, t)`` is the baseline's value ``(B,)`` of observations at step ``t`` of their episodes.
    Returns the valid samples' ``obs, t, a, x`` (and ``mask`` where the batch has one), ``adv`` (standardised
    within the batch when ``normalize``), ``returns`` (``adv + values``, the baseline's regression target) and
    ``values``, with the fraction of the returns' variance the values explain.
    """
    T, N = batch["reward"].shape
    flat = lambda arr: arr.reshape(T * N, *arr.shape[2:])  # noqa: E731
    values = values_fn(flat(batch["obs"]), flat(batch["t"])).reshape(T, N)
    next_values = values_fn(flat(batch["next_obs"]), flat(batch["t"]) + 1).reshape(T, N)
    adv = gae(batch["reward"], values, next_values, batch["terminated"], batch["done"], gamma, lam)
    returns = adv + values

    valid = flat(batch["valid"])
    data = {k: flat(batch[k])[valid] for k in ("obs", "t", "a", "x", "mask") if k in batch}
    data.update(adv=flat(adv)[valid], returns=flat(returns)[valid], values=flat(values)[valid])
    var_ret = np.var(data["returns"])
    explained_var = float(1 - np.var(data["returns"] - data["values"]) / var_ret) if var_ret > 0 else float("nan")
    if normalize:
        data["adv"] = (data["adv"] - data["adv"].mean()) / (data["adv"].std() + 1e-8)
    return data, explained_var


def update_tensors(data: dict[str, np.ndarray], device: torch.device | str = "cpu") -> tuple[torch.Tensor, ...]:
    """The policy update's tensors ``(obs, a, x, adv, mask)`` of an :func:`advantage_batch` on ``device``
    (observations and advantages in float32, the networks' precision; ``mask``, the samples' allowed actions
    ``(B, K)``, ``None`` without masks)."""
    return (
        torch.as_tensor(np.asarray(data["obs"], dtype=np.float32), device=device),
        torch.as_tensor(data["a"], device=device),
        torch.as_tensor(data["x"], device=device),
        torch.as_tensor(data["adv"], dtype=torch.float32, device=device),
        torch.as_tensor(data["mask"], device=device) if "mask" in data else None,
    )


class LinearFeatureBaseline:
    """rllab's baseline: ridge regression of returns on ``[clip(s), s^2, t/100, (t/100)^2, (t/100)^3, 1]``."""

    def __init__(self, obs_dim: int, reg: float = 1e-5):
        self.coef = np.zeros(2 * obs_dim + 4)
        self.reg = reg

    @staticmethod
    def features(obs: np.ndarray, t: np.ndarray) -> np.ndarray:
        s = np.clip(obs, -10, 10)
        tt = (np.asarray(t, dtype=np.float64) / 100.0)[:, None]
        return np.concatenate([s, s**2, tt, tt**2, tt**3, np.ones_like(tt)], axis=1)

    def predict(self, obs: np.ndarray, t: np.ndarray) -> np.ndarray:
        return self.features(obs, t) @ self.coef

    def fit(self, obs: np.ndarray, t: np.ndarray, returns: np.ndarray) -> float:
        """Fit the coefficients to ``returns``; the mean squared error after the fit."""
        f = self.features(obs, t)
        reg = self.reg
        for _ in range(5):  # rllab raises the ridge term until the solve is finite
            coef = np.linalg.lstsq(f.T @ f + reg * np.eye(f.shape[1]), f.T @ returns, rcond=None)[0]
            if np.all(np.isfinite(coef)):
                self.coef = coef
                break
            reg *= 10
        return float(np.mean((self.predict(obs, t) - returns) ** 2))
