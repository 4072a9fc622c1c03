"""Callbacks: code run by :meth:`Algorithm.learn <pamdp.algos.base.Algorithm.learn>` at set points of training, as in
Stable-Baselines3.

``model.learn(n, callback=...)`` takes a :class:`BaseCallback`, a list of them (a :class:`CallbackList`) or, as
before, a function ``(model, stats)``. Every algorithm runs them the same way, from the one ``learn`` loop:

1. :meth:`~BaseCallback.on_training_start` once, before the first epoch;
2. after each epoch, :meth:`~BaseCallback.on_evaluation` with the result of the greedy evaluation that ``learn``'s
   ``eval_every`` asks for (when it made one), then the epoch's figures are logged and checkpointed, then
   :meth:`~BaseCallback.on_epoch` with them;
3. :meth:`~BaseCallback.on_training_end` once, when training ends (its budget spent, or stopped).

``False`` from ``on_epoch`` or ``on_evaluation`` stops training after that epoch: ``learn`` returns normally, the
model as it is, and a run with a ``run_dir`` has its checkpoint of that epoch, so that ``Algo.load(run_dir /
"checkpoint.pt").learn(...)`` goes on from it. Ready-made: :class:`CheckpointCallback`, :class:`EvalCallback`,
:class:`StopTrainingOnRewardThreshold` and the Weights & Biases tracker :class:`WandbCallback`.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from pamdp.evaluation import evaluate

if TYPE_CHECKING:
    from pamdp.logger import Logger

Algorithm = Any
"""A model, any :class:`~pamdp.algos.base.Algorithm` (the learn loop in ``pamdp.algos.base`` imports this module,
so this one names the class without importing it)."""

__all__ = [
    "BaseCallback",
    "CallbackList",
    "FunctionCallback",
    "CheckpointCallback",
    "EvalCallback",
    "StopTrainingOnRewardThreshold",
    "WandbCallback",
    "as_callback",
]


def _count(name: str, value: object, low: int) -> int:
    """``value`` as an integer >= ``low`` (an integral float such as ``1e6`` too), else a ``ValueError`` naming it."""
    number = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))
    if not (number and math.isfinite(value) and value == int(value) and value >= low):
        raise ValueError(f"{name} = {value!r}; expected an integer >= {low}")
    return int(value)


def _eval_figures(result: dict[str, float]) -> dict[str, float]:
    """An evaluation's figures as a run logs them: ``eval/mean_return``, ``eval/mean_length`` and, where the env
    reports success, ``eval/success_rate``."""
    figures = {"eval/mean_return": result["mean_return"], "eval/mean_length": result["mean_length"]}
    if "success_rate" in result:
        figures["eval/success_rate"] = result["success_rate"]
    return figures


WANDB_MISSING = 'the Weights & Biases tracker needs wandb, which is not installed: pip install "pamdp[wandb]"'


class BaseCallback:
    """A callback: override the hooks it needs. ``learn`` sets :attr:`model` and :attr:`logger` before the first.

    ``on_epoch`` and ``on_evaluation`` return ``False`` to stop training (``None`` or ``True``: go on).
    """

    def __init__(self):
        self.model: Algorithm | None = None
        """The model being trained."""
        self.logger: Logger | None = None
        """The run's logger: :meth:`Logger.record <pamdp.logger.Logger.record>` at :attr:`num_timesteps`
        adds figures to the epoch's row of ``progress.csv``, its TensorBoard scalars and every tracker."""

    def init_callback(self, model: Algorithm, logger: Logger) -> None:
        """Called by ``learn`` before training: the model and its logger, for the hooks to use."""
        self.model, self.logger = model, logger

    @property
    def num_timesteps(self) -> int:
        """The model's environment steps so far."""
        return self.model.num_timesteps

    def on_training_start(self) -> None:
        """Before the first epoch of a ``learn`` call."""

    def on_epoch(self, stats: dict[str, float]) -> bool | None:
        """After each epoch, once its figures (``stats``, the keys of ``progress.csv``) are logged and checkpointed."""
        return None

    def on_evaluation(self, result: dict[str, float]) -> bool | None:
        """After each greedy evaluation: ``result`` is :func:`~pamdp.evaluation.evaluate`'s (``mean_return``,
        ``std_return``, ``mean_length``, ``episodes``, and ``success_rate`` where the env reports success)."""
        return None

    def on_training_end(self) -> None:
        """After the last epoch of a ``learn`` call, whether its budget was spent or a callback stopped it."""


