"""Hyperparameter search with Optuna (``pamdp tune ALGO --env ID``): a search space per algorithm, and the search.

Each trial trains the algorithm with settings drawn from :data:`SEARCH_SPACES` over a base preset (the one
``pamdp train`` picks for the env, or ``preset``) for ``steps_per_trial`` samples. Its score is the final greedy
evaluation's success rate where the env reports ``is_success``, else its mean return. The greedy evaluations made
during training (about :data:`REPORTS` of them, evenly spaced) are reported to the pruner, which stops a trial that
falls behind the others at the same point of their training: the learn callback returns ``False`` and the trial is
recorded as pruned, with the samples it trained.

The study lives in a storage (a SQLite file by default) and is loaded again when it exists, so a search that was
stopped goes on where it was: its finished trials are kept and the search runs until it holds ``n_trials`` in all.
Several worker processes on one machine share the storage (Optuna's own pattern for parallel searches); a lock
file beside it makes each count-then-start atomic, so no more than ``n_trials`` are started. A trial whose process
died (killed with its search) is marked failed when the search resumes and is not counted.

The sampler is Optuna's TPE, seeded by the study's seed, the worker's index and the trials already held (a resumed
search draws new settings, not the first session's again). Every trial trains with the study's seed.
"""

from __future__ import annotations

import concurrent.futures as cf
import dataclasses
import json
import multiprocessing
import os
import socket
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import filelock
import numpy as np

from pamdp.algos import ALGORITHMS
from pamdp.experiments.runner import RunSpec

__all__ = ["SEARCH_SPACES", "Dim", "Search", "tune", "summary", "write_preset", "check_space", "REPORTS"]

REPORTS = 10
"""Greedy evaluations reported to the pruner during a trial, evenly spaced over its samples."""


@dataclasses.dataclass(frozen=True)
class Dim:
    """One setting's range in a search space: ``kind`` is ``"log"`` (log-uniform floats), ``"float"`` (uniform),
    ``"int"`` (uniform integers, log-spaced with ``log``) or ``"choice"`` (one of ``choices``)."""

    kind: str
    low: float = 0.0
    high: float = 0.0
    choices: tuple = ()
    log: bool = False
    note: str = ""

    def suggest(self, trial, name: str) -> Any:
        """The value ``trial`` draws for setting ``name`` (a tuple choice is drawn by its label, e.g. ``64x64``)."""
        if self.kind == "log":
            return trial.suggest_float(name, self.low, self.high, log=True)
        if self.kind == "float":
            return trial.suggest_float(name, self.low, self.high)
        if self.kind == "int":
            return trial.suggest_int(name, int(self.low), int(self.high), log=self.log)
        labels = {_label(c): c for c in self.choices}
        return labels[trial.suggest_categorical(name, list(labels))]

    def extremes(self) -> list:
        """The values the range's ends allow: both ends, or every choice."""
        return list(self.choices) if self.kind == "choice" else [self.low, self.high]

    def describe(self) -> str:
        if self.kind == "choice":
            return ", ".join(str(_label(c)) for c in self.choices)
        scale = "log-uniform" if self.kind == "log" or self.log else "uniform"
        kind = "integers" if self.kind == "int" else scale
        return f"{self.low:g} to {self.high:g} ({kind}{', log-spaced' if self.kind == 'int' and self.log else ''})"


def _label(value) -> str:
    """A categorical value as Optuna stores it: a tuple of layer sizes as ``64x64``, anything else as itself."""
    return "x".join(map(str, value)) if isinstance(value, tuple) else value


def log_uniform(low: float, high: float, note: str) -> Dim:
    return Dim("log", low, high, note=note)


def uniform(low: float, high: float, note: str) -> Dim:
    return Dim("float", low, high, note=note)


def integers(low: int, high: int, note: str, log: bool = False) -> Dim:
    return Dim("int", low, high, log=log, note=note)


def choice(choices, note: str) -> Dim:
    return Dim("choice", choices=tuple(choices), note=note)


