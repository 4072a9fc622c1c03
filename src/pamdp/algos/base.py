"""What every pamdp algorithm shares: settings, environments, the epoch loop, logging and checkpoints.

The public API is Stable-Baselines3's, which users know: ``Algo(env, config)``, ``.learn(total_timesteps)``,
``.predict(obs, deterministic=True)``, ``.save(path)``, ``Algo.load(path)``. An algorithm subclasses
:class:`Algorithm` (one level of inheritance) and provides ``_build`` (networks and optimisers),
``_run_epoch`` (collect and learn from one epoch of samples), ``_act`` (actions for a batch of
observations) and ``_modules``/``_optimizers`` (what a checkpoint holds).

Checkpoints are one file written atomically (a temporary file, fsync, rename) holding tensors and plain
data only; they are read back with ``torch.load(weights_only=True)``, so loading never executes code.
"""

from __future__ import annotations

import contextlib
import csv
import dataclasses
import importlib
import importlib.util
import math
import os
import tempfile
import time
import types
import typing
from collections.abc import Callable
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any, ClassVar

import gymnasium
import numpy as np
import torch
from gymnasium import spaces
from gymnasium.vector import AutoresetMode

import pamdp
from pamdp.algos import MODULE_OF
from pamdp.spaces import HybridActionSpace

if TYPE_CHECKING:
    from typing_extensions import Self  # typing.Self from Python 3.11

__all__ = [
    "AlgoConfig",
    "Algorithm",
    "setting",
    "Check",
    "at_least",
    "interval",
    "one_of",
    "POSITIVE",
    "NON_NEGATIVE",
    "LAYERS",
    "load_model",
    "make_vector_env",
    "EpisodeTracker",
    "Logger",
]

FINAL_MODEL = "final_model.pt"
CHECKPOINT = "checkpoint.pt"
_FORMAT = "pamdp-checkpoint"


@dataclasses.dataclass(frozen=True)
class Check:
    """A setting's valid values: ``ok(value)`` says whether a value is one, ``expected`` says which in words
    (the error message's "expected ..." and the settings tables' "valid" column)."""

    ok: Callable[[Any], bool]
    expected: str


def at_least(n: int) -> Check:
    return Check(lambda v: v >= n, f"an integer >= {n}")


def interval(low: float, high: float, low_open: bool = False, high_open: bool = False) -> Check:
    """Numbers between ``low`` and ``high``, each end included unless it is open."""
    text = f"a number in {'(' if low_open else '['}{low}, {high}{')' if high_open else ']'}"
    return Check(
        lambda v: (low < v if low_open else low <= v) and (v < high if high_open else v <= high),
        text,
    )


def one_of(choices) -> Check:
    choices = tuple(choices)
    return Check(lambda v: v in choices, "one of " + ", ".join(repr(c) for c in choices))


POSITIVE = Check(lambda v: v > 0, "a positive number")
NON_NEGATIVE = Check(lambda v: v >= 0, "a non-negative number")
LAYERS = Check(lambda v: len(v) > 0 and all(h > 0 for h in v), "one or more positive layer sizes")


def setting(default: Any, help: str, check: Check | None = None) -> Any:
    """A documented dataclass field: the ``help`` text is the field's documentation and its CLI help; a
    config rejects a value that fails ``check`` with an error naming the value and ``check.expected``."""
    if isinstance(default, (list, dict)):
        raise TypeError("use tuples for sequence settings, so that configs stay immutable")
    return dataclasses.field(default=default, metadata={"help": help, "check": check})


