"""pamdp's one env shell: a :class:`Domain`'s copies as a Gymnasium ``VectorEnv`` (:class:`DomainVectorEnv`), and
what it shares with the scalar env (:class:`Shell`). The contract, the seeding and the rules the shell keeps:
``docs/environments.md``, "How the environments are built" and "Writing a new domain"."""

from __future__ import annotations

import inspect
import re
import typing
from collections.abc import Sequence

import numba
import numpy as np
from gymnasium import spaces
from gymnasium.error import ResetNeeded
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from pamdp.envs.streams import RandomStreams, copy_seeds

__all__ = ["Domain", "DomainVectorEnv", "Shell", "split_actions", "column", "hybrid_space", "every_copy", "shown"]

_TYPES = {bool: (bool, np.bool_), int: (int, np.integer), float: (int, float, np.integer, np.floating), str: (str,)}
"""What a value of a domain argument annotated with the key may be (``bool`` nowhere but under ``bool``)."""
NO_GENERATOR = "each copy has its own generator: read or assign np_randoms (one per copy)"


def shown(value) -> str:
    """``repr(value)`` in one line, for an error message (an array of several rows spans several)."""
    return re.sub(r"\s*\n\s*", " ", repr(value))


def split_actions(actions, domain: str, n: int, expected: str, n_actions=None, n_params=None) -> tuple:
    """``(a, params)`` of a batch of ``n`` actions, as given, once ``a`` is an int array ``(n,)`` (in ``0..n_actions
    - 1``) and ``params`` a tuple or list of ``n_params`` (None: either not checked); else ``ValueError``."""
    if not isinstance(actions, (tuple, list)) or len(actions) != 2:
        raise ValueError(f"invalid batch of {domain} actions {shown(actions)}; expected {expected}")
    a = np.asarray(actions[0])
    if a.shape != (n,) or a.dtype.kind not in "iu":
        raise ValueError(f"invalid discrete actions {shown(actions[0])}; expected {expected}")
    if n_actions is not None and _outside(a, n_actions):
        bad = (a < 0) | (a >= n_actions)
        raise ValueError(f"discrete actions {a[bad]} at indices {np.flatnonzero(bad)}; expected {expected}")
    params = actions[1]
    if n_params is not None and (not isinstance(params, (tuple, list)) or len(params) != n_params):
        raise ValueError(f"invalid parameters {shown(params)}; expected {expected}")
    return a, params


def column(p, n: int, name: int | str, expected: str, size: int = 1, finite: bool = False) -> np.ndarray:
    """The first number of ``n`` copies' parameters given ``(n, size)`` (one number: or ``(n,)``), numeric (all finite
    if ``finite``), as an ``(n,)`` array (dtype kept); else a ``ValueError`` naming ``name`` (an int ``i``: "parameter
    i") and the bad value."""
    p = np.asarray(p)
    bad = p.shape not in ((n, size), (n,) if size == 1 else (n, size)) or p.dtype.kind not in "iuf"
    if bad or finite and not np.isfinite(p).all():  # (the message is built only here: a step checks many)
        name = f"parameter {name}" if isinstance(name, int) else name
        found = f"invalid {name} of shape {p.shape}: {shown(p)}" if bad else f"{name} contains {p[~np.isfinite(p)]}"
        raise ValueError(f"{found}; expected {expected}")
    return p.reshape(n) if size == 1 else p[:, 0]


def hybrid_space(*boxes) -> spaces.Tuple:
    """``Tuple(Discrete(K), Tuple(Box_0, ..., Box_{K-1}))``, float32, from each action's ``(low, high, size)`` (a
    size of 0: no parameter)."""
    boxes = tuple(spaces.Box(np.full(m, lo, np.float32), np.full(m, hi, np.float32)) for lo, hi, m in boxes)
    return spaces.Tuple((spaces.Discrete(len(boxes)), spaces.Tuple(boxes)))