_GAMMA = uniform(0.9, 0.999, "discount: shorter horizons learn faster on short episodes, longer ones see further")
_POLICY_NETS = choice(((64, 64), (128, 128), (256, 256), (200, 100, 50)), "the policy's hidden layers")
_INIT_LOG_STD = uniform(-2.0, 0.0, "initial parameter noise: Catch Point wants it low (benchmarks/catch_point.md)")
_REPLAY_BATCH = choice((32, 64, 128, 256), "transitions per gradient update")
_TAU = log_uniform(1e-3, 5e-2, "target networks' step towards the learned ones")
_CRITIC_LR = log_uniform(1e-4, 3e-3, "the critic's Adam step")
_ACTOR_LR = log_uniform(1e-6, 1e-3, "the actor's Adam step; the papers' are small")
# TD3's and SAC's usual ranges (HyAR and Hybrid SAC)
_TD3_SAC_ACTOR_LR = log_uniform(1e-4, 1e-3, "the actor's Adam step")
_TD3_SAC_CRITIC_LR = log_uniform(1e-4, 1e-3, "the critics' Adam step")
_TD3_SAC_TAU = log_uniform(1e-3, 2e-2, "target networks' step towards the learned ones")
_Q_NETS = choice(((64,), (128,), (128, 128), (256, 256)), "the Q-network's and actor's hidden layers")

SEARCH_SPACES: dict[str, dict[str, Dim]] = {
    "patrpo": {
        "delta": log_uniform(1e-3, 5e-2, "the trust region's KL bound: the step size of every update"),
        "gamma": _GAMMA,
        "gae_lambda": uniform(0.8, 1.0, "GAE: bias (low) against variance (1: Monte-Carlo returns)"),
        "batch_size": choice((2000, 5000, 10000), "samples per update: fewer, noisier steps or more, surer ones"),
        "hidden_sizes": _POLICY_NETS,
        "vf_hidden_sizes": choice(((64, 64), (128, 128), (256, 256)), "the value network's hidden layers"),
        "vf_lr": log_uniform(1e-4, 3e-3, "the value network's Adam step"),
        "vf_epochs": integers(3, 10, "passes of the value fit over each batch"),
        "init_log_std": _INIT_LOG_STD,
        "entropy_coef": uniform(0.0, 0.1, "entropy bonus of both policies, against early collapse onto one action"),
    },
    "pappo": {
        "lr": log_uniform(1e-4, 1e-3, "Adam's step for the policy and value networks"),
        "gamma": _GAMMA,
        "gae_lambda": uniform(0.8, 1.0, "GAE: bias (low) against variance (1: Monte-Carlo returns)"),
        "batch_size": choice((2048, 4096, 8192), "samples per epoch"),
        "minibatch_size": choice((64, 128, 256, 512), "samples per gradient step (at most the smallest batch)"),
        "n_epochs": integers(3, 15, "passes over each batch"),
        "clip_range": uniform(0.1, 0.3, "PPO's clip of the probability ratio"),
        "ent_coef_d": log_uniform(1e-3, 0.5, "the discrete policy's entropy bonus, against early collapse"),
        "ent_coef_c": uniform(0.0, 0.01, "the parameters' entropy bonus"),
        "hidden_sizes": _POLICY_NETS,
        "init_log_std": _INIT_LOG_STD,
        "target_kl": choice((0.0, 0.01, 0.02, 0.05), "stop an epoch's passes past this KL (0: never)"),
    },
    "pasvg0": {
        "critic_lr": _CRITIC_LR,
        "policy_lr": _ACTOR_LR,
        "batch_size": _REPLAY_BATCH,
        "gamma": _GAMMA,
        "tau": _TAU,
        "hidden_sizes": choice(((64, 64), (128, 128), (256, 256), (400, 300)), "the networks' hidden layers"),
        "temperature": log_uniform(0.1, 2.0, "Gumbel-Softmax temperature: low, nearly one-hot and noisy gradients"),
        "init_log_std": _INIT_LOG_STD,
        "explore_epsilon": uniform(0.0, 0.2, "chance of a uniformly random discrete action when acting"),
        "updates_per_step": choice((0.25, 0.5, 1.0), "gradient updates per sample (cost grows with it)"),
    },
    "paddpg": {
        "actor_lr": _ACTOR_LR,
        "critic_lr": _CRITIC_LR,
        "batch_size": _REPLAY_BATCH,
        "gamma": _GAMMA,
        "tau": _TAU,
        "hidden_sizes": choice(((64, 64), (128, 128), (256, 256), (400, 300)), "the networks' hidden layers"),
        "beta": uniform(0.0, 0.5, "weight of the Monte-Carlo return in the critic's target (Hausknecht & Stone)"),
        "epsilon_end": uniform(0.01, 0.2, "final chance of a random action"),
        "epsilon_steps": integers(10_000, 200_000, "samples over which epsilon decays", log=True),
        "ou_sigma": uniform(0.0, 0.3, "Ornstein-Uhlenbeck noise on the parameters (0: none)"),
    },
    "pdqn": {
        "q_lr": _CRITIC_LR,
        "actor_lr": log_uniform(1e-5, 1e-3, "the parameter network's Adam step"),
        "batch_size": _REPLAY_BATCH,
        "gamma": _GAMMA,
        "tau_q": log_uniform(1e-2, 0.5, "the Q-network's target step (P-DQN's is large)"),
        "tau_actor": log_uniform(1e-4, 1e-2, "the parameter network's target step"),
        "hidden_sizes": _Q_NETS,
        "epsilon_end": uniform(0.0, 0.1, "final chance of a random discrete action"),
        "epsilon_steps": integers(1_000, 100_000, "samples over which epsilon decays", log=True),
        "multi_pass": choice((False, True), "MP-DQN's one pass per action (Bester et al.)"),
    },
    "hyar": {
        "actor_lr": _TD3_SAC_ACTOR_LR,
        "critic_lr": _TD3_SAC_CRITIC_LR,
        "vae_lr": log_uniform(3e-5, 1e-3, "the action representation's Adam step"),
        "batch_size": _REPLAY_BATCH,
        "gamma": _GAMMA,
        "tau": _TD3_SAC_TAU,
        "hidden_sizes": choice(((128, 128), (256, 256)), "the actor's and critics' hidden layers"),
        "latent_dim": integers(2, 12, "size of the parameters' latent code"),
        "exploration_noise": uniform(0.05, 0.3, "Gaussian noise on the latent action when acting"),
        "policy_delay": integers(1, 3, "critic updates per actor update (TD3)"),
    },
    "hsac": {
        "actor_lr": _TD3_SAC_ACTOR_LR,
        "critic_lr": _TD3_SAC_CRITIC_LR,
        "alpha_lr": log_uniform(1e-4, 1e-3, "the temperatures' Adam step"),
        "batch_size": _REPLAY_BATCH,
        "gamma": _GAMMA,
        "tau": _TD3_SAC_TAU,
        "hidden_sizes": choice(((64, 64), (128, 128), (256, 256)), "the networks' hidden layers"),
        "init_alpha_d": log_uniform(0.01, 1.0, "the discrete policy's initial temperature"),
        "init_alpha_c": log_uniform(0.01, 1.0, "the parameters' initial temperature"),
        "target_entropy_d": uniform(0.3, 0.98, "the discrete target entropy, a fraction of the uniform's"),
        "updates_per_step": choice((0.1, 0.25, 0.5, 1.0), "gradient updates per sample (cost grows with it)"),
        "form": choice(("flat", "hierarchical"), "one policy over all parameters, or the discrete choice first"),
    },
}
"""Algorithm -> setting -> its range. Each range is one the config accepts at both ends (:func:`check_space`)."""


