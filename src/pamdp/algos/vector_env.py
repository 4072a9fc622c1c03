"""How an algorithm gets its environments: an env id checked against Gymnasium's registry, its copies
batched or stepped in turn, and the spaces of whatever a user passed (an id, an env or a vector env)."""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import typing

import gymnasium
import numpy as np
from gymnasium import spaces

from pamdp.hints import type_name, type_ok
from pamdp.logger import EpisodeTracker

__all__ = [
    "env_spec",
    "env_creator",
    "check_env_kwargs",
    "make_vector_env",
    "describe_env",
    "info_action_masks",
    "Step",
    "VectorStepper",
]


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
            f"env {env_id!r} is not registered ({exc}); expected a registered Gymnasium id (pamdp's are listed in "
            "pamdp.envs), or module:EnvId-v0 to import the module that registers it"
        ) from exc


def make_vector_env(
    env_id: str, num_envs: int, env_kwargs: dict | None = None, mode: str = "auto"
) -> gymnasium.vector.VectorEnv:
    """``num_envs`` copies of the env: ``"batched"`` (its ``vector_entry_point``), ``"sync"`` (scalar copies
    stepped in turn) or ``"auto"`` (batched whenever the env has a batched version: the scalar env is the batched
    one at one copy, so even one copy steps faster in one compiled loop than through ``SyncVectorEnv``'s per-copy
    Python, benchmarks/platform_speed.md).
    """
    if mode not in ("auto", "batched", "sync"):
        raise ValueError(f"vector env mode {mode!r}; expected 'auto', 'batched' or 'sync'")
    spec = env_spec(env_id)
    batched = spec.vector_entry_point is not None and mode != "sync"
    if mode == "batched" and spec.vector_entry_point is None:
        raise ValueError(f"{env_id} has no batched version (no vector_entry_point); use 'sync'")
    vectorization_mode = "vector_entry_point" if batched else "sync"
    return gymnasium.make_vec(env_id, num_envs=num_envs, vectorization_mode=vectorization_mode, **(env_kwargs or {}))


def env_creator(env_id: str):
    """The class (or function) that makes a registered env; an unregistered id is refused with a ``ValueError``
    (see :func:`env_spec`)."""
    creator = env_spec(env_id).entry_point
    return gymnasium.envs.registration.load_env_creator(creator) if isinstance(creator, str) else creator


def check_env_kwargs(env_id: str, env_kwargs: dict) -> None:
    """Refuse env arguments that the env's constructor does not take, or whose type differs from its annotation
    (or its default's type, where it has none): ``{"deterministic": "no"}`` would otherwise switch the option on.

    An unregistered ``env_id`` is refused too (see :func:`env_spec`).
    """
    if not env_kwargs:
        env_creator(env_id)
        return
    creator = env_creator(env_id)
    try:
        params = inspect.signature(creator).parameters
    except (TypeError, ValueError):  # a callable without a signature: nothing to check against
        return
    try:
        hints = typing.get_type_hints(creator.__init__ if inspect.isclass(creator) else creator)
    except (NameError, TypeError):  # annotations naming what cannot be imported: the defaults still say
        hints = {}
    takes_any = any(p.kind is inspect.Parameter.VAR_KEYWORD for p in params.values())
    named = {n: p for n, p in params.items() if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)}
    for name, value in env_kwargs.items():
        if name not in named:
            if takes_any:
                continue
            raise ValueError(
                f"env {env_id!r} takes no argument {name!r}; expected some of {', '.join(sorted(named)) or 'none'}"
            )
        default = named[name].default
        hint = hints.get(name, type(default) if default not in (inspect.Parameter.empty, None) else None)
        if hint is not None and not type_ok(value, hint):
            raise ValueError(f"env {env_id!r} argument {name} = {value!r}; expected {type_name(hint)}")


MAKE_VEC_ARGUMENTS = frozenset({"num_envs", "vectorization_mode", "vector_kwargs", "wrappers"})
"""What ``gymnasium.make_vec`` adds to a vector env's ``spec.kwargs``: none of them is the env's own argument."""