def every_copy(n: int, **values: np.ndarray) -> dict:
    """Gymnasium's merged ``info`` of ``values`` that all ``n`` copies report (their ``"_" + key`` masks all true)."""
    infos, every = dict(values), np.ones(n, dtype=bool)
    for key in values:
        infos["_" + key] = every
    return infos


class Domain:
    """The contract between a domain and the env shell, subclassed in the domain's ``env.py``: the attributes below,
    ``action_space`` and ``observation_space`` (one copy's), the methods below and ``parse``, ``reset``, ``step`` and
    ``frame`` (``docs/environments.md``, "Writing a new domain"); an instance is one variant."""

    name: str  # in error messages
    render_fps: int = 10
    state_size: int  # length of one copy's state row
    draw: str = "random"  # the generator method a copy's numbers come from (RandomStreams)
    reset_draws: int = 0  # the most numbers one copy's reset takes
    step_draws: int = 0  # the most one copy's step takes before it must be topped up (0: a step draws nothing)
    buffer_size: int = 1  # numbers kept per copy in the batched env
    scalar_buffer_size: int = 1  # in the scalar env (a reset's where nothing may be drawn ahead of np_random)
    max_episode_steps: int | None = None  # the time limit, also the batched env's default; None: the domain's end
    reset_options: tuple[str, ...] = ()  # the keys reset(options=...) takes (and the batched env's reset_mask)
    option_hints: dict = {}  # a word for a refused key that looks meant (Hard Move's n: a constructor argument)
    initial_state: np.ndarray | None = None  # a copy's state row before its first reset (None: zeros)

    def initial_states(self, n: int) -> np.ndarray:
        """The state rows ``(n, state_size)`` before the first reset (and the domain's own per-copy arrays)."""
        return np.zeros((n, self.state_size)) if self.initial_state is None else np.tile(self.initial_state, (n, 1))

    def state(self, states: np.ndarray):
        """What the envs' ``state`` shows of the rows (the scalar env's: copy 0's part of it)."""
        return states.copy()

    def check_options(self, options: dict, n: int) -> None:
        """Check the values of ``reset`` options (their keys are checked already); ``ValueError`` naming one."""

    def substep_frames(self, env) -> list[np.ndarray]:
        """The scalar env's frames of its last step (one per sub-step where the domain records them)."""
        return [self.frame(env, 0)]