def check_space(space: dict[str, Dim], base) -> None:
    """Refuse a search space with a value ``base`` (a config) does not accept: each end of each range alone, and all
    the low ends and all the high ends together (a check across settings, minibatch against batch size)."""
    corners = [{name: dim.extremes()[i] for name, dim in space.items()} for i in (0, -1)]
    for values in [*({name: v} for name, dim in space.items() for v in dim.extremes()), *corners]:
        try:
            type(base).from_dict(values, base=base)
        except ValueError as exc:
            raise ValueError(f"the search space holds a value {type(base).__name__} refuses: {exc}") from None


def _epoch_size(config) -> int:
    """Samples an epoch collects: an off-policy algorithm's ``epoch_steps``, an on-policy one's ``batch_size``."""
    return int(getattr(config, "epoch_steps", None) or config.batch_size)


def _largest_epoch(space: dict[str, Dim], base) -> int:
    """The largest epoch a trial over ``base`` may have: a trial's budget must hold one to evaluate."""
    name = "epoch_steps" if hasattr(base, "epoch_steps") else "batch_size"
    dim = space.get(name)
    return int(max(dim.extremes())) if dim is not None else _epoch_size(base)


@dataclasses.dataclass(frozen=True)
class Search:
    """What a search is: the algorithm and env, the trials and their budget, where the study lives."""

    algo: str
    env: str
    n_trials: int
    steps_per_trial: int
    storage: str
    study_name: str
    seed: int = 0
    preset: str | None = None
    pruner: str = "median"
    eval_episodes: int = 100
    space: dict[str, Dim] | None = None
    """The settings searched and their ranges (``None``: the algorithm's, :data:`SEARCH_SPACES`)."""

    @property
    def dims(self) -> dict[str, Dim]:
        return SEARCH_SPACES[self.algo] if self.space is None else self.space

    def base(self):
        """The resolved :class:`~pamdp.experiments.runner.RunConfig` every trial's settings go over."""
        return RunSpec(self.algo, self.env, self.steps_per_trial, self.seed, self.preset).check()

    def check(self) -> None:
        """Refuse bad input at once, in one line naming the bad value."""
        if self.algo not in ALGORITHMS:
            raise ValueError(f"unknown algorithm {self.algo!r}; expected one of {', '.join(ALGORITHMS)}")
        if self.n_trials < 1:
            raise ValueError(f"trials = {self.n_trials!r}; expected an integer >= 1")
        if self.eval_episodes < 1:
            raise ValueError(f"eval episodes = {self.eval_episodes!r}; expected an integer >= 1")
        if self.pruner not in PRUNERS:
            raise ValueError(f"pruner = {self.pruner!r}; expected one of {', '.join(PRUNERS)}")
        base = self.base().config
        check_space(self.dims, base)
        least = getattr(base, "learning_starts", 0) + _largest_epoch(self.dims, base)
        if self.steps_per_trial < least:
            raise ValueError(
                f"steps per trial = {self.steps_per_trial:,} is too few to train and evaluate; expected at least "
                f"{least:,} (the largest epoch of {self.algo}'s search space, after any learning_starts)"
            )

    def trial_spec(self, settings: dict) -> RunSpec:
        settings = tuple(sorted(settings.items()))
        return RunSpec(self.algo, self.env, self.steps_per_trial, self.seed, self.preset, settings)