@dataclasses.dataclass(frozen=True)
class AlgoConfig:
    """Settings every algorithm has. Subclasses add their own and a ``presets()`` table."""

    seed: int = setting(0, "Seeds the networks' initialisation, action sampling and the environments.", at_least(0))
    num_envs: int = setting(
        16, "Copies of the environment stepped together (batched when the env has a vector version).", at_least(1)
    )
    torch_threads: int = setting(
        1, "Torch intra-op threads; 1 is fastest for these small networks on a laptop CPU.", at_least(1)
    )
    flush_denormal: bool = setting(
        True,
        "Flush subnormal floats to zero (x86 FTZ/DAZ) in the CPU arithmetic of the gradient updates, never while "
        "the env steps: Adam's decaying moments can reach the subnormal range, where each operation is many times "
        "slower (PASVG(0) trains 1.6x to 1.7x faster with it, benchmarks/denormals.md).",
    )
    vector_mode: str = setting(
        "auto",
        "How env copies are stepped: batched, sync (scalar copies in turn) or auto (batched from 2 copies with Numba "
        "installed, from 48 without).",
        one_of(("auto", "batched", "sync")),
    )

    def __post_init__(self):
        """Each setting against its ``check`` (in declaration order); subclasses add checks across settings."""
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if isinstance(value, float) and not math.isfinite(value):
                raise ValueError(f"{type(self).__name__}.{f.name} = {value!r}; expected a finite number")
            check = self.check_of(f.name)
            if check is not None:
                self._check(check.ok(value), f.name, check.expected)

    @classmethod
    def check_of(cls, name: str) -> Check | None:
        """The check of setting ``name``: its own, or, for a setting a subclass declares again (a new default)
        without one, the nearest base class's."""
        for klass in cls.__mro__:
            f = getattr(klass, "__dataclass_fields__", {}).get(name)
            if f is not None and f.metadata.get("check") is not None:
                return f.metadata["check"]
        return None

    def _check(self, ok: bool, name: str, expected: str) -> None:
        if not ok:
            raise ValueError(f"{type(self).__name__}.{name} = {getattr(self, name)!r}; expected {expected}")

    @classmethod
    def presets(cls) -> dict[str, Self]:
        """Named settings, e.g. ``"paper"``; the first one is the default."""
        return {"default": cls()}

    @classmethod
    def preset(cls, name: str) -> Self:
        table = cls.presets()
        if name not in table:
            raise ValueError(f"unknown preset {name!r} for {cls.__name__}; expected one of {', '.join(table)}")
        return table[name]

    def to_dict(self) -> dict[str, Any]:
        return {
            f.name: (list(v) if isinstance(v := getattr(self, f.name), tuple) else v) for f in dataclasses.fields(self)
        }

    @classmethod
    def field_types(cls) -> dict[str, Any]:
        return typing.get_type_hints(cls)

    @classmethod
    def from_dict(cls, values: dict[str, Any], base: Self | None = None) -> Self:
        """Settings from plain data (a config file, a checkpoint), over ``base`` (default: the defaults).

        Unknown names and values of the wrong type raise a ``ValueError`` naming them.
        """
        base = base if base is not None else cls()
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(values) - names)
        if unknown:
            raise ValueError(f"unknown {cls.__name__} setting(s) {unknown}; expected some of {sorted(names)}")
        hints = cls.field_types()
        return dataclasses.replace(base, **{k: _coerce(k, v, hints[k]) for k, v in values.items()})


def _coerce(name: str, value: Any, hint: Any) -> Any:
    """Check a plain value against a field's type hint, converting lists to tuples and ints to floats."""
    origin = typing.get_origin(hint)
    if origin in (typing.Union, types.UnionType):
        options = typing.get_args(hint)
        if value is None and type(None) in options:
            return None
        hint = next(t for t in options if t is not type(None))
        origin = typing.get_origin(hint)
    if origin is tuple:
        if not isinstance(value, (list, tuple)):
            raise ValueError(f"setting {name!r} = {value!r}; expected a list")
        (item,) = {a for a in typing.get_args(hint) if a is not Ellipsis}
        return tuple(_coerce(name, v, item) for v in value)
    if hint is float and isinstance(value, (int, float)) and not isinstance(value, bool):
        return float(value)
    if hint in (int, str, bool) and type(value) is not hint:
        raise ValueError(f"setting {name!r} = {value!r}; expected {hint.__name__}")
    return value


