"""The class every pamdp algorithm subclasses: construction from an env, the epoch loop, predict, save and load.

The public API is Stable-Baselines3's, which users know: ``Algo(env, config)``, ``.learn(total_timesteps)``,
``.predict(obs, deterministic=True)``, ``.save(path)``, ``Algo.load(path)``. An algorithm subclasses
:class:`Algorithm` (one level of inheritance) and provides ``_build`` (networks and optimisers),
``_act`` (actions for a batch of observations), ``MODULES``/``OPTIMIZERS`` (what a checkpoint holds) and its
family's loop, :attr:`Algorithm.loop`, which runs its epochs: an off-policy algorithm's
:class:`~pamdp.algos.offpolicy.OffPolicyLoop` (the algorithm gives it ``_explore`` and ``_update``), an on-policy
one's :class:`~pamdp.algos.onpolicy.Rollout` (``_values`` and ``_learn``). Its settings are an
:class:`~pamdp.algos.settings.AlgoConfig`; checkpoints are written by :mod:`pamdp.algos.checkpoints`.
"""

from __future__ import annotations

import os
import time
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, ClassVar

import gymnasium
import numpy as np
import torch
from gymnasium import spaces
from gymnasium.vector import AutoresetMode

from pamdp._version import __version__
from pamdp.algos.checkpoints import CHECKPOINT, FORMAT, atomic_save, read_checkpoint
from pamdp.algos.settings import AlgoConfig
from pamdp.callbacks import BaseCallback, _count, _eval_figures, as_callback
from pamdp.envs.backends import describe_env, make_vector_env
from pamdp.evaluation import evaluate
from pamdp.logger import Logger
from pamdp.spaces import HybridActionSpace

if TYPE_CHECKING:
    from typing_extensions import Self  # typing.Self from Python 3.11

__all__ = ["Algorithm", "resolve_device"]


def resolve_device(name: str) -> torch.device:
    """The torch device a ``device`` setting names on this machine: ``"auto"`` is CUDA when available, else the
    CPU; CUDA asked for where there is none (or a ``cuda:N`` beyond the GPUs there are) is a ``ValueError``."""
    if name == "auto":
        return torch.device("cuda" if torch.cuda.is_available() else "cpu")
    device = torch.device(name)
    if device.type == "cuda":
        if not torch.cuda.is_available():
            raise ValueError(
                f"device = {name!r}, but CUDA is not available on this machine (torch {torch.__version__}); "
                "expected 'auto' or 'cpu' here"
            )
        if device.index is not None and device.index >= torch.cuda.device_count():
            raise ValueError(
                f"device = {name!r}, but this machine has {torch.cuda.device_count()} CUDA device(s); "
                f"expected 'cuda' or 'cuda:N' with N < {torch.cuda.device_count()}"
            )
    return device


def _shown(shapes: dict[str, list[int]]) -> str:
    """An env's shapes (:meth:`Algorithm._shapes`) in a few words, however many actions it has."""
    params = shapes["parameters"]
    return f"(observation {tuple(shapes['observation'])}, {len(params)} actions, {sum(params)} parameters)"