class Shell:
    """What the scalar and the batched env share: their domain, the checks of their arguments and reset options, the
    state rows and random streams; the domain's attributes (``n``, ``motions``...) read as the env's own."""

    metadata = {"render_modes": ["rgb_array"]}
    domain_class: type[Domain]
    variant: dict = {}  # constructor arguments of the domain fixed by the class (Hard Goal's hard=True)

    def _build(self, n: int, buffer_size: str, max_episode_steps, render_mode, variant: dict) -> Domain:
        """Check the arguments (an unknown domain argument, or one of another type than its annotation, is a
        ``ValueError`` naming it: ``deterministic="no"`` would otherwise switch it on) and set the shell up."""
        cls, variant = self.domain_class, {**self.variant, **variant}
        params = [name for name in inspect.signature(cls.__init__).parameters if name != "self"]
        hints = typing.get_type_hints(cls.__init__)
        for name, value in variant.items():
            if name not in params:
                expected = ", ".join(params) or "none"
                raise ValueError(f"{cls.name} takes no argument {name!r}; expected some of {expected}")
            kinds, hint = _TYPES.get(hints.get(name)), hints.get(name)
            if kinds and (isinstance(value, (bool, np.bool_)) and hint is not bool or not isinstance(value, kinds)):
                raise ValueError(f"{cls.name} argument {name}={value!r}; expected {hint.__name__}")
        self.domain = domain = cls(**variant)  # the constructor checks the ranges
        if max_episode_steps == "domain":
            max_episode_steps = domain.max_episode_steps
        elif max_episode_steps is not None and (
            isinstance(max_episode_steps, bool) or not isinstance(max_episode_steps, (int, np.integer))
            or max_episode_steps < 1
        ):  # fmt: skip
            raise ValueError(f"max_episode_steps must be a positive integer or None, got {max_episode_steps!r}")
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            modes = [None, *self.metadata["render_modes"]]
            raise ValueError(f"render_mode={render_mode!r} is not supported; expected one of {modes}")
        self.max_episode_steps, self.render_mode = max_episode_steps, render_mode
        self.metadata = {**self.metadata, "render_fps": domain.render_fps}
        self.streams = RandomStreams(n, domain.draw, getattr(domain, buffer_size))
        self._states = domain.initial_states(n)
        self._obs_shape, self._obs_dtype = (n, *domain.observation_space.shape), domain.observation_space.dtype
        self._started = False
        return domain

    def _outputs(self) -> tuple:
        """New arrays for a step's outputs, which the domain fills: observations (every row), rewards and both flags
        (zero and false where it writes nothing)."""
        n = self._obs_shape[0]
        return np.empty(self._obs_shape, self._obs_dtype), np.zeros(n), np.zeros(n, bool), np.zeros(n, bool)

    def __getattr__(self, name: str):
        if name == "np_random":  # the batched env's property refused it; Python then asks here, for the hint
            raise AttributeError(NO_GENERATOR)
        if name == "domain":
            raise AttributeError(name)
        return getattr(self.domain, name)

    def _check_options(self, options, n: int, shell_keys: tuple[str, ...] = ()) -> None:
        """``reset(options=...)``: None or a dict of keys among the domain's and ``shell_keys``, else a ``ValueError``
        naming the unknown keys and the accepted ones; then the domain checks the values."""
        if options is None:
            return
        domain, accepted = self.domain, (*self.domain.reset_options, *shell_keys)
        listed = ", ".join(map(repr, accepted)) or "none"
        if not isinstance(options, dict):
            raise ValueError(f"reset options={shown(options)}; expected None or a dict with keys among {listed}")
        unknown = [k for k in options if k not in accepted]
        if unknown:
            hints = "".join(f"; {domain.option_hints[k]}" for k in unknown if k in domain.option_hints)
            raise ValueError(f"{domain.name} takes no reset option(s) {unknown}; expected any of {listed}{hints}")
        domain.check_options(options, n)