class CallbackList(BaseCallback):
    """Several callbacks, each hook called on every one of them in the list's order; training stops when any of
    them returns ``False`` (the others are still called for that epoch)."""

    def __init__(self, callbacks: Iterable[BaseCallback | Callable]):
        super().__init__()
        self.callbacks = [as_callback(c) for c in callbacks]

    def init_callback(self, model: Algorithm, logger: Logger) -> None:
        super().init_callback(model, logger)
        for callback in self.callbacks:
            callback.init_callback(model, logger)

    def on_training_start(self) -> None:
        for callback in self.callbacks:
            callback.on_training_start()

    def on_epoch(self, stats: dict[str, float]) -> bool:
        go_on = [callback.on_epoch(stats) is not False for callback in self.callbacks]
        return all(go_on)

    def on_evaluation(self, result: dict[str, float]) -> bool:
        go_on = [callback.on_evaluation(result) is not False for callback in self.callbacks]
        return all(go_on)

    def on_training_end(self) -> None:
        for callback in self.callbacks:
            callback.on_training_end()


class FunctionCallback(BaseCallback):
    """A function ``(model, stats) -> bool | None`` called after every epoch (``learn``'s callback before this
    module): ``False`` stops training."""

    def __init__(self, function: Callable[[Algorithm, dict[str, float]], bool | None]):
        super().__init__()
        self.function = function

    def on_epoch(self, stats: dict[str, float]) -> bool | None:
        return self.function(self.model, stats)


def as_callback(callback) -> BaseCallback:
    """``learn``'s ``callback`` argument as one :class:`BaseCallback`: ``None`` (a callback that does nothing), a
    callback, a list or tuple of callbacks (a :class:`CallbackList`) or a function ``(model, stats)`` (a
    :class:`FunctionCallback`); anything else is a ``ValueError`` naming it."""
    if callback is None:
        return BaseCallback()
    if isinstance(callback, BaseCallback):
        return callback
    if isinstance(callback, (list, tuple)):
        return CallbackList(callback)
    if callable(callback):
        return FunctionCallback(callback)
    raise ValueError(
        f"callback = {callback!r:.80}; expected a function of (model, stats), a pamdp.callbacks.BaseCallback, "
        "a list of them, or None"
    )


def _path(name: str, value) -> Path:
    if not isinstance(value, (str, os.PathLike)):
        raise ValueError(f"{name} = {value!r:.80}; expected a path (a str or os.PathLike)")
    return Path(value)


def _crossed(before: int, now: int, every: int) -> bool:
    """Whether a multiple of ``every`` lies in ``(before, now]``: the epoch that ended at ``now`` passed one."""
    return now // every > before // every