def _pruner(name: str):
    import optuna

    if name == "median":  # no pruning before three trials have finished or before a third of a trial's evaluations
        return optuna.pruners.MedianPruner(n_startup_trials=3, n_warmup_steps=REPORTS // 3)
    if name == "hyperband":
        return optuna.pruners.HyperbandPruner(min_resource=1, max_resource=REPORTS, reduction_factor=3)
    return optuna.pruners.NopPruner()


PRUNERS = ("median", "hyperband", "none")


def require_optuna():
    """Optuna, or a ``ValueError`` naming the extra that installs it."""
    try:
        import optuna
    except ModuleNotFoundError:
        raise ValueError('pamdp tune needs optuna, which is not installed: pip install "pamdp[tune]"') from None
    optuna.logging.set_verbosity(optuna.logging.WARNING)  # each trial is said in one line of ours
    return optuna


def _storage(url: str):
    import optuna

    if url.startswith("sqlite:///"):  # wait for a write another worker holds instead of failing at once
        return optuna.storages.RDBStorage(url, engine_kwargs={"connect_args": {"timeout": 60}})
    return url


def _lock_path(url: str) -> Path:
    """The lock file of a storage: beside a SQLite file, else in the temporary directory under the URL's hash."""
    if url.startswith("sqlite:///"):
        return Path(url[len("sqlite:///") :] + ".lock")
    import hashlib
    import tempfile

    return Path(tempfile.gettempdir()) / f"pamdp-tune-{hashlib.sha1(url.encode()).hexdigest()[:16]}.lock"


_RECORDED = ("algo", "env", "steps_per_trial", "seed", "preset", "eval_episodes")


def load_study(search: Search, pruner=None):
    """The study of ``search`` (created, or loaded as it stands); one recorded with other terms is refused."""
    optuna = require_optuna()
    study = optuna.create_study(
        storage=_storage(search.storage),
        study_name=search.study_name,
        direction="maximize",
        load_if_exists=True,
        pruner=pruner if pruner is not None else _pruner(search.pruner),
    )
    asked = {name: getattr(search, name) for name in _RECORDED}
    asked["preset"] = search.base().preset
    recorded = study.user_attrs
    differ = [f"{k}: {recorded[k]!r} in the study, {v!r} asked" for k, v in asked.items() if recorded.get(k, v) != v]
    if differ:
        raise ValueError(
            f"study {search.study_name!r} in {search.storage} was started with other terms ({'; '.join(differ)}); "
            "give the same ones to resume it, or another study"
        )
    for k, v in asked.items():
        study.set_user_attr(k, v)
    return study


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    return True


def _fail_dead_trials(study) -> None:
    """Mark failed the running trials whose process on this machine is gone (killed with an earlier search)."""
    from optuna.trial import TrialState

    for t in study.get_trials(deepcopy=False, states=(TrialState.RUNNING,)):
        if t.user_attrs.get("host") == socket.gethostname() and not _alive(t.user_attrs.get("pid", -1)):
            study.tell(t.number, state=TrialState.FAIL)  # without the "error" a failure of its own records


def _counted(study) -> int:
    """Trials that count towards the search's total: finished, running, or failed by an error of their own (a trial
    killed with its search is not: the resumed search runs another in its place)."""
    from optuna.trial import TrialState

    return sum(
        1
        for t in study.get_trials(deepcopy=False)
        if t.state != TrialState.WAITING and (t.state != TrialState.FAIL or "error" in t.user_attrs)
    )


def _run_trial(trial, search: Search) -> float:
    """Train one trial's settings; its final greedy score, or ``optuna.TrialPruned`` once the pruner stops it."""
    import optuna

    from pamdp.evaluation import evaluate

    settings = {name: dim.suggest(trial, name) for name, dim in search.dims.items()}
    trial.set_user_attr("settings", {k: list(v) if isinstance(v, tuple) else v for k, v in settings.items()})
    cls, _, config, _ = search.trial_spec(settings).check()
    model = cls(search.env, config)
    epochs = max(1, round(search.steps_per_trial / _epoch_size(config) / REPORTS))
    reports, pruned = [0], [False]

    def report(model, stats) -> bool:
        if "eval/mean_return" not in stats:
            return True
        reports[0] += 1
        trial.report(stats.get("eval/success_rate", stats["eval/mean_return"]), reports[0])
        trial.set_user_attr("steps", model.num_timesteps)
        # a trial past its budget is scored, whatever its last evaluation: its training is done
        pruned[0] = model.num_timesteps < search.steps_per_trial and trial.should_prune()
        return not pruned[0]

    cpu = time.process_time()
    try:
        model.learn(
            search.steps_per_trial,
            callback=report,
            progress_bar=False,
            eval_every=epochs,
            eval_episodes=search.eval_episodes,
        )
        trial.set_user_attr("steps", model.num_timesteps)
        if pruned[0]:
            raise optuna.TrialPruned(f"pruned at {model.num_timesteps:,} steps")
        result = evaluate(model, episodes=search.eval_episodes, seed=10_000 + search.seed)
    finally:
        trial.set_user_attr("cpu_seconds", time.process_time() - cpu)
        model.vec_env.close()
    objective = "success_rate" if "success_rate" in result else "mean_return"
    trial.set_user_attr("objective", objective)
    return float(result[objective])


def _work(search: Search, worker: int, pruner=None, log: Callable[[str], None] = print) -> None:
    """One worker's share of the search: start trials, one at a time, until the study holds ``n_trials``."""
    import optuna
    from optuna.trial import TrialState

    require_optuna()
    import torch

    torch.set_num_threads(1)  # workers side by side, one core each
    study = load_study(search, pruner)
    lock = filelock.FileLock(_lock_path(search.storage))
    held = len(study.get_trials(deepcopy=False))
    seed = int(np.random.SeedSequence([search.seed, worker, held]).generate_state(1)[0])
    # random settings for the first quarter of the trials (up to 10, Optuna's default), then TPE's
    study.sampler = optuna.samplers.TPESampler(seed=seed, n_startup_trials=max(2, min(10, search.n_trials // 4)))
    while True:
        with lock:
            _fail_dead_trials(study)
            if _counted(study) >= search.n_trials:
                return
            trial = study.ask()
            trial.set_user_attr("host", socket.gethostname())
            trial.set_user_attr("pid", os.getpid())
        try:
            value = _run_trial(trial, search)
        except optuna.TrialPruned as exc:
            study.tell(trial, state=TrialState.PRUNED)
            log(f"trial {trial.number}: {exc}")
        except Exception as exc:  # a failed trial is one of the search's results; the search goes on
            trial.set_user_attr("error", f"{type(exc).__name__}: {exc}")
            study.tell(trial, state=TrialState.FAIL)
            log(f"trial {trial.number}: failed: {type(exc).__name__}: {exc}")
        else:
            study.tell(trial, value)
            log(f"trial {trial.number}: {trial.user_attrs.get('objective', 'score')} {value:.4f}")


def _work_in_process(search: Search, worker: int) -> None:
    from pamdp._memory import keep_freed_memory

    keep_freed_memory()  # a spawned process: the parent's allocator settings are not inherited
    _work(search, worker, log=lambda m: print(f"worker {worker}: {m}", flush=True))


def tune(search: Search, workers: int = 1, pruner=None, log: Callable[[str], None] = print):
    """Run ``search`` (or resume it) until its study holds ``search.n_trials`` trials; returns the study.

    ``workers``: processes side by side on this machine, sharing the storage (1: in this process). ``pruner``: an
    Optuna pruner instead of ``search.pruner``'s (in this process only).
    """
    search.check()
    require_optuna()
    if workers < 1:
        raise ValueError(f"workers = {workers!r}; expected an integer >= 1")
    if search.storage.startswith("sqlite:///"):
        Path(search.storage[len("sqlite:///") :]).parent.mkdir(parents=True, exist_ok=True)
    study = load_study(search, pruner)  # the storage's tables, once, before the workers race to make them
    if workers == 1:
        _work(search, 0, pruner, log)
    else:
        ctx = multiprocessing.get_context("spawn")
        with cf.ProcessPoolExecutor(max_workers=workers, mp_context=ctx) as pool:
            for future in [pool.submit(_work_in_process, search, i) for i in range(workers)]:
                future.result()
    return study


def summary(study) -> dict:
    """The search in figures: the best trial's score and settings, the trials by state, the CPU time they took."""
    from optuna.trial import TrialState

    trials = study.get_trials(deepcopy=False)
    count = {state: sum(t.state == state for t in trials) for state in TrialState}
    complete = [t for t in trials if t.state == TrialState.COMPLETE]
    best = max(complete, key=lambda t: t.value) if complete else None
    return {
        **study.user_attrs,
        "study": study.study_name,
        "objective": best.user_attrs.get("objective") if best else None,
        "best_value": best.value if best else None,
        "best_trial": best.number if best else None,
        "best_settings": best.user_attrs["settings"] if best else None,
        "trials": len(trials),
        "complete": count[TrialState.COMPLETE],
        "pruned": count[TrialState.PRUNED],
        "failed": count[TrialState.FAIL],
        "running": count[TrialState.RUNNING],
        "cpu_seconds": round(sum(t.user_attrs.get("cpu_seconds", 0.0) for t in trials), 1),
    }


def _toml(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(map(_toml, value)) + "]"
    if isinstance(value, str):
        return json.dumps(value)  # a JSON string is a TOML basic string
    return repr(value)


def write_preset(study, out: str | os.PathLike) -> dict:
    """Write the best trial's settings as a config file ``pamdp train ALGO --config OUT`` reads (its ``preset`` the
    search's base), and the :func:`summary` as JSON beside it (``OUT`` with ``.json``); returns the summary."""
    from pamdp.atomic import atomic_write_text

    info = summary(study)
    if info["best_settings"] is None:
        raise ValueError(f"study {study.study_name!r} has no finished trial yet; nothing to write to {out}")
    out = Path(out)
    lines = [
        f"# Found by pamdp tune {info['algo']} --env {info['env']}: trial {info['best_trial']} of study "
        f"{info['study']!r}, {info['objective']} {info['best_value']:.4f} after {info['steps_per_trial']:,} steps",
        f"# pamdp train {info['algo']} --env {info['env']} --config {out.name}",
        f"preset = {_toml(info['preset'])}",
        *(f"{name} = {_toml(value)}" for name, value in info["best_settings"].items()),
    ]
    atomic_write_text(out, "\n".join(lines) + "\n")
    atomic_write_text(out.with_suffix(".json"), json.dumps({**info, "preset_file": str(out)}, indent=2) + "\n")
    return info