# -- environments -----------------------------------------------------------------------------------
# A batched env on its NumPy backend pays NumPy's per-call cost on every inner loop iteration, whatever its
# number of copies; below about this many copies, scalar envs stepped one after the other are faster (measured
# on Platform: 8 copies run ~600 steps/s batched, ~3 500 as scalar copies; the two meet near 48; HFO's near 32).
AUTO_BATCH_MIN = 48
# With Numba (pamdp[fast]) the batched envs run compiled kernels and win from two copies on (2026-11-29, one
# core: Platform 13 000 against 4 000 steps/s at 2 copies, 73 000 against 6 300 at 8; HFO 55 000 against
# 21 000 at 2, 196 000 against 29 000 at 8); a single HFO copy is faster scalar (34 000 against 16 000).
AUTO_BATCH_MIN_NUMBA = 2


@contextlib.contextmanager
def subnormals_flushed(enabled: bool = True):
    """Flush subnormal floats to zero (x86 FTZ/DAZ, ``torch.set_flush_denormal``) in this thread's CPU arithmetic
    inside the block, and restore IEEE subnormals after it. Yields whether flushing is on: ``False`` when not
    ``enabled`` or where the CPU cannot flush."""
    flush = enabled and torch.set_flush_denormal(True)
    try:
        yield flush
    finally:
        if flush:
            torch.set_flush_denormal(False)


def auto_batch_min() -> int:
    """The number of copies from which ``"auto"`` steps an env's batched version."""
    return AUTO_BATCH_MIN_NUMBA if importlib.util.find_spec("numba") is not None else AUTO_BATCH_MIN


def env_spec(env_id: str) -> gymnasium.envs.registration.EnvSpec:
    """Gymnasium's spec of a registered env id; ``"module:Name-v0"`` first imports ``module`` (which registers
    the env), as ``gymnasium.make`` does, so that ``pamdp train --env mypackage:MyEnv-v0`` works.

    An id that is not registered, or a module that does not import, is a ``ValueError`` saying so.
    """
    module, _, name = env_id.rpartition(":")
    if module:
        try:
            importlib.import_module(module)
        except ModuleNotFoundError as exc:
            raise ValueError(
                f"env {env_id!r}: cannot import module {module!r} ({exc}); expected an importable module "
                f"that registers {name!r} with gymnasium.register"
            ) from exc
    try:
        return gymnasium.spec(name)
    except gymnasium.error.Error as exc:
        raise ValueError(
            f"env {env_id!r} is not registered ({exc}); expected a Gymnasium id such as pamdp/Platform-v0, "
            "or module:EnvId-v0 to import the module that registers it"
        ) from exc


def make_vector_env(
    env_id: str, num_envs: int, env_kwargs: dict | None = None, mode: str = "auto"
) -> gymnasium.vector.VectorEnv:
    """``num_envs`` copies of the env: ``"batched"`` (its ``vector_entry_point``), ``"sync"`` (scalar copies
    stepped in turn) or ``"auto"`` (batched from :func:`auto_batch_min` copies on, when the env has a batched
    version).
    """
    if mode not in ("auto", "batched", "sync"):
        raise ValueError(f"vector env mode {mode!r}; expected 'auto', 'batched' or 'sync'")
    spec = env_spec(env_id)
    batched = spec.vector_entry_point is not None and (
        mode == "batched" or (mode == "auto" and num_envs >= auto_batch_min())
    )
    if mode == "batched" and spec.vector_entry_point is None:
        raise ValueError(f"{env_id} has no batched version (no vector_entry_point); use 'sync'")
    vectorization_mode = "vector_entry_point" if batched else "sync"
    return gymnasium.make_vec(env_id, num_envs=num_envs, vectorization_mode=vectorization_mode, **(env_kwargs or {}))


