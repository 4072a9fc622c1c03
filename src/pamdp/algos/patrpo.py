"""PATRPO: Trust Region Policy Optimization of the hierarchical policy (Wei, Wicke & Luke 2018).

One epoch, as section "Parameterized Actions TRPO" of the paper reads:

1. Sample ``batch_size`` steps with ``(a, x) ~ pi_d(a|s) pi_c(x|s,a)`` from the batched env.
2. Advantages by GAE(``gamma``, ``gae_lambda``) from the baseline; a step cut by the time limit (or by the
   end of the epoch) bootstraps from the baseline, a true termination does not. Then refit the baseline.
3. Maximise the surrogate ``E[pi(a,x|s) / pi_old(a,x|s) * A]`` subject to ``mean KL(pi_old || pi) <= delta``,
   the joint KL estimated by ``kl_estimator`` (the chain rule splits it into the discrete KL plus the
   parameter policy's KL): natural-gradient direction by conjugate gradient on the Fisher-vector product,
   step length ``sqrt(2 delta / (d^T H d))``, backtracking line search.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
import torch

from pamdp.algos.base import Algorithm
from pamdp.algos.logger import EpisodeTracker
from pamdp.algos.settings import LAYERS, NON_NEGATIVE, POSITIVE, AlgoConfig, at_least, interval, one_of, setting
from pamdp.algos.subnormals import subnormals_flushed
from pamdp.algos.trpo import (
    FisherVectorProduct,
    GaussNewtonFVP,
    backtracking_line_search,
    conjugate_gradient,
    flat_grad,
)
from pamdp.distributions import KL_ESTIMATORS, kl_divergence
from pamdp.policies import ACTIVATIONS, HybridPolicy, ValueNetwork
from pamdp.spaces import HybridActionSpace

if TYPE_CHECKING:
    from typing_extensions import Self

__all__ = ["PATRPO", "PATRPOConfig", "LinearFeatureBaseline", "OnPolicyHybrid", "Rollout", "advantage_batch", "gae"]


FVP_METHODS = ("auto", "gauss_newton", "double_backprop")


@dataclasses.dataclass(frozen=True)
class PATRPOConfig(AlgoConfig):
    """PATRPO's settings; the defaults are the paper's preset, rllab's TRPO settings where the paper is silent,
    and two modern choices that do not change the algorithm: an MLP value baseline (rllab's linear one is
    ``baseline="linear"``) and 128 env copies stepped together (samples per epoch are ``batch_size`` either way).
    """

    num_envs: int = setting(
        128, "Copies of the env stepped together; PATRPO's samples are on-policy, so more is just faster.", at_least(1)
    )
    hidden_sizes: tuple[int, ...] = setting(
        (200, 100, 50), "Hidden layers of pi_d and pi_c (the paper's {200, 100, 50}).", LAYERS
    )
    activation: str = setting(
        "relu", "Hidden activation of the policies: relu (paper), tanh, leaky_relu or elu.", one_of(ACTIVATIONS)
    )
    init_log_std: float = setting(0.0, "Initial log-std of the parameter noise, in [-1, 1] units (rllab: std 1).")
    batch_size: int = setting(
        10_000, "Samples per epoch (one TRPO update per epoch); the paper uses 10 000.", at_least(1)
    )
    delta: float = setting(
        0.005,
        "Trust region: the bound on the mean KL(pi_old || pi). Paper: 0.005 (0.01, 0.05 in its step-size figure).",
        POSITIVE,
    )
    kl_estimator: str = setting(
        "chain_analytic",
        "KL estimator for the constraint: joint_sample, chain_sample or chain_analytic (the paper's preferred).",
        one_of(KL_ESTIMATORS),
    )
    cg_iters: int = setting(10, "Conjugate-gradient iterations for the natural-gradient direction.", at_least(1))
    fvp_subsample: float = setting(
        1.0,
        "Fraction of the batch for Fisher-vector products (0.1-0.2 is a common speed-up; the line search uses all).",
        interval(0, 1, low_open=True),
    )
    fvp: str = setting(
        "auto",
        "How Fisher-vector products are computed: gauss_newton (closed-form KL Hessian, 1.4-1.7x faster; exact "
        "for the chain estimators), double_backprop (any estimator), or auto (gauss_newton where it is exact).",
        one_of(FVP_METHODS),
    )
    cg_damping: float = setting(
        1e-5, "Damping added to the Fisher-vector product; raise it if steps are erratic.", NON_NEGATIVE
    )
    backtrack_ratio: float = setting(
        0.8, "Step shrink factor of the line search.", interval(0, 1, low_open=True, high_open=True)
    )
    max_backtracks: int = setting(
        15, "Line-search tries before the update is abandoned (parameters restored).", at_least(1)
    )
    gamma: float = setting(0.99, "Discount factor.", interval(0, 1))
    gae_lambda: float = setting(
        1.0, "GAE lambda: 1.0 is rllab's (Monte-Carlo advantages); 0.95-0.99 lowers variance.", interval(0, 1)
    )
    entropy_coef: float = setting(
        0.0,
        "Weight of the policy entropy added to the surrogate (not in the paper); keeps exploring longer.",
        NON_NEGATIVE,
    )
    normalize_advantages: bool = setting(True, "Standardise advantages within the batch.")
    baseline: str = setting(
        "mlp",
        "Baseline: mlp (a value network, the modern choice) or linear (rllab's linear-feature baseline).",
        one_of(("mlp", "linear")),
    )
    vf_hidden_sizes: tuple[int, ...] = setting((64, 64), "Hidden layers of the value network.", LAYERS)
    vf_lr: float = setting(1e-3, "Adam learning rate of the value network.", POSITIVE)
    vf_epochs: int = setting(5, "Passes over each batch when fitting the value network.", at_least(1))
    vf_batch_size: int = setting(256, "Minibatch size of the value network's fit.", at_least(1))

    def __post_init__(self):
        """The checks across settings (each setting's own runs in AlgoConfig)."""
        super().__post_init__()
        self._check(
            not (self.fvp == "gauss_newton" and self.kl_estimator == "joint_sample"),
            "fvp",
            "auto or double_backprop with kl_estimator='joint_sample' (its Hessian has no closed form)",
        )

    @classmethod
    def presets(cls) -> dict[str, Self]:
        return {
            "paper": cls(),
            "tuned": cls(
                delta=0.02,
                gae_lambda=0.97,
                batch_size=5_000,
                init_log_std=-0.5,
                entropy_coef=0.01,
                fvp_subsample=0.2,
            ),
        }


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
    """On-policy sampling of a :class:`~pamdp.policies.HybridPolicy` in a vector env (PATRPO's and PAPPO's).

    Episodes run on across epochs (an epoch's last step bootstraps from the value function), so no partial
    episode is thrown away; a new ``Rollout`` (as after loading a model) starts new episodes. Gymnasium's
    vector envs reset a finished copy on the *next* step, ignoring its action: those autoreset steps are
    marked invalid and carry no sample.
    """

    KEYS = ("obs", "a", "x", "reward", "terminated", "done", "valid", "next_obs", "t")

    def __init__(self):
        # (observation, autoreset pending, step within episode) of every env copy between epochs
        self.state: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        self.tracker: EpisodeTracker | None = None

    def collect(
        self,
        env,
        policy: HybridPolicy,
        hybrid: HybridActionSpace,
        n_samples: int,
        np_rng: np.random.Generator,
        torch_gen: torch.Generator,
    ) -> dict[str, np.ndarray]:
        """Step ``env`` with ``(a, x) ~ policy`` until ``n_samples`` valid samples; ``(T, N, ...)`` arrays of
        :attr:`KEYS` (``t``: the step within the episode; ``terminated`` and ``done`` are false when not valid).
        """
        n = env.num_envs
        if self.state is None:
            obs, _ = env.reset(seed=int(np_rng.integers(2**31 - 1)))
            self.state = (obs, np.zeros(n, dtype=bool), np.zeros(n, dtype=np.int64))
            self.tracker = EpisodeTracker(n)
        obs, prev_done, t_ep = self.state
        rows: dict[str, list] = {k: [] for k in self.KEYS}
        n_valid = 0
        while n_valid < n_samples:
            with torch.no_grad():
                a, x = policy(torch.as_tensor(np.asarray(obs, dtype=np.float32))).sample(torch_gen)
            next_obs, reward, terminated, truncated, info = env.step(hybrid.to_env_batch(a.numpy(), x.numpy()))
            valid = ~prev_done
            done = (terminated | truncated) & valid
            row = (obs, a.numpy(), x.numpy(), reward, terminated & valid, done, valid, next_obs, t_ep)
            for k, v in zip(self.KEYS, row):
                rows[k].append(np.array(v))
            self.tracker.step(np.asarray(reward, dtype=np.float64), done, valid, info)
            n_valid += int(valid.sum())
            t_ep = np.where(valid, t_ep + 1, 0)
            prev_done, obs = done, next_obs
        self.state = (obs, prev_done, t_ep)
        return {k: np.stack(v) for k, v in rows.items()}

    def epoch_stats(self, a: np.ndarray, n_actions: int) -> dict[str, float]:
        """The discrete actions' frequencies, the episodes completed since the last call, and ``steps``."""
        freq = np.bincount(a, minlength=n_actions) / len(a)
        stats = {f"train/action_freq_{k}": float(f) for k, f in enumerate(freq)}
        stats.update(self.tracker.pop())
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
    Returns the valid samples' ``obs, t, a, x``, ``adv`` (standardised within the batch when ``normalize``),
    ``returns`` (``adv + values``, the baseline's regression target) and ``values``, with the fraction of
    the returns' variance the values explain.
    """
    T, N = batch["reward"].shape
    flat = lambda arr: arr.reshape(T * N, *arr.shape[2:])  # noqa: E731
    values = values_fn(flat(batch["obs"]), flat(batch["t"])).reshape(T, N)
    next_values = values_fn(flat(batch["next_obs"]), flat(batch["t"]) + 1).reshape(T, N)
    adv = gae(batch["reward"], values, next_values, batch["terminated"], batch["done"], gamma, lam)
    returns = adv + values

    valid = flat(batch["valid"])
    data = {k: flat(batch[k])[valid] for k in ("obs", "t", "a", "x")}
    data.update(adv=flat(adv)[valid], returns=flat(returns)[valid], values=flat(values)[valid])
    var_ret = np.var(data["returns"])
    explained_var = float(1 - np.var(data["returns"] - data["values"]) / var_ret) if var_ret > 0 else float("nan")
    if normalize:
        data["adv"] = (data["adv"] - data["adv"].mean()) / (data["adv"].std() + 1e-8)
    return data, explained_var


class OnPolicyHybrid(Algorithm):
    """What PATRPO and PAPPO share: pi_d pi_c sampled by a :class:`Rollout` (``self.rollout``), advantages by
    :func:`advantage_batch` from ``self._values``, and the greedy or sampled action of ``self.policy``. Their
    configs name ``batch_size``, ``gamma``, ``gae_lambda`` and ``normalize_advantages`` alike."""

    def _act(self, obs, deterministic):
        dist = self.policy(obs)
        return dist.mode() if deterministic else dist.sample(self.torch_gen)

    def _values(self, obs: np.ndarray, t: np.ndarray) -> np.ndarray:
        """The baseline ``V(s)`` of observations at step ``t`` of their episodes: here ``self.value``'s."""
        with torch.no_grad():
            return self.value(self._obs_tensor(obs)).double().numpy()

    def _sample_epoch(self) -> tuple[dict[str, np.ndarray], float, tuple[torch.Tensor, ...]]:
        """One epoch's valid samples with their advantages (:func:`advantage_batch`'s ``data`` and explained
        variance) and the policy update's tensors ``(obs, a, x, adv)``."""
        cfg = self.config
        batch = self.rollout.collect(
            self.vec_env, self.policy, self.hybrid, cfg.batch_size, self.np_rng, self.torch_gen
        )
        data, explained_var = advantage_batch(batch, self._values, cfg.gamma, cfg.gae_lambda, cfg.normalize_advantages)
        tensors = (
            self._obs_tensor(data["obs"]),
            torch.as_tensor(data["a"]),
            torch.as_tensor(data["x"]),
            torch.as_tensor(data["adv"], dtype=torch.float32),
        )
        return data, explained_var, tensors

    def _epoch_stats(self, stats: dict[str, float], data: dict[str, np.ndarray], explained_var: float):
        """``stats`` with the explained variance, the action frequencies and the finished episodes added."""
        stats["train/explained_variance"] = explained_var
        stats.update(self.rollout.epoch_stats(data["a"], self.hybrid.n_actions))
        return stats


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
        f = self.features(obs, t)
        reg = self.reg
        for _ in range(5):  # rllab raises the ridge term until the solve is finite
            coef = np.linalg.lstsq(f.T @ f + reg * np.eye(f.shape[1]), f.T @ returns, rcond=None)[0]
            if np.all(np.isfinite(coef)):
                self.coef = coef
                break
            reg *= 10
        return float(np.mean((self.predict(obs, t) - returns) ** 2))


class PATRPO(OnPolicyHybrid):
    """Parameterized Actions TRPO. See the module docstring for the update and :class:`PATRPOConfig`."""

    config_class = PATRPOConfig
    config: PATRPOConfig

    def _build(self) -> None:
        cfg = self.config
        self.policy = HybridPolicy(self.obs_dim, self.hybrid, cfg.hidden_sizes, cfg.activation, cfg.init_log_std)
        if cfg.baseline == "mlp":
            self.value = ValueNetwork(self.obs_dim, cfg.vf_hidden_sizes)
            self.vf_optimizer = torch.optim.Adam(self.value.parameters(), lr=cfg.vf_lr)
        else:
            self.linear_baseline = LinearFeatureBaseline(self.obs_dim)
        self.rollout = Rollout()  # a loaded model starts new episodes

    def _modules(self):
        return {"policy": self.policy, **({"value": self.value} if self.config.baseline == "mlp" else {})}

    def _optimizers(self):
        return {"value": self.vf_optimizer} if self.config.baseline == "mlp" else {}

    def _extra_state(self, replay):
        if self.config.baseline == "linear":
            return {"linear_baseline": torch.as_tensor(self.linear_baseline.coef)}
        return {}

    def _load_extra_state(self, state):
        if self.config.baseline == "linear":
            self.linear_baseline.coef = state["linear_baseline"].numpy()

    # -- baseline --------------------------------------------------------------------------------
    def _values(self, obs: np.ndarray, t: np.ndarray) -> np.ndarray:
        if self.config.baseline == "linear":
            return self.linear_baseline.predict(obs, t)
        return super()._values(obs, t)

    def _fit_baseline(self, obs: np.ndarray, t: np.ndarray, returns: np.ndarray) -> float:
        cfg = self.config
        if cfg.baseline == "linear":
            return self.linear_baseline.fit(obs, t, returns)
        obs_t, ret_t = self._obs_tensor(obs), torch.as_tensor(returns, dtype=torch.float32)
        n = len(ret_t)
        for _ in range(cfg.vf_epochs):
            perm = torch.randperm(n, generator=self.torch_gen)
            for start in range(0, n, cfg.vf_batch_size):
                idx = perm[start : start + cfg.vf_batch_size]
                loss = (self.value(obs_t[idx]) - ret_t[idx]).pow(2).mean()
                self.vf_optimizer.zero_grad()
                loss.backward()
                self.vf_optimizer.step()
        with torch.no_grad():
            return float((self.value(obs_t) - ret_t).pow(2).mean())

    # -- one epoch -------------------------------------------------------------------------------
    def _run_epoch(self) -> dict[str, float]:
        data, explained_var, tensors = self._sample_epoch()
        with subnormals_flushed(self.config.flush_denormal):
            stats = self._update_policy(*tensors)
            stats["losses/value_loss"] = self._fit_baseline(data["obs"], data["t"], data["returns"])
        return self._epoch_stats(stats, data, explained_var)

    def _fisher_vector_product(self, obs, a, x, old) -> Callable[[torch.Tensor], torch.Tensor]:
        """The damped Fisher-vector product of the KL estimator, on ``fvp_subsample`` of the batch."""
        cfg = self.config
        n_fvp = max(1, int(round(cfg.fvp_subsample * len(obs))))
        if n_fvp < len(obs):
            sub = torch.randperm(len(obs), generator=self.torch_gen)[:n_fvp]
            obs, a, x, old = obs[sub], a[sub], x[sub], old[sub]
        named = [(n, p) for n, p in self.policy.named_parameters() if p.requires_grad]
        names, params = [n for n, _ in named], [p for _, p in named]
        method = cfg.fvp
        if method == "auto":
            method = "double_backprop" if cfg.kl_estimator == "joint_sample" else "gauss_newton"
        if method == "double_backprop":
            kl = kl_divergence(old, self.policy(obs), cfg.kl_estimator, a, x).mean()
            return FisherVectorProduct(kl, params, cfg.cg_damping)
        new, jvp = self.policy.linearize(obs)

        def metric(d_logits, d_means, d_log_std):
            return old.kl_hessian_product(d_logits, d_means, d_log_std, cfg.kl_estimator, a)

        outputs = (new.logits, new.means, self.policy.log_std)
        return GaussNewtonFVP(outputs, params, lambda ts: jvp(dict(zip(names, ts))), metric, cfg.cg_damping)

    def _update_policy(self, obs, a, x, adv) -> dict[str, float]:
        """One natural-gradient step with line search on the surrogate (the paper's PATRPO update)."""
        cfg = self.config
        params = [p for p in self.policy.parameters() if p.requires_grad]
        with torch.no_grad():
            old = self.policy(obs).detach()
            old_logp = old.log_prob(a, x)

        def surrogate(new) -> torch.Tensor:
            gain = (torch.exp(new.log_prob(a, x) - old_logp) * adv).mean()
            return gain + cfg.entropy_coef * new.entropy().mean() if cfg.entropy_coef else gain

        tried = []  # the line search's last policy distribution: the accepted one's, for the KL after the step

        def evaluate() -> tuple[torch.Tensor, torch.Tensor]:  # one forward pass for both of a step's figures
            tried[:] = [self.policy(obs)]
            return surrogate(tried[0]), kl_divergence(old, tried[0], cfg.kl_estimator, a, x).mean()

        objective = surrogate(self.policy(obs))
        g = flat_grad(objective, params)
        fvp = self._fisher_vector_product(obs, a, x, old)
        direction = conjugate_gradient(fvp, g, cfg.cg_iters)
        shs = float(direction @ fvp(direction))
        stats = {"train/entropy": float(old.entropy().mean()), "train/grad_norm": float(g.norm())}
        if not (np.isfinite(shs) and shs > 0):
            stats.update(
                {
                    "train/line_search_success": 0.0,
                    "train/backtracks": float(cfg.max_backtracks),
                    "losses/surrogate_improvement": 0.0,
                    "train/kl": 0.0,
                }
            )
            return stats
        full_step = np.sqrt(2.0 * cfg.delta / shs) * direction
        result = backtracking_line_search(
            params, full_step, evaluate, float(objective.detach()), cfg.delta, cfg.backtrack_ratio, cfg.max_backtracks
        )
        with torch.no_grad():
            after = tried[0] if result.success else old  # a rejected step restores the old parameters
            kl_after = float(kl_divergence(old, after, "chain_analytic").mean())
        stats.update(
            {
                "train/line_search_success": float(result.success),
                "train/backtracks": float(result.backtracks),
                "losses/surrogate_improvement": result.improvement,
                "train/kl": kl_after,
                "train/kl_estimate": result.kl,
                "train/param_std": float(self.policy.log_std.detach().exp()[self.policy.mask].mean()),
            }
        )
        return stats