class CheckpointCallback(BaseCallback):
    """Save the model every ``save_freq`` environment steps into ``save_path``, as
    ``{name_prefix}_{num_timesteps}_steps.pt`` (files :meth:`Algo.load <pamdp.algos.base.Algorithm.load>` reads).

    A save happens at the end of the first epoch that reaches each multiple of ``save_freq``, so the step in its name
    is where that epoch ended (an epoch passing two multiples saves once). ``replay``: whether an off-policy
    algorithm's replay buffer goes in (``None``: the ``save_replay`` setting, as ``learn``'s own checkpoints), which
    a file to resume from needs and one to act with does not.
    """

    def __init__(
        self, save_freq: int, save_path: str | os.PathLike, name_prefix: str = "model", replay: bool | None = None
    ):
        super().__init__()
        self.save_freq = _count("save_freq", save_freq, 1)
        self.save_path = _path("save_path", save_path)
        if not isinstance(name_prefix, str):
            raise ValueError(f"name_prefix = {name_prefix!r:.80}; expected a str")
        if replay is not None and not isinstance(replay, bool):
            raise ValueError(f"replay = {replay!r:.80}; expected True, False or None")
        self.name_prefix, self.replay = name_prefix, replay
        self.saved: list[Path] = []
        """The files written, in order."""
        self._previous = 0

    def on_training_start(self) -> None:
        self._previous = self.num_timesteps

    def on_epoch(self, stats: dict[str, float]) -> None:
        if _crossed(self._previous, self.num_timesteps, self.save_freq):
            path = self.save_path / f"{self.name_prefix}_{self.num_timesteps}_steps.pt"
            self.model.save(path, replay=self.replay)
            self.saved.append(path)
        self._previous = self.num_timesteps


