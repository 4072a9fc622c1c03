"""The scalar env: a :class:`~pamdp.envs.vector.Domain` at N = 1 as a ``gymnasium.Env``, running the domain's own
batched ``parse``, ``reset`` and ``step`` on one state row, its stream following ``np_random``; no autoreset, its
own time limit (``docs/environments.md``, "How the environments are built" and "Checked inputs")."""

from __future__ import annotations

import inspect

import gymnasium
import numpy as np

from pamdp.envs.streams import check_seed
from pamdp.envs.vector import Domain, DomainVectorEnv, Shell

__all__ = ["DomainEnv", "as_batch", "env_classes"]


class _OneEach(tuple):
    """One action's parameters, each read as a batch of one (``p[None]``) only when read (Hard Move's 1 024 boxes)."""

    def __getitem__(self, i):
        if isinstance(i, slice):
            return _OneEach(tuple.__getitem__(self, i))
        return np.asarray(tuple.__getitem__(self, i))[None]

    def __iter__(self):
        return map(self.__getitem__, range(len(self)))


def as_batch(action):
    """One action ``(a, params)`` as a batch of one; anything else as it is, for the parser to refuse."""
    if not isinstance(action, (tuple, list)) or len(action) != 2:
        return action
    a, params = action
    return np.asarray(a)[None], _OneEach(params) if isinstance(params, (tuple, list)) else params


class DomainEnv(Shell, gymnasium.Env):
    """One copy of a :class:`~pamdp.envs.vector.Domain` as a Gymnasium env; ``max_episode_steps`` truncates (default:
    the domain's; None: never), ``render_mode`` None or ``"rgb_array"``, ``**variant`` the domain's arguments."""

    num_envs = 1  # the domain's hooks see the scalar env as a batched one of one copy

    def __init__(
        self, render_mode: str | None = None, max_episode_steps: int | str | None = "domain", **variant: object
    ):
        domain = self._build(1, "scalar_buffer_size", max_episode_steps, render_mode, variant)
        self.action_space, self.observation_space = domain.action_space, domain.observation_space
        self._elapsed = 0
        self._calm = np.zeros(1, dtype=bool)  # a scalar env never resets inside a step

    @property
    def state(self):
        """The domain's view of the state (see its ``state``), for copy 0."""
        view = self.domain.state(self._states)
        return {k: v[0] for k, v in view.items()} if isinstance(view, dict) else view[0]

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        check_seed(seed)
        self._check_options(options, 1)
        super().reset(seed=seed)
        self.streams.follow(0, self.np_random)
        if self.domain.reset_draws:
            self.streams.refill(self.domain.reset_draws)
        obs = self._outputs()[0]
        infos = self.domain.reset(self, np.ones(1, dtype=bool), options, np.array([seed is not None]), obs)
        self._started = True
        self._elapsed = 0
        return obs[0], _first(infos)

    def step(self, action):
        if not self._started:
            raise gymnasium.error.ResetNeeded("call reset() before step()")
        parsed = self.domain.parse(as_batch(action), 1)
        self.streams.follow(0, self.np_random)
        if self.domain.step_draws:
            self.streams.refill(self.domain.step_draws)
        obs, rewards, terminated, truncated = out = self._outputs()
        infos = self.domain.step(self, parsed, self._calm, *out)
        self._elapsed += 1
        limited = self.max_episode_steps is not None and self._elapsed >= self.max_episode_steps
        return obs[0], float(rewards[0]), bool(terminated[0]), bool(truncated[0]) or limited, _first(infos)

    def render(self):
        return self.domain.frame(self, 0) if self.render_mode == "rgb_array" else None

    def render_substeps(self) -> list[np.ndarray]:
        """With ``render_mode="rgb_array"``: the last step's frames, one per sub-step where the domain runs several
        (Platform, Goal; none after a reset), the last one :meth:`render`'s (``record_episode`` plays them)."""
        if self.render_mode != "rgb_array":
            raise ValueError(f"render_substeps needs render_mode='rgb_array', got {self.render_mode!r}")
        return self.domain.substep_frames(self)


def _first(infos: dict) -> dict:
    """Copy 0's info from batched infos: the keys it reports, NumPy scalars as Python ones."""
    info = {}
    for key, value in infos.items():
        if not key.startswith("_") and infos.get("_" + key, (True,))[0]:
            v = value[0]
            info[key] = v.item() if isinstance(v, np.generic) else v
    return info


def env_classes(domain_class: type[Domain], module: str, scalar: str, batched: str, **variant) -> tuple[type, type]:
    """A domain's scalar and batched env, classes ``scalar`` and ``batched`` of ``module`` with ``variant`` fixed, whose
    signatures list the domain's arguments (as ``pamdp.algos``, inspecting an env's constructor, expects)."""
    what = f"{domain_class.name}" + "".join(f", {k}={v!r}" for k, v in variant.items())
    attrs = {"domain_class": domain_class, "variant": variant, "__module__": module}
    doc = f"{{}} of {what} (see :class:`{module}.{domain_class.__name__}`)."
    shells = []
    for name, shell, text in (
        (scalar, DomainEnv, "One copy as a ``gymnasium.Env``"),
        (batched, DomainVectorEnv, "N copies stepped at once"),
    ):
        signature = _signature(shell, domain_class, variant, max_episode_steps=domain_class.max_episode_steps)
        shells.append(type(name, (shell,), {**attrs, "__doc__": doc.format(text), "__signature__": signature}))
    return shells[0], shells[1]


def _signature(shell: type, domain_class: type[Domain], variant: dict, **defaults) -> inspect.Signature:
    """The shell's own arguments, then the domain's as keywords (defaults: ``defaults`` and ``variant``)."""
    own = [
        p.replace(default=defaults.get(name, p.default))
        for name, p in inspect.signature(shell.__init__).parameters.items()
        if name != "self" and p.kind is not p.VAR_KEYWORD
    ]
    domain = [
        p.replace(default=variant.get(name, p.default), kind=p.KEYWORD_ONLY)
        for name, p in inspect.signature(domain_class.__init__).parameters.items()
        if name != "self"
    ]
    return inspect.Signature(own + domain)