def _describe_env(env, env_kwargs: dict | None = None) -> tuple[str | None, dict, spaces.Space, spaces.Space]:
    """``(env_id, env_kwargs, single observation space, single action space)`` of what a user passed."""
    if isinstance(env, str):
        spec = env_spec(env)
        probe = gymnasium.make(env, **(env_kwargs or {}))
        obs_space, act_space = probe.observation_space, probe.action_space
        probe.close()
        # "module:Name-v0" keeps its module, so that a loaded model imports it again to make its env
        return (env if ":" in env else spec.id), {}, obs_space, act_space
    if isinstance(env, gymnasium.vector.VectorEnv):
        spec = env.spec
        return (
            (spec.id if spec else None),
            dict(spec.kwargs if spec else {}),
            env.single_observation_space,
            env.single_action_space,
        )
    if isinstance(env, gymnasium.Env):
        spec = env.spec
        return (
            (spec.id if spec else None),
            dict(spec.kwargs if spec else {}),
            env.observation_space,
            env.action_space,
        )
    raise ValueError(f"env must be a registered env id, a gymnasium.Env or a VectorEnv; got {env!r}")


class EpisodeTracker:
    """Running return and length per env copy; completed episodes are kept until :meth:`pop`.

    Where the env reports an episode's outcome as ``info["status"]`` (Half Field Offense: ``"GOAL"``,
    ``"OUT_OF_BOUNDS"``, ...), the goal rate and the mean length of scoring episodes are kept too, the training
    counterparts of :func:`pamdp.evaluation.evaluate`'s ``goal_rate`` and ``mean_steps_to_goal``, logged as
    ``charts/goal_rate`` and ``charts/steps_to_goal`` (over the episodes whose end came with a status).
    """

    def __init__(self, num_envs: int):
        self.returns = np.zeros(num_envs)
        self.lengths = np.zeros(num_envs, dtype=np.int64)
        self.done_returns: list[float] = []
        self.done_lengths: list[int] = []
        self.done_goals: list[bool | None] = []  # per ended episode; None where the env reported no status

    def reset(self) -> None:
        self.returns[:] = 0.0
        self.lengths[:] = 0

    def step(self, rewards: np.ndarray, dones: np.ndarray, valid: np.ndarray, info: dict | None = None) -> None:
        """Add one vector step; ``valid`` is false for the autoreset steps of Gymnasium's vector envs."""
        self.returns += np.where(valid, rewards, 0.0)
        self.lengths += valid
        ended = dones & valid
        self.done_returns += self.returns[ended].tolist()
        self.done_lengths += self.lengths[ended].tolist()
        if ended.any():
            if info is not None and "status" in info:
                self.done_goals += [str(s) == "GOAL" for s in np.asarray(info["status"], dtype=object)[ended]]
            else:
                self.done_goals += [None] * int(ended.sum())
        self.returns[ended] = 0.0
        self.lengths[ended] = 0

    def pop(self) -> dict[str, float]:
        """Statistics of the episodes completed since the last call (empty if none)."""
        if not self.done_returns:
            return {}
        stats = {
            "charts/episodic_return": float(np.mean(self.done_returns)),
            "charts/episodic_length": float(np.mean(self.done_lengths)),
            "charts/episodes": float(len(self.done_returns)),
        }
        known = [(n, g) for n, g in zip(self.done_lengths, self.done_goals) if g is not None]
        if known:
            stats["charts/goal_rate"] = float(np.mean([g for _, g in known]))
            scoring = [n for n, g in known if g]
            if scoring:
                stats["charts/steps_to_goal"] = float(np.mean(scoring))
        self.done_returns, self.done_lengths, self.done_goals = [], [], []
        return stats