class EvalCallback(BaseCallback):
    """Evaluate the greedy policy every ``eval_freq`` environment steps on env copies of its own, keep the best model.

    Each evaluation plays ``n_eval_episodes`` episodes of :func:`~pamdp.evaluation.evaluate` on ``eval_env`` (an env
    id; ``None``: the model's env, with its arguments) seeded ``seed`` (``None``: ``10_000`` + the training seed, as
    ``pamdp evaluate``): every evaluation plays the same episodes, so their scores compare, and it draws nothing from
    the training's random streams. It runs at the end of the first epoch that reaches each multiple of
    ``eval_freq``; its figures are logged in that epoch's row as ``eval/mean_return``, ``eval/mean_length`` and
    ``eval/success_rate`` (where the env reports success), the keys of ``learn``'s own ``eval_every`` (at an epoch
    with both, the row keeps this callback's).

    A score (``metric``: ``"mean_return"`` or ``"success_rate"``) above every earlier one of this callback saves the
    model (for acting, without its replay buffer) to ``best_model_save_path/best_model.pt`` when a path is given.
    ``callback_on_new_best`` then gets :meth:`~BaseCallback.on_evaluation` with the result, and
    ``callback_after_eval`` gets it after every evaluation; ``False`` from either stops training (a
    :class:`StopTrainingOnRewardThreshold` as ``callback_on_new_best`` stops at the first score over its threshold).
    """

    METRICS = ("mean_return", "success_rate")

    def __init__(
        self,
        eval_env: str | None = None,
        eval_freq: int = 10_000,
        n_eval_episodes: int = 10,
        best_model_save_path: str | os.PathLike | None = None,
        metric: str = "mean_return",
        eval_env_kwargs: dict | None = None,
        seed: int | None = None,
        deterministic: bool = True,
        callback_on_new_best: BaseCallback | None = None,
        callback_after_eval: BaseCallback | None = None,
    ):
        super().__init__()
        from pamdp.envs.backends import check_env_kwargs

        if eval_env is not None and not isinstance(eval_env, str):
            raise ValueError(f"eval_env = {eval_env!r:.80}; expected a registered env id (a str) or None")
        if eval_env_kwargs is not None and not isinstance(eval_env_kwargs, dict):
            raise ValueError(f"eval_env_kwargs = {eval_env_kwargs!r:.80}; expected a dict of env arguments or None")
        if eval_env is not None:
            check_env_kwargs(eval_env, eval_env_kwargs or {})
        if metric not in self.METRICS:
            raise ValueError(f"metric = {metric!r}; expected one of {', '.join(map(repr, self.METRICS))}")
        if not isinstance(deterministic, bool):
            raise ValueError(f"deterministic = {deterministic!r}; expected True or False")
        self.eval_env, self.eval_env_kwargs = eval_env, eval_env_kwargs
        self.eval_freq = _count("eval_freq", eval_freq, 1)
        self.n_eval_episodes = _count("n_eval_episodes", n_eval_episodes, 1)
        self.seed = None if seed is None else _count("seed", seed, 0)
        self.best_model_save_path = None
        if best_model_save_path is not None:
            self.best_model_save_path = _path("best_model_save_path", best_model_save_path)
        self.metric, self.deterministic = metric, deterministic
        self.callback_on_new_best = _callback_object("callback_on_new_best", callback_on_new_best)
        self.callback_after_eval = _callback_object("callback_after_eval", callback_after_eval)
        self.evaluations: list[tuple[int, dict[str, float]]] = []
        """``(num_timesteps, result)`` of every evaluation, in order."""
        self.best_score = -math.inf
        """The best score so far (``-inf`` before the first evaluation)."""
        self._previous = 0

    @property
    def best_model_path(self) -> Path | None:
        """Where the best model is saved (``None``: nowhere)."""
        return None if self.best_model_save_path is None else self.best_model_save_path / "best_model.pt"

    def init_callback(self, model: Algorithm, logger: Logger) -> None:
        super().init_callback(model, logger)
        for child in (self.callback_on_new_best, self.callback_after_eval):
            if child is not None:
                child.init_callback(model, logger)

    def on_training_start(self) -> None:
        self._previous = self.num_timesteps

    def on_epoch(self, stats: dict[str, float]) -> bool:
        crossed = _crossed(self._previous, self.num_timesteps, self.eval_freq)
        self._previous = self.num_timesteps
        return self.evaluate() is not False if crossed else True

    def evaluate(self) -> bool:
        """Evaluate now, log and keep the result, save a new best; ``False`` where a child callback stops training."""
        model = self.model
        if self.eval_env is None:
            env_id, env_kwargs = model.env_id, model.env_kwargs
        else:
            env_id, env_kwargs = self.eval_env, self.eval_env_kwargs or {}
        if env_id is None:
            raise ValueError("EvalCallback needs an env id: this model's env has none; pass eval_env=")
        seed = 10_000 + model.config.seed if self.seed is None else self.seed
        result = evaluate(model, self.n_eval_episodes, seed, self.deterministic, env_id=env_id, env_kwargs=env_kwargs)
        if self.metric not in result:
            raise ValueError(
                f"metric = {self.metric!r}, but env {env_id!r} reports no success (info['is_success']); "
                "expected metric = 'mean_return'"
            )
        self.evaluations.append((self.num_timesteps, result))
        self.logger.record(_eval_figures(result), self.num_timesteps)
        go_on = True
        score = result[self.metric]
        if score > self.best_score:
            self.best_score = score
            if self.best_model_path is not None:
                model.save(self.best_model_path, replay=False)
            if self.callback_on_new_best is not None:
                go_on = self.callback_on_new_best.on_evaluation(result) is not False
        if self.callback_after_eval is not None:
            go_on = (self.callback_after_eval.on_evaluation(result) is not False) and go_on
        return go_on


def _callback_object(name: str, callback) -> BaseCallback | None:
    if callback is not None and not isinstance(callback, BaseCallback):
        raise ValueError(f"{name} = {callback!r:.80}; expected a pamdp.callbacks.BaseCallback or None")
    return callback


