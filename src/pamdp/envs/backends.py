"""How an env is made: an env id checked against Gymnasium's registry (its module imported for ``module:Name-v0``),
its arguments checked against its constructor, its copies batched or stepped in turn, and the spaces of whatever a
user passed (an id, an env or a vector env). The algorithms, the evaluation, the callbacks, the presets and the
runner make their envs here; how the copies are then stepped is :mod:`pamdp.envs.stepping`'s."""

from __future__ import annotations

import importlib
import inspect
import typing

import gymnasium
from gymnasium import spaces

from pamdp.hints import type_name, type_ok

__all__ = ["env_spec", "env_creator", "check_env_kwargs", "make_vector_env", "describe_env"]


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
        not_the_envs = MAKE_VEC_ARGUMENTS  # make_vec records its own arguments beside the env's
    elif isinstance(env, gymnasium.Env):
        spaces_of, not_the_envs = (env.observation_space, env.action_space), frozenset()
    else:
        raise ValueError(f"env must be a registered env id, a gymnasium.Env or a VectorEnv; got {env!r}")
    spec = env.spec
    kwargs = {key: value for key, value in (spec.kwargs if spec else {}).items() if key not in not_the_envs}
    return (spec.id if spec else None), kwargs, *spaces_of