# -- logging ------------------------------------------------------------------------------------------
class Logger:
    """One CSV row and a set of TensorBoard scalars per epoch, in ``run_dir/progress.csv`` and ``run_dir/tb``.

    On resume (``resume_step > 0``) rows logged after the checkpoint being resumed are dropped, so that a
    killed and restarted run leaves one clean log.
    """

    def __init__(self, run_dir: str | os.PathLike, resume_step: int = 0):
        from torch.utils.tensorboard import SummaryWriter

        self.run_dir = Path(run_dir)
        self.run_dir.mkdir(parents=True, exist_ok=True)
        self.csv_path = self.run_dir / "progress.csv"
        self.rows: list[dict[str, Any]] = []
        if self.csv_path.exists():
            with open(self.csv_path, newline="") as f:
                self.rows = [r for r in csv.DictReader(f) if float(r["time/total_timesteps"]) <= resume_step]
        if resume_step == 0:
            self.rows = []
        self.writer = SummaryWriter(str(self.run_dir / "tb"), purge_step=resume_step or None)

    def record(self, stats: dict[str, float], step: int) -> None:
        for key, value in stats.items():
            self.writer.add_scalar(key, value, step)
        self.writer.flush()
        self.rows.append(stats)
        columns: list[str] = []
        for row in self.rows:
            columns += [k for k in row if k not in columns]
        tmp = self.csv_path.with_suffix(".csv.tmp")
        with open(tmp, "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=columns)
            writer.writeheader()
            writer.writerows(self.rows)
        os.replace(tmp, self.csv_path)

    def close(self) -> None:
        self.writer.close()


# -- checkpoints --------------------------------------------------------------------------------------
def _umask() -> int:
    mask = os.umask(0)  # the only way to read it is to set it
    os.umask(mask)
    return mask


def _atomic_write(path: str | os.PathLike, write: Callable[[IO[bytes]], object], example: str) -> None:
    """``write`` into a temporary file beside ``path``, fsync, then rename it over ``path``: a reader (or a run
    killed mid-write) sees the old file or the new one, never a part."""
    path = Path(path)
    if path.is_dir():
        raise ValueError(f"cannot save to {path}: it is a directory; expected a file path such as {path / example}")
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp's file is private (0600); the file gets what open() would give
        with os.fdopen(fd, "wb") as f:
            write(f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


def atomic_save(payload: dict, path: str | os.PathLike) -> None:
    """``torch.save`` to a temporary file beside ``path``, fsync, then rename over it."""
    _atomic_write(path, lambda f: torch.save(payload, f), "model.pt")


def atomic_write_text(path: str | os.PathLike, text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically, as :func:`atomic_save` does a checkpoint."""
    _atomic_write(path, lambda f: f.write(text.encode()), "run.json")


def _alone() -> float:
    return 1.0


def _own_storage(obj):
    """``obj`` with every tensor that views a larger storage copied out: ``torch.save`` writes a view's whole
    storage, which for a stacked seed's weights (pamdp.algos.stacking) holds every seed's."""
    if isinstance(obj, torch.Tensor):
        if obj.untyped_storage().nbytes() != obj.nbytes or not obj.is_contiguous():
            return obj.clone(memory_format=torch.contiguous_format)
        return obj
    if isinstance(obj, dict):
        return {k: _own_storage(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return type(obj)(_own_storage(v) for v in obj)
    return obj


def _resolve_model_path(path: str | os.PathLike) -> Path:
    path = Path(path)
    if path.is_dir():
        for name in (FINAL_MODEL, CHECKPOINT):
            if (path / name).is_file():
                return path / name
        raise FileNotFoundError(f"run directory {path} holds neither {FINAL_MODEL} nor {CHECKPOINT}")
    if not path.is_file():
        raise FileNotFoundError(f"no pamdp model at {path}: expected a checkpoint file or a run directory")
    return path


def read_checkpoint(path: str | os.PathLike) -> dict:
    """Read a checkpoint with ``weights_only=True``; a file that is not one raises a clear ``ValueError``."""
    path = _resolve_model_path(path)
    try:
        payload = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as exc:
        raise ValueError(f"{path} is not a readable pamdp checkpoint ({type(exc).__name__}: {exc})") from exc
    if not isinstance(payload, dict) or payload.get("format") != _FORMAT:
        raise ValueError(f"{path} is not a pamdp checkpoint (no '{_FORMAT}' header)")
    return payload


_REGISTRY: dict[str, type[Algorithm]] = {}


def load_model(path: str | os.PathLike, env=None) -> Algorithm:
    """Load any pamdp model (file or run directory), whichever algorithm wrote it."""
    payload = read_checkpoint(path)
    name = payload["algo"]
    if name not in _REGISTRY:
        if name in MODULE_OF:
            __import__(MODULE_OF[name])
    if name not in _REGISTRY:
        raise ValueError(f"{path} was written by unknown algorithm {name!r}")
    return _REGISTRY[name]._from_payload(payload, env)


class Algorithm:
    """Base class of pamdp's algorithms; see the module docstring for what a subclass provides."""

    config_class: ClassVar[type[AlgoConfig]] = AlgoConfig

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        _REGISTRY[cls.__name__] = cls

    def __init__(self, env, config: AlgoConfig | dict | None = None, env_kwargs: dict | None = None):
        """``config``: the algorithm's config, or a dict of settings over the defaults (``{"delta": 0.01}``)."""
        config = self.config_class() if config is None else config
        if isinstance(config, dict):
            config = self.config_class.from_dict(config)
        if not isinstance(config, self.config_class):
            raise ValueError(
                f"{type(self).__name__} needs a {self.config_class.__name__} or a dict of its settings, "
                f"got {type(config).__name__}"
            )
        self.config = config
        env_id, spec_kwargs, obs_space, act_space = _describe_env(env, env_kwargs)
        self.env_id = env_id
        self.env_kwargs = {**spec_kwargs, **(env_kwargs or {})}
        self._env_arg = None if isinstance(env, str) else env
        if not (isinstance(obs_space, spaces.Box) and len(obs_space.shape) == 1):
            raise ValueError(f"observation space {obs_space!r} is not supported; expected a 1-D Box")
        self.observation_space = obs_space
        self.action_space = act_space
        self.hybrid = HybridActionSpace.from_gym(act_space)
        self.obs_dim = int(obs_space.shape[0])
        self.num_timesteps = 0
        self.epoch = 0
        self.np_rng = np.random.default_rng(config.seed)
        self.torch_gen = torch.Generator().manual_seed(config.seed)
        with torch.random.fork_rng():
            torch.manual_seed(config.seed)
            self._build()
        self._vec_env: gymnasium.vector.VectorEnv | None = None
        self._cpu_share: Callable[[], float] = _alone  # runs sharing this process's CPU time (seed stacks)

    # -- to be provided by each algorithm ----------------------------------------------------
    def _build(self) -> None:
        raise NotImplementedError

    def _run_epoch(self) -> dict[str, float]:
        """Collect one epoch of samples and learn from them; returns statistics including ``"steps"``."""
        raise NotImplementedError

    def _act(self, obs: torch.Tensor, deterministic: bool) -> tuple[torch.Tensor, torch.Tensor]:
        """Discrete actions ``(B,)`` and padded ``[-1, 1]`` parameters ``(B, m)`` for a batch of observations."""
        raise NotImplementedError

    def _modules(self) -> dict[str, torch.nn.Module]:
        raise NotImplementedError

    def _optimizers(self) -> dict[str, torch.optim.Optimizer]:
        return {}

    def _extra_state(self, replay: bool) -> dict:
        """What a checkpoint holds besides modules and optimisers; ``replay``: the replay buffer's contents too."""
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

    def _obs_tensor(self, obs) -> torch.Tensor:
        return torch.as_tensor(np.asarray(obs, dtype=np.float32))

    # -- public API --------------------------------------------------------------------------
    def predict(self, obs, deterministic: bool = True):
        """The action for one observation (the env's action tuple) or a batch (a vector env's action)."""
        obs = np.asarray(obs, dtype=np.float32)
        single = obs.ndim == 1
        if obs.shape[-1] != self.obs_dim or obs.ndim not in (1, 2):
            raise ValueError(f"observation of shape {obs.shape}; expected ({self.obs_dim},) or (N, {self.obs_dim})")
        if not np.isfinite(obs).all():
            where = np.argwhere(~np.isfinite(obs))[0].tolist()
            raise ValueError(
                f"observation with a non-finite value {obs[tuple(where)]} at index {where}; expected numbers"
            )
        with torch.no_grad():
            a, x = self._act(torch.as_tensor(obs.reshape(-1, self.obs_dim)), deterministic)
        a, x = a.numpy(), x.numpy()
        return self.hybrid.to_env(a[0], x[0]) if single else self.hybrid.to_env_batch(a, x)

    def learn(
        self,
        total_timesteps: int,
        callback: Callable[[Algorithm, dict[str, float]], bool | None] | None = None,
        progress_bar: bool = True,
        run_dir: str | os.PathLike | None = None,
        checkpoint_every: int = 1,
        eval_every: int = 0,
        eval_episodes: int = 100,
    ) -> Self:
        """Train for ``total_timesteps`` more environment steps, in whole epochs.

        Args:
            callback: called after every epoch with the algorithm and the epoch's statistics; returning
                ``False`` stops training.
            progress_bar: show a tqdm progress bar on the terminal.
            run_dir: where to write ``progress.csv``, TensorBoard logs (``tb/``) and ``checkpoint.pt``.
            checkpoint_every: epochs between checkpoints (with ``run_dir``).
            eval_every: epochs between greedy evaluations (0: none), logged as ``eval/mean_return`` (and
                ``eval/goal_rate`` on Half Field Offense). They play ``eval_episodes`` episodes on separate
                env copies seeded ``10_000 + seed`` and draw nothing from the training's random streams.
        """
        from tqdm.auto import tqdm

        if total_timesteps < 0:
            raise ValueError(f"total_timesteps = {total_timesteps!r}; expected a non-negative integer")
        if eval_every < 0 or (eval_every > 0 and eval_episodes < 1):
            raise ValueError(
                f"eval_every = {eval_every!r}, eval_episodes = {eval_episodes!r}; expected eval_every >= 0 "
                "and, when it is positive, eval_episodes >= 1"
            )
        if eval_every > 0 and self.env_id is None:  # before training, not after its first epoch
            raise ValueError("eval_every needs a registered env (an env id); this model's env has none")
        torch.set_num_threads(self.config.torch_threads)
        target = self.num_timesteps + int(total_timesteps)
        logger = Logger(run_dir, resume_step=self.num_timesteps) if run_dir is not None else None
        start_steps, start_time = self.num_timesteps, time.perf_counter()
        bar = tqdm(
            total=target,
            initial=self.num_timesteps,
            disable=not progress_bar,
            unit="step",
            dynamic_ncols=True,
        )
        try:
            while self.num_timesteps < target:
                t0, cpu0 = time.perf_counter(), time.process_time()
                stats = self._run_epoch()
                self.num_timesteps += int(stats.pop("steps"))
                self.epoch += 1
                elapsed = time.perf_counter() - t0
                stats.update(
                    {
                        "time/epoch": float(self.epoch),
                        "time/total_timesteps": float(self.num_timesteps),
                        "time/epoch_seconds": elapsed,
                        # CPU time of this process: unlike the wall clock, it stops while the run is suspended
                        # (shared equally by the seeds stacked in this process, see pamdp.algos.stacking)
                        "time/epoch_cpu_seconds": (time.process_time() - cpu0) / self._cpu_share(),
                        "charts/SPS": (self.num_timesteps - start_steps) / (time.perf_counter() - start_time),
                    }
                )
                if eval_every > 0 and self.epoch % eval_every == 0:
                    stats.update(self._greedy_evaluation(eval_episodes))
                if logger is not None:
                    logger.record(stats, self.num_timesteps)
                    if self.epoch % checkpoint_every == 0:
                        self.save(Path(run_dir) / CHECKPOINT)
                bar.update(self.num_timesteps - bar.n)
                if "charts/episodic_return" in stats:
                    bar.set_postfix(ret=f"{stats['charts/episodic_return']:.3f}", epoch=self.epoch)
                if callback is not None and callback(self, stats) is False:
                    break
        finally:
            bar.close()
            if logger is not None:
                logger.close()
        return self

    def _greedy_evaluation(self, episodes: int) -> dict[str, float]:
        from pamdp.evaluation import evaluate

        result = evaluate(self, episodes=episodes, seed=10_000 + self.config.seed)
        stats = {"eval/mean_return": result["mean_return"], "eval/mean_length": result["mean_length"]}
        if "goal_rate" in result:
            stats["eval/goal_rate"] = result["goal_rate"]
        return stats

    def save(self, path: str | os.PathLike, replay: bool | None = None) -> None:
        """Write weights, optimiser states, settings, counters and RNG states to one file, atomically.

        ``replay``: whether an off-policy algorithm's replay buffer goes in too (large); ``None`` follows the
        ``save_replay`` setting. A resumed run needs it to go on exactly; a model for acting does not.
        """
        replay = bool(getattr(self.config, "save_replay", False)) if replay is None else replay
        payload = {
            "format": _FORMAT,
            "pamdp_version": pamdp.__version__,
            "algo": type(self).__name__,
            "config": self.config.to_dict(),
            "env_id": self.env_id,
            "env_kwargs": self.env_kwargs,
            "num_timesteps": self.num_timesteps,
            "epoch": self.epoch,
            "rng": {"numpy": self.np_rng.bit_generator.state, "torch": self.torch_gen.get_state()},
            "modules": _own_storage({k: m.state_dict() for k, m in self._modules().items()}),
            "optimizers": _own_storage({k: o.state_dict() for k, o in self._optimizers().items()}),
            "extra": self._extra_state(replay),
        }
        atomic_save(payload, path)

    @classmethod
    def load(cls, path: str | os.PathLike, env=None) -> Self:
        """Load a model saved by :meth:`save`, or the final model of a run directory written by ``pamdp train``.

        ``env`` (an id, env or vector env) replaces the env recorded in the file.
        """
        payload = read_checkpoint(path)
        if payload["algo"] != cls.__name__:
            raise ValueError(f"{path} holds a {payload['algo']} model, not a {cls.__name__} one")
        return cls._from_payload(payload, env)

    @classmethod
    def _from_payload(cls, payload: dict, env=None) -> Self:
        config = cls.config_class.from_dict(payload["config"])
        if env is None:
            if payload["env_id"] is None:
                raise ValueError("this model was trained on an unregistered env; pass env= to load it")
            algo = cls(payload["env_id"], config, env_kwargs=payload["env_kwargs"])
        else:  # the recorded env arguments still apply when the same env id is named again
            same_id = isinstance(env, str) and env == payload["env_id"]
            algo = cls(env, config, env_kwargs=payload["env_kwargs"] if same_id else None)
        for name, module in algo._modules().items():
            module.load_state_dict(payload["modules"][name])
        for name, opt in algo._optimizers().items():
            opt.load_state_dict(payload["optimizers"][name])
        algo._load_extra_state(payload["extra"])
        algo.num_timesteps = int(payload["num_timesteps"])
        algo.epoch = int(payload["epoch"])
        algo.np_rng.bit_generator.state = payload["rng"]["numpy"]
        algo.torch_gen.set_state(payload["rng"]["torch"])
        return algo