class StopTrainingOnRewardThreshold(BaseCallback):
    """Stop training once a figure reaches ``reward_threshold``.

    ``key`` names the figure, in whatever this callback is given: an evaluation's result (``"mean_return"``,
    ``"success_rate"``: as :class:`EvalCallback`'s ``callback_on_new_best``, or with ``learn``'s ``eval_every``) or
    an epoch's figures (``"charts/episodic_return"``, ``"eval/mean_return"``: in ``learn``'s callbacks). Training
    stops after the first epoch at which it is ``>= reward_threshold``; a dict without the key changes nothing.
    """

    def __init__(self, reward_threshold: float, key: str = "mean_return"):
        super().__init__()
        number = isinstance(reward_threshold, (int, float, np.integer, np.floating))
        if not number or isinstance(reward_threshold, bool) or not math.isfinite(reward_threshold):
            raise ValueError(f"reward_threshold = {reward_threshold!r:.80}; expected a finite number")
        if not isinstance(key, str):
            raise ValueError(f"key = {key!r:.80}; expected a str such as 'mean_return' or 'charts/episodic_return'")
        self.reward_threshold, self.key = float(reward_threshold), key

    def _check(self, figures: dict[str, Any]) -> bool:
        value = figures.get(self.key)
        return value is None or value < self.reward_threshold

    def on_epoch(self, stats: dict[str, float]) -> bool:
        return self._check(stats)

    def on_evaluation(self, result: dict[str, float]) -> bool:
        return self._check(result)


class WandbCallback(BaseCallback):
    """Log a run to Weights & Biases beside TensorBoard: the figures of ``progress.csv`` (all of them, as the
    run's logger records them), the run's config and, with :meth:`finish`, a summary.

    The run starts with the first ``learn`` call (``wandb.init(project=..., config=...)``), its config the model's:
    ``algo``, ``env_id``, ``env_kwargs``, ``seed``, ``preset`` and ``settings`` (every setting), and ``config``'s
    entries over them. Later ``learn`` calls log to the same run; :meth:`finish` ends it, with the figures of a final
    evaluation as its summary where given. ``init_kwargs`` go to ``wandb.init`` (``dir``, ``mode``, ``tags``, ...);
    ``WANDB_MODE=offline`` logs to local files only. Needs ``pip install "pamdp[wandb]"``: without wandb,
    constructing one is an ``ImportError`` saying so.
    """

    def __init__(
        self, project: str | None = "pamdp", name: str | None = None, config: dict | None = None, **init_kwargs
    ):
        super().__init__()
        try:
            import wandb
        except ModuleNotFoundError as exc:
            raise ImportError(WANDB_MISSING) from exc
        if config is not None and not isinstance(config, dict):
            raise ValueError(f"config = {config!r:.80}; expected a dict or None")
        self._wandb = wandb
        self.project, self.name, self.config, self.init_kwargs = project, name, dict(config or {}), init_kwargs
        self.run = None
        """The wandb run, from the first ``learn`` call on."""

    def run_config(self) -> dict[str, Any]:
        """What the run's config records: the model's algorithm, env, seed, preset and settings, then ``config``."""
        model = self.model
        return {
            "algo": type(model).__name__,
            "env_id": model.env_id,
            "env_kwargs": model.env_kwargs,
            "seed": model.config.seed,
            "preset": model.preset,
            "settings": model.config.to_dict(),
            **self.config,
        }

    def on_training_start(self) -> None:
        if self.run is None:
            try:
                self.run = self._wandb.init(
                    project=self.project, name=self.name, config=self.run_config(), **self.init_kwargs
                )
            except (self._wandb.errors.Error, ValueError) as exc:  # not logged in, a bad setting: in one line
                reason = " ".join(str(exc).split())
                raise ValueError(
                    f"wandb.init failed: {reason}; expected a W&B login (wandb login, WANDB_API_KEY) or "
                    "WANDB_MODE=offline"
                ) from None
        self.logger.sinks.append(self._log)

    def _log(self, stats: dict[str, float], step: int) -> None:
        self.run.log(dict(stats), step=step)  # at the step just logged, wandb adds to its row

    def finish(self, summary: dict[str, Any] | None = None) -> None:
        """End the run (nothing where none started), with ``summary`` (a final evaluation's result: its numbers) in
        the run's summary under ``final/``."""
        if self.run is None:
            return
        if summary:
            figures = {f"final/{k}": v for k, v in summary.items() if isinstance(v, (int, float))}
            self.run.summary.update(figures)
        self.run.finish()
        self.run = None