class Algorithm:
    """Base class of pamdp's algorithms; see the module docstring for what a subclass provides."""

    config_class: ClassVar[type[AlgoConfig]] = AlgoConfig
    loop = None
    """The family's loop, built by ``_build``; a loop with a ``state_dict`` (the replay) is saved with the model."""

    def __init__(self, env, config: AlgoConfig | dict | None = None, env_kwargs: dict | None = None):
        """``config``: the algorithm's config, or a dict of settings over the defaults (``{"delta": 0.01}``); ``None``:
        the preset ``pamdp train`` picks for the env (the env's where it has one, else the default), named in
        :attr:`preset`."""
        env_id, spec_kwargs, obs_space, act_space = describe_env(env, env_kwargs)
        self.env_id = env_id
        self.env_kwargs = {**spec_kwargs, **(env_kwargs or {})}
        self.preset: str | None = None
        """The preset a config of ``None`` took (``None`` for a config given)."""
        if config is None:
            self.preset, config = self.config_class.for_env(env_id, self.env_kwargs)
        if isinstance(config, dict):
            config = self.config_class.from_dict(config)
        if not isinstance(config, self.config_class):
            raise ValueError(
                f"{type(self).__name__} needs a {self.config_class.__name__} or a dict of its settings, "
                f"got {type(config).__name__}"
            )
        self.config = config
        self._env_arg = None if isinstance(env, str) else env
        if not (isinstance(obs_space, spaces.Box) and len(obs_space.shape) == 1):
            raise ValueError(f"observation space {obs_space!r} is not supported; expected a 1-D Box")
        self.observation_space = obs_space
        self.action_space = act_space
        self.hybrid = HybridActionSpace.from_gym(act_space)
        if self.hybrid.max_param_size == 0:
            raise ValueError(
                f"action space {act_space!r}: no action has parameters (every box has size 0), so it is a plain "
                "discrete action space; expected at least one action with continuous parameters (use a "
                "discrete-action algorithm such as DQN on the Discrete part)"
            )
        self.obs_dim = int(obs_space.shape[0])
        self.device = resolve_device(config.device)
        self.num_timesteps = 0
        self.epoch = 0
        self.num_updates = 0
        """Gradient updates made so far (each epoch's ``train/updates``), saved in checkpoints: 0 is an untrained
        model however many samples it has seen."""
        self.np_rng = np.random.default_rng(config.seed)
        # on the device, so that sampling there draws there; on the CPU the same stream as ever
        self.torch_gen = torch.Generator(device=self.device).manual_seed(config.seed)
        with torch.random.fork_rng():
            torch.manual_seed(config.seed)
            self._build()  # on the CPU: the same initial weights whatever the device
        for module in self._modules().values():
            module.to(self.device)  # in place: the optimisers built beside them keep their parameters
        self._vec_env: gymnasium.vector.VectorEnv | None = None

    # -- to be provided by each algorithm ----------------------------------------------------
    def _build(self) -> None:
        raise NotImplementedError

    def _run_epoch(self, budget: int) -> dict[str, float]:
        """Collect one epoch of samples, at most about ``budget`` (the samples left to train), and learn from them;
        returns statistics including ``"steps"`` and ``"train/updates"``. By default the family loop's epoch."""
        return self.loop.run_epoch(budget)

    def _epoch_stats(self, step: int) -> dict[str, float]:
        """The algorithm's own figures at the end of an epoch, after ``step`` samples (a schedule's value)."""
        return {}

    def _act(
        self, obs: torch.Tensor, deterministic: bool, mask: torch.Tensor | None = None
    ) -> tuple[torch.Tensor, torch.Tensor]:
        """Discrete actions ``(B,)`` and padded ``[-1, 1]`` parameters ``(B, m)`` for a batch of observations,
        among the actions ``mask`` allows (bool ``(B, K)`` on the device; ``None``: all)."""
        raise NotImplementedError

    MODULES: ClassVar[tuple[str, ...]] = ()
    """The attributes that hold the algorithm's networks, saved under their names (``None``: a network its
    settings leave out)."""
    OPTIMIZERS: ClassVar[dict[str, str]] = {}
    """The optimisers, ``{name in a checkpoint: attribute}`` (``None``: one its settings leave out)."""

    def _modules(self) -> dict[str, torch.nn.Module]:
        return {name: module for name in self.MODULES if (module := getattr(self, name, None)) is not None}

    def _optimizers(self) -> dict[str, torch.optim.Optimizer]:
        return {name: opt for name, attr in self.OPTIMIZERS.items() if (opt := getattr(self, attr, None)) is not None}

    def _extra_state(self) -> dict:
        """What a checkpoint holds besides modules, optimisers and the loop's state."""
        return {}

    def _load_extra_state(self, state: dict) -> None:
        pass

    # -- environments ------------------------------------------------------------------------
    @property
    def vec_env(self) -> gymnasium.vector.VectorEnv:
        """The batched training env, created on first use."""
        if self._vec_env is None:
            if isinstance(self._env_arg, gymnasium.vector.VectorEnv):
                self._vec_env = self._env_arg
            elif self.env_id is not None:
                self._vec_env = make_vector_env(
                    self.env_id, self.config.num_envs, self.env_kwargs, self.config.vector_mode
                )
            else:
                env = self._env_arg
                self._vec_env = gymnasium.vector.SyncVectorEnv([lambda: env])
            mode = self._vec_env.metadata.get("autoreset_mode", AutoresetMode.NEXT_STEP)
            if AutoresetMode(mode) != AutoresetMode.NEXT_STEP:
                raise ValueError(f"vector env with autoreset mode {mode!r}; pamdp expects {AutoresetMode.NEXT_STEP!r}")
        return self._vec_env

    def _from_numpy(self, array: np.ndarray) -> torch.Tensor:
        """``array`` as a tensor on the algorithm's device (the same memory on the CPU)."""
        return torch.from_numpy(array).to(self.device)

    def _obs_tensor(self, obs) -> torch.Tensor:
        return torch.as_tensor(np.asarray(obs, dtype=np.float32), device=self.device)

    # -- public API --------------------------------------------------------------------------
    def predict(self, obs, deterministic: bool = True, action_mask=None):
        """The action for one observation (the env's action tuple) or a batch (a vector env's action).

        ``action_mask``: bool ``(K,)`` for one observation, ``(N, K)`` for a batch, True where a discrete action
        is allowed (an env's ``info["action_mask"]``); the action is chosen among those. ``None``: all allowed.
        """
        expected = f"expected an array of shape ({self.obs_dim},) or (N, {self.obs_dim})"
        shown = "" if isinstance(obs, np.ndarray) else f" {obs!r:.60}"  # an array's shape says it in one line
        try:
            array = np.asarray(obs, dtype=np.float32)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"observation{shown}; {expected}") from exc
        if array.ndim not in (1, 2) or array.shape[-1] != self.obs_dim:
            raise ValueError(f"observation{shown} of shape {array.shape}; {expected}")
        if not isinstance(deterministic, (bool, np.bool_)):
            raise ValueError(f"deterministic = {deterministic!r}; expected True or False")
        obs, single = array, array.ndim == 1
        if not np.isfinite(obs).all():
            where = np.argwhere(~np.isfinite(obs))[0].tolist()
            raise ValueError(
                f"observation with a non-finite value {obs[tuple(where)]} at index {where}; expected numbers"
            )
        mask = None
        if action_mask is not None:
            k = self.hybrid.n_actions
            mask = np.asarray(action_mask)
            if mask.dtype != np.bool_ or mask.shape != obs.shape[:-1] + (k,):
                raise ValueError(
                    f"action_mask of dtype {mask.dtype} and shape {mask.shape}; expected bool of shape "
                    f"{obs.shape[:-1] + (k,)} (True where a discrete action is allowed)"
                )
            mask = torch.as_tensor(mask.reshape(-1, k), device=self.device)
        with torch.no_grad():
            a, x = self._act(self._obs_tensor(obs.reshape(-1, self.obs_dim)), deterministic, mask)
        a, x = a.cpu().numpy(), x.cpu().numpy()
        return self.hybrid.to_env(a[0], x[0]) if single else self.hybrid.to_env_batch(a, x)

    def learn(
        self,
        total_timesteps: int,
        callback: BaseCallback | list[BaseCallback] | Callable | None = None,
        progress_bar: bool = True,
        run_dir: str | os.PathLike | None = None,
        checkpoint_every: int = 1,
        eval_every: int = 0,
        eval_episodes: int = 100,
    ) -> Self:
        """Train for ``total_timesteps`` more environment steps (samples of all env copies together), in epochs.

        The last epoch is shortened to the samples left; an epoch ends at the first vector step that reaches its
        count, so a run may pass its budget by less than ``num_envs`` samples. A budget that cannot train (below
        an off-policy algorithm's ``learning_starts``, HyAR's ``warmup_steps``, or one vector step of the
        ``num_envs`` copies) is said at the start in a ``UserWarning``; :attr:`num_updates` counts what was learned.

        Args:
            callback: a :class:`~pamdp.callbacks.BaseCallback`, a list of them, or a function called after every
                epoch with the algorithm and the epoch's statistics (:mod:`pamdp.callbacks` says when each hook
                runs). ``False`` from a hook stops training after that epoch, its checkpoint written (with
                ``run_dir``) whatever ``checkpoint_every``.
            progress_bar: show a tqdm progress bar on the terminal.
            run_dir: where to write ``progress.csv``, TensorBoard logs (``tb/``) and ``checkpoint.pt``.
            checkpoint_every: epochs between checkpoints (with ``run_dir``).
            eval_every: epochs between greedy evaluations (0: none), logged as ``eval/mean_return`` (and
                ``eval/success_rate`` where the env reports ``is_success``). They play ``eval_episodes`` episodes on
                separate env copies seeded ``10_000 + seed`` and draw nothing from the training's random streams.
        """
        from tqdm.auto import tqdm

        total_timesteps = _count("total_timesteps", total_timesteps, 0)
        checkpoint_every = _count("checkpoint_every", checkpoint_every, 1)
        eval_every, eval_episodes = _count("eval_every", eval_every, 0), _count("eval_episodes", eval_episodes, 0)
        if eval_every > 0 and eval_episodes < 1:
            raise ValueError(
                f"eval_every = {eval_every!r}, eval_episodes = {eval_episodes!r}; expected eval_every >= 0 "
                "and, when it is positive, eval_episodes >= 1"
            )
        if eval_every > 0 and self.env_id is None:  # before training, not after its first epoch
            raise ValueError("eval_every needs a registered env (an env id); this model's env has none")

        callback = as_callback(callback)  # before training, not after its first epoch
        note = self.loop.budget_note(total_timesteps) if total_timesteps > 0 and self.loop is not None else None
        if note is not None:
            warnings.warn(note, UserWarning, stacklevel=2)
        torch.set_num_threads(self.config.torch_threads)
        target = self.num_timesteps + int(total_timesteps)
        logger = Logger(run_dir, resume_step=self.num_timesteps)
        start_steps, start_time = self.num_timesteps, time.perf_counter()
        bar = tqdm(
            total=target,
            initial=self.num_timesteps,
            disable=not progress_bar,
            unit="step",
            dynamic_ncols=True,
        )
        try:
            callback.init_callback(self, logger)
            callback.on_training_start()
            while self.num_timesteps < target:
                t0, cpu0 = time.perf_counter(), time.process_time()
                stats = self._run_epoch(target - self.num_timesteps)
                self.num_timesteps += int(stats.pop("steps"))
                self.num_updates += int(stats.get("train/updates", 0))
                self.epoch += 1
                elapsed = time.perf_counter() - t0
                stats.update(
                    {
                        "time/epoch": float(self.epoch),
                        "time/total_timesteps": float(self.num_timesteps),
                        "time/epoch_seconds": elapsed,
                        # CPU time of this process: unlike the wall clock, it stops while the run is suspended
                        "time/epoch_cpu_seconds": time.process_time() - cpu0,
                        "charts/SPS": (self.num_timesteps - start_steps) / (time.perf_counter() - start_time),
                    }
                )
                stop = False
                if eval_every > 0 and self.epoch % eval_every == 0:
                    result = evaluate(self, episodes=eval_episodes, seed=10_000 + self.config.seed)
                    stats.update(_eval_figures(result))
                    stop = callback.on_evaluation(result) is False
                logger.record(stats, self.num_timesteps)
                saved = run_dir is not None and self.epoch % checkpoint_every == 0
                if saved:
                    self.save(Path(run_dir) / CHECKPOINT)
                bar.update(self.num_timesteps - bar.n)
                if "charts/episodic_return" in stats:
                    bar.set_postfix(ret=f"{stats['charts/episodic_return']:.3f}", epoch=self.epoch)
                stop = (callback.on_epoch(stats) is False) or stop
                if stop:
                    if run_dir is not None and not saved:  # a stopped run resumes from where it stopped
                        self.save(Path(run_dir) / CHECKPOINT)
                    break
            callback.on_training_end()
        finally:
            bar.close()
            logger.close()
        return self

    def _shapes(self) -> dict[str, list[int]]:
        """What the networks' sizes follow from: the observation's shape and each action's parameter count."""
        return {"observation": list(self.observation_space.shape), "parameters": list(self.hybrid.param_sizes)}

    def save(self, path: str | os.PathLike, replay: bool | None = None) -> None:
        """Write weights, optimiser states, settings, counters and RNG states to one file, atomically.

        ``replay``: whether an off-policy algorithm's replay buffer goes in too (large); ``None`` follows the
        ``save_replay`` setting. A resumed run needs it to go on exactly; a model for acting does not.
        """
        replay = bool(getattr(self.config, "save_replay", False)) if replay is None else replay
        payload = {
            "format": FORMAT,
            "pamdp_version": __version__,
            "algo": type(self).__name__,
            "config": self.config.to_dict(),
            "preset": self.preset,
            "env_id": self.env_id,
            "env_kwargs": self.env_kwargs,
            "num_timesteps": self.num_timesteps,
            "epoch": self.epoch,
            "num_updates": self.num_updates,
            "shapes": self._shapes(),
            "rng": {
                "numpy": self.np_rng.bit_generator.state,
                "torch": self.torch_gen.get_state(),
                "torch_device": self.device.type,
            },
            "modules": {k: m.state_dict() for k, m in self._modules().items()},
            "optimizers": {k: o.state_dict() for k, o in self._optimizers().items()},
            "extra": self._extra_state(),
        }
        if hasattr(self.loop, "state_dict"):
            payload["extra"]["loop"] = self.loop.state_dict(replay)
        atomic_save(payload, path)

    @classmethod
    def load(cls, path: str | os.PathLike, env=None, device: str | None = None) -> Self:
        """Load a model saved by :meth:`save`, or the final model of a run directory written by ``pamdp train``.

        ``env`` (an id, env or vector env) replaces the env recorded in the file. ``device`` (a ``device``
        setting) is where the model goes; by default the saved setting where this machine has it, else the CPU,
        so a model trained on a GPU loads on a machine without one.
        """
        payload = read_checkpoint(path)
        if payload["algo"] != cls.__name__:
            raise ValueError(f"{path} holds a {payload['algo']} model, not a {cls.__name__} one")
        return cls._from_payload(payload, env, device)

    @classmethod
    def _from_payload(cls, payload: dict, env=None, device: str | None = None) -> Self:
        config = cls.config_class.from_dict(payload["config"])
        if device is None:  # the saved setting where this machine has it, else the CPU
            device = config.device
            try:
                resolve_device(device)
            except ValueError:
                device = "cpu"
        config = cls.config_class.from_dict({"device": device}, base=config)
        if env is None:
            if payload["env_id"] is None:
                raise ValueError("this model was trained on an unregistered env; pass env= to load it")
            algo = cls(payload["env_id"], config, env_kwargs=payload["env_kwargs"])
        else:  # the recorded env arguments still apply when the same env id is named again
            same_id = isinstance(env, str) and env == payload["env_id"]
            algo = cls(env, config, env_kwargs=payload["env_kwargs"] if same_id else None)
        saved, shapes = payload.get("shapes"), algo._shapes()
        if saved is not None and saved != shapes:  # before torch's "size mismatch" of every tensor
            raise ValueError(
                f"the model was trained on an env of shapes {_shown(saved)}, this env's are {_shown(shapes)}; "
                "expected an env of the model's shapes"
            )
        for name, module in algo._modules().items():
            try:
                module.load_state_dict(payload["modules"][name])
            except RuntimeError as exc:  # files written before the shapes were kept
                if "size mismatch" not in str(exc):
                    raise
                raise ValueError(
                    f"{name}'s weights do not fit this env of shapes {_shown(shapes)}; expected an env of the "
                    "model's shapes"
                ) from None
        for name, opt in algo._optimizers().items():
            opt.load_state_dict(payload["optimizers"][name])
        if hasattr(algo.loop, "load_state_dict"):
            algo.loop.load_state_dict(payload["extra"]["loop"])
        algo._load_extra_state(payload["extra"])
        algo.preset = payload.get("preset")  # files written before it was kept: None
        algo.num_timesteps = int(payload["num_timesteps"])
        algo.epoch = int(payload["epoch"])
        algo.num_updates = int(payload.get("num_updates", 0))  # files written before it was kept: 0
        algo.np_rng.bit_generator.state = payload["rng"]["numpy"]
        # a generator's state is the device's own kind (the CPU's Mersenne Twister, CUDA's Philox): a model moved
        # to another kind of device keeps the seed's fresh stream there
        if payload["rng"].get("torch_device", "cpu") == algo.device.type:
            algo.torch_gen.set_state(payload["rng"]["torch"])
        return algo