def describe_env(env, env_kwargs: dict | None = None) -> tuple[str | None, dict, spaces.Space, spaces.Space]:
    """``(env_id, env_kwargs, single observation space, single action space)`` of what a user passed."""
    if isinstance(env, str):
        spec = env_spec(env)
        check_env_kwargs(env, env_kwargs or {})
        probe = gymnasium.make(env, **(env_kwargs or {}))
        obs_space, act_space = probe.observation_space, probe.action_space
        probe.close()
        # "module:Name-v0" keeps its module, so that a loaded model imports it again to make its env
        return (env if ":" in env else spec.id), {}, obs_space, act_space
    if isinstance(env, gymnasium.vector.VectorEnv):
        spaces_of = (env.single_observation_space, env.single_action_space)
    elif isinstance(env, gymnasium.Env):
        spaces_of = (env.observation_space, env.action_space)
    else:
        raise ValueError(f"env must be a registered env id, a gymnasium.Env or a VectorEnv; got {env!r}")
    spec = env.spec
    kwargs = dict(spec.kwargs if spec else {})
    if isinstance(env, gymnasium.vector.VectorEnv):  # make_vec records its own arguments beside the env's
        kwargs = {key: value for key, value in kwargs.items() if key not in MAKE_VEC_ARGUMENTS}
    return (spec.id if spec else None), kwargs, *spaces_of


def info_action_masks(infos: dict, num_envs: int, n_actions: int) -> np.ndarray:
    """The discrete actions allowed in each copy's current state, bool ``(num_envs, n_actions)``, from a vector
    env's infos (Gymnasium's dict of arrays: ``infos["action_mask"]`` ``(N, K)`` beside ``infos["_action_mask"]``,
    which copies report one).

    True means the action has an effect now. A copy that reports no mask, or a mask allowing nothing, gets all
    actions allowed; a mask of another shape is a ``ValueError``.
    """
    masks = np.ones((num_envs, n_actions), dtype=bool)
    if "action_mask" not in infos:
        return masks
    reported = np.asarray(infos["action_mask"])
    if reported.shape != (num_envs, n_actions):
        raise ValueError(
            f"info['action_mask'] of shape {reported.shape}; expected ({num_envs}, {n_actions}) (one bool per "
            "env copy and discrete action)"
        )
    has = np.asarray(infos.get("_action_mask", np.ones(num_envs, dtype=bool)), dtype=bool)
    has &= reported.any(axis=1)
    masks[has] = reported[has].astype(bool)
    return masks


@dataclasses.dataclass
class Step:
    """One step of every copy of a vector env, as :meth:`VectorStepper.step` returns it: ``(N, ...)`` arrays.

    ``obs`` and ``masks`` are the copies' states before the step (``masks``: their allowed actions, ``None``
    without action masks), ``next_obs`` and ``next_masks`` after it. ``valid`` is false on the autoreset steps
    (see :class:`VectorStepper`); ``terminated`` and ``done`` (terminated or truncated) are true only where valid.
    ``ended`` lists the copies whose episode ended, ``flatnonzero(done)``, and ``returns``, ``lengths`` and
    ``successes`` those episodes' (a success ``None`` where the env did not report one).
    """

    obs: np.ndarray
    masks: np.ndarray | None
    reward: np.ndarray
    terminated: np.ndarray
    done: np.ndarray
    valid: np.ndarray
    next_obs: np.ndarray
    next_masks: np.ndarray | None
    info: dict
    returns: np.ndarray
    lengths: np.ndarray
    successes: list[bool | None]

    @property
    def ended(self) -> np.ndarray:
        return np.flatnonzero(self.done)


class VectorStepper:
    """Steps a vector env with Gymnasium's next-step autoreset, keeping the episodes' accounts.

    Such an env resets a finished copy on the *next* step and ignores that step's action: the step is marked
    invalid (no sample, no reward counted). The stepper holds each copy's current observation and allowed actions
    (``masked``: from ``info["action_mask"]``, :func:`info_action_masks`); its :attr:`episodes` keep the running
    and finished episodes' returns and lengths. Training (the on- and off-policy loops) and evaluation step their
    envs through it.
    """

    def __init__(self, env: gymnasium.vector.VectorEnv, n_actions: int, masked: bool, seed: int):
        self.env, self.n_actions, self.masked = env, n_actions, masked
        self.obs, info = env.reset(seed=seed)
        self.masks = self._masks(info)
        self.prev_done = np.zeros(env.num_envs, dtype=bool)
        self.episodes = EpisodeTracker(env.num_envs)

    def _masks(self, info: dict) -> np.ndarray | None:
        return info_action_masks(info, self.env.num_envs, self.n_actions) if self.masked else None

    def step(self, action) -> Step:
        """Step every copy with the env's ``action`` and move on to the new observations."""
        obs, masks = self.obs, self.masks
        next_obs, reward, terminated, truncated, info = self.env.step(action)
        valid = ~self.prev_done
        done = (terminated | truncated) & valid
        ended = self.episodes.step(np.asarray(reward, dtype=np.float64), done, valid, info)
        self.obs, self.masks, self.prev_done = next_obs, self._masks(info), done
        return Step(obs, masks, reward, terminated & valid, done, valid, next_obs, self.masks, info, *ended)