class DomainVectorEnv(Shell, VectorEnv):
    """``num_envs`` copies of a :class:`Domain` with Gymnasium's next-step autoreset; ``max_episode_steps`` truncates
    (default: the domain's; None: never), ``render_mode`` None or ``"rgb_array"``, ``**variant`` the domain's."""

    metadata = {**Shell.metadata, "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(
        self,
        num_envs: int = 1,
        max_episode_steps: int | str | None = "domain",
        render_mode: str | None = None,
        **variant: object,
    ):
        if isinstance(num_envs, bool) or not isinstance(num_envs, (int, np.integer)) or num_envs < 1:
            raise ValueError(f"num_envs must be a positive integer, got {num_envs!r}")
        self.num_envs = n = int(num_envs)
        domain = self._build(n, "buffer_size", max_episode_steps, render_mode, variant)
        self.single_action_space, self.single_observation_space = domain.action_space, domain.observation_space
        self.action_space = batch_space(self.single_action_space, n)
        self.observation_space = batch_space(self.single_observation_space, n)
        self.draws_per_step = max(domain.reset_draws, domain.step_draws)
        self._elapsed, self._autoreset = np.zeros(n, dtype=np.int64), np.zeros(n, dtype=bool)

    @property
    def states(self) -> np.ndarray:
        """A copy of the copies' state rows ``(N, state_size)`` (indices in the domain's dynamics module)."""
        return self._states.copy()

    @property
    def state(self):
        """The domain's view of the state rows, one entry per copy."""
        return self.domain.state(self._states)

    @property
    def np_randoms(self) -> tuple:
        """Each copy's generator; assign a sequence of ``num_envs`` of them to replace them all."""
        return self.streams.generators

    @np_randoms.setter
    def np_randoms(self, generators: Sequence) -> None:
        if len(generators) != self.num_envs:
            raise ValueError(f"{len(generators)} generators given; expected one per copy ({self.num_envs})")
        for i, rng in enumerate(generators):
            self.streams.set(i, rng)

    @property
    def np_random(self):
        raise AttributeError(NO_GENERATOR)

    @np_random.setter
    def np_random(self, value):
        raise AttributeError("each copy has its own generator: assign np_randoms (one per copy) instead")

    def reset(self, *, seed=None, options: dict | None = None):
        """Reset all copies, or with ``options={"reset_mask": mask}`` only those where ``mask`` is true.

        ``seed``: None, an int (copy i gets ``seed + i``) or a list with one seed (or None) per copy. The seed and
        the options are checked whole before any copy is seeded or reset: a refused reset changes nothing.
        """
        self._check_options(options, self.num_envs, shell_keys=("reset_mask",))
        seeded = np.array([s is not None for s in copy_seeds(seed, self.num_envs)])
        mask = np.asarray((options or {}).get("reset_mask", np.ones(self.num_envs, dtype=bool)))
        if mask.shape != (self.num_envs,) or mask.dtype != np.bool_:
            raise ValueError(f"reset_mask must be a bool array of shape ({self.num_envs},), got {shown(mask)}")
        self.streams.seed(seed)
        self.streams.refill(self.draws_per_step)
        obs = self._outputs()[0]
        infos = self.domain.reset(self, mask, options, seeded, obs)
        self._started = True
        self._elapsed[mask] = 0
        self._autoreset[mask] = False
        return obs, infos

    def step(self, actions):
        if not self._started:
            raise ResetNeeded("call reset() before step()")
        parsed = self.domain.parse(actions, self.num_envs)
        resetting = self._autoreset
        if self.draws_per_step:
            self.streams.refill(self.draws_per_step)
        obs, rewards, terminated, truncated = out = self._outputs()
        infos = self.domain.step(self, parsed, resetting, *out)
        self._autoreset = np.empty(self.num_envs, dtype=bool)  # a new array: ``resetting`` was handed out
        limit = self.max_episode_steps or 0
        _end_step(resetting, rewards, terminated, truncated, self._elapsed, limit, self._autoreset)
        return obs, rewards, terminated, truncated, infos

    def render(self):
        """One frame per copy (a tuple) with ``render_mode="rgb_array"``, else None."""
        if self.render_mode != "rgb_array":
            return None
        return tuple(self.domain.frame(self, i) for i in range(self.num_envs))


# -- the shell's per-step bookkeeping, compiled: in NumPy it was a dozen array operations a step, at 1 024 copies
# a third of Catch Point's whole batched step (benchmarks/env_speed.md) ------------------------------------------
_jit = numba.njit(cache=True, nogil=True)


@_jit
def _outside(a, n_actions) -> bool:
    """Whether any of ``a`` lies outside ``0..n_actions - 1`` (in one pass: NumPy's ``min`` and ``max`` are two)."""
    for i in range(a.shape[0]):
        if a[i] < 0 or a[i] >= n_actions:
            return True
    return False


@_jit
def _end_step(resetting, rewards, terminated, truncated, elapsed, max_steps, autoreset) -> None:
    """The end of a batched step: a copy reset in it gets reward 0, both flags false and its count 0; the others
    count the step, truncated at ``max_steps`` (0: never); ``autoreset``: whose episode has ended."""
    for i in range(resetting.shape[0]):
        if resetting[i]:
            rewards[i] = 0.0
            terminated[i] = truncated[i] = False
            elapsed[i] = 0
        else:
            elapsed[i] += 1
            if max_steps > 0 and elapsed[i] >= max_steps:
                truncated[i] = True
        autoreset[i] = terminated[i] or truncated[i]
