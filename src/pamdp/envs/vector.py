"""pamdp's one env shell: a domain's copies as a Gymnasium ``VectorEnv``, and what every domain shares.

A domain is a subclass of :class:`Domain` (see its docstring for the contract; ``envs/platform/env.py`` is
a worked example): sizes, spaces, random numbers per step, one batch action parser and compiled per-copy
``reset`` / ``step`` / ``observe`` looped over the copies. :class:`DomainVectorEnv` runs N copies of it;
``pamdp.envs.scalar.DomainEnv`` is the same domain at N = 1. A variant (Hard Goal, Sliding, Hard Move's
``n``, HFO's settings) is a constructor argument of the domain, passed through the registration's kwargs.

Every copy draws only from its own generator, seeded as Gymnasium seeds the copies of its vector envs:
``reset(seed=s)`` gives copy i ``seed + i``, ``reset(seed=[s0, s1, ...])`` one seed each. A copy's
trajectory therefore depends on its seed alone, not on how many copies run beside it, and copy i equals the
scalar env reset with copy i's seed, step for step, noise included.

Random numbers reach compiled code through :class:`~pamdp.envs.streams.RandomStreams`, one buffer of draws per
copy, topped up by the shell before a step; the compiled step never calls back.

The shell does the rest: argument checks, seeding, ``options={"reset_mask": mask}``, next-step autoreset
(the step after an episode ends returns the copy's reset observation, reward 0, both flags false), the
``max_episode_steps`` truncation, and ``np_randoms`` (the copies' generators; assigning a sequence of
generators, or of stand-ins such as a Platform ``ZeroNoise``, replaces them and drops the buffers).
"""

from __future__ import annotations

import inspect
import typing
from collections.abc import Sequence

import numba
import numpy as np
from gymnasium.error import ResetNeeded
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from pamdp.envs.streams import RandomStreams, copy_seeds

__all__ = [
    "Domain",
    "DomainVectorEnv",
    "build_domain",
    "check_options",
    "check_render_mode",
    "time_limit",
    "split_actions",
    "column",
]

_TYPES = {bool: (bool, np.bool_), int: (int, np.integer), float: (int, float, np.integer, np.floating), str: (str,)}
"""What a value of a domain argument annotated with the key may be (``bool`` nowhere but under ``bool``)."""


def build_domain(domain_class: type[Domain], variant: dict) -> Domain:
    """The domain made with the constructor arguments ``variant``, each checked first against the constructor's
    signature: an unknown name, or a value of another type than its annotation (a bool argument takes only a real
    bool: ``deterministic="no"`` would otherwise switch it on), is a ``ValueError`` naming the argument, the value
    and what is expected. The constructor checks the ranges."""
    params = {n: p for n, p in inspect.signature(domain_class.__init__).parameters.items() if n != "self"}
    hints = typing.get_type_hints(domain_class.__init__)
    for name, value in variant.items():
        if name not in params:
            expected = ", ".join(params) or "none"
            raise ValueError(f"{domain_class.name} takes no argument {name!r}; expected some of {expected}")
        kinds = _TYPES.get(hints.get(name))
        if kinds is None:
            continue
        if isinstance(value, (bool, np.bool_)) and hints[name] is not bool or not isinstance(value, kinds):
            raise ValueError(f"{domain_class.name} argument {name}={value!r}; expected {hints[name].__name__}")
    return domain_class(**variant)


def time_limit(max_episode_steps, domain: Domain) -> int | None:
    """The shells' ``max_episode_steps`` argument checked: ``"domain"`` (the domain's limit), None or a positive
    integer."""
    if max_episode_steps == "domain":
        return domain.max_episode_steps
    if max_episode_steps is not None and (
        isinstance(max_episode_steps, bool)
        or not isinstance(max_episode_steps, (int, np.integer))
        or max_episode_steps < 1
    ):
        raise ValueError(f"max_episode_steps must be a positive integer or None, got {max_episode_steps!r}")
    return max_episode_steps


def check_options(domain: Domain, options, n: int, shell_keys: tuple[str, ...] = ()) -> None:
    """The one rule for ``reset(options=...)``: None or a dict whose keys are among the domain's
    ``reset_options`` and the shell's ``shell_keys``; anything else is a ``ValueError`` naming the unknown keys and
    the accepted ones. Then the domain checks the values (:meth:`Domain.check_options`)."""
    if options is None:
        return
    accepted = (*domain.reset_options, *shell_keys)
    listed = ", ".join(map(repr, accepted)) or "none"
    if not isinstance(options, dict):
        raise ValueError(f"reset options={options!r}; expected None or a dict with keys among {listed}")
    unknown = [k for k in options if k not in accepted]
    if unknown:
        hints = "".join(f"; {domain.option_hints[k]}" for k in unknown if k in domain.option_hints)
        raise ValueError(f"{domain.name} takes no reset option(s) {unknown}; expected any of {listed}{hints}")
    domain.check_options(options, n)


def check_render_mode(render_mode, modes) -> None:
    """``ValueError`` unless ``render_mode`` is None or one of ``modes``."""
    if render_mode is not None and render_mode not in modes:
        raise ValueError(f"render_mode={render_mode!r} is not supported; expected one of {[None, *modes]}")


def split_actions(actions, domain: str, n: int, expected: str, n_actions=None, n_params=None) -> tuple:
    """Check the form of a batch of ``n`` actions ``(a, params)``: ``a`` an int array of shape ``(n,)``
    (in ``0..n_actions - 1`` unless ``n_actions`` is None), ``params`` a tuple or list of ``n_params``
    (None: not checked). Returns ``(a, params)`` as given; a bad part raises ``ValueError`` naming it and
    the ``expected`` form."""
    if not isinstance(actions, (tuple, list)) or len(actions) != 2:
        raise ValueError(f"invalid batch of {domain} actions {actions!r}; expected {expected}")
    a = np.asarray(actions[0])
    if a.shape != (n,) or a.dtype.kind not in "iu":
        raise ValueError(f"invalid discrete actions {actions[0]!r}; expected {expected}")
    if n_actions is not None and _outside(a, n_actions):
        bad = (a < 0) | (a >= n_actions)
        raise ValueError(f"discrete actions {a[bad]} at indices {np.flatnonzero(bad)}; expected {expected}")
    params = actions[1]
    if n_params is not None and (not isinstance(params, (tuple, list)) or len(params) != n_params):
        raise ValueError(f"invalid parameters {params!r}; expected {expected}")
    return a, params


def column(p, n: int, name: int | str, expected: str) -> np.ndarray:
    """One parameter of ``n`` copies given with shape ``(n,)`` or ``(n, 1)`` and a numeric dtype, as an
    array of shape ``(n,)`` (dtype kept); ``ValueError`` otherwise, naming ``name`` (an int ``i`` reads
    "parameter i")."""
    p = np.asarray(p)
    if p.shape not in ((n,), (n, 1)) or p.dtype.kind not in "iuf":
        name = f"parameter {name}" if isinstance(name, int) else name
        raise ValueError(f"invalid {name} of shape {p.shape}: {p!r}; expected {expected}")
    return p.reshape(n)


class Domain:
    """The contract between a domain and the env shell; a domain subclasses it once, in its ``env.py``.

    An instance is one variant (its constructor takes the variant's arguments: Hard Move's ``n``, Goal's
    ``hard``, HFO's settings...) for one env; it may keep per-copy arrays of its own beside the state rows, and
    a variant may set its own sizes (``state_size``, the spaces) in its constructor: more players, another
    observation.
    It sets the class attributes below and ``action_space`` / ``observation_space`` (one copy's), and
    implements:

    * :meth:`parse`: check a batch of ``n`` actions (``batch_space`` of ``action_space``) and return the
      arrays its compiled step reads, or raise ``ValueError`` naming the bad part and the expected form. The
      scalar env hands it one action as a batch of one (:func:`pamdp.envs.scalar.as_batch`);
    * :meth:`reset` and :meth:`step`: one compiled call each over the copies (``env._states`` rows,
      ``env.streams`` buffers), returning batched observations, rewards, flags and infos in Gymnasium's
      merged form (``info[k]`` an array, ``info["_" + k]`` which copies report it);
    * :meth:`frame`: the picture of copy ``i`` for ``render_mode="rgb_array"`` (and :meth:`substep_frames`
      where a step runs sub-steps worth showing).
    """

    name: str
    """The domain's name in error messages."""
    render_fps: int = 10
    state_size: int
    """Length of one copy's state row."""
    draw: str = "random"
    """The generator method a copy's numbers come from (see :class:`RandomStreams`)."""
    reset_draws: int = 0
    """The most numbers one copy's reset takes."""
    step_draws: int = 0
    """The most numbers one copy's step takes before it must be topped up (0: a step draws nothing)."""
    buffer_size: int = 1
    """Numbers kept per copy in the batched env."""
    scalar_buffer_size: int = 1
    """Numbers kept in the scalar env (just a reset's where nothing should be drawn ahead of ``np_random``)."""
    max_episode_steps: int | None = None
    """The registration's time limit, also the batched env's default; None leaves the end to the domain."""
    reset_options: tuple[str, ...] = ()
    """The keys ``reset(options=...)`` takes (the batched env's ``reset_mask`` besides); others are refused."""
    option_hints: dict = {}
    """A word for a key that is refused but looks meant (Hard Move's ``n``: a constructor argument)."""

    def initial_states(self, n: int) -> np.ndarray:
        """The state rows ``(n, state_size)`` before the first reset (and where the domain keeps per-copy arrays
        of its own, such as the last actions its pictures show, it allocates them here)."""
        return np.zeros((n, self.state_size))

    def state(self, states: np.ndarray):
        """What the envs' ``state`` shows of the rows (the scalar env's: copy 0's part of it)."""
        return states.copy()

    def parse(self, actions, n: int) -> tuple:
        raise NotImplementedError

    def check_options(self, options: dict, n: int) -> None:
        """Check the values of ``reset`` options for ``n`` copies (the keys are checked already); ``ValueError``
        naming a bad one. Runs before any copy is seeded or reset."""

    def reset(self, env, mask: np.ndarray, options: dict | None, seeded: np.ndarray) -> tuple:
        """Start an episode in the copies where ``mask`` is true (``seeded``: those just given a seed)."""
        raise NotImplementedError

    def step(self, env, parsed: tuple, resetting: np.ndarray) -> tuple:
        """Reset the copies where ``resetting`` is true, step the others with the ``parsed`` actions."""
        raise NotImplementedError

    def frame(self, env, i: int) -> np.ndarray:
        raise NotImplementedError

    def substep_frames(self, env) -> list[np.ndarray]:
        """The scalar env's frames of its last step: one per sub-step where a step runs several and the domain
        records them (Platform, Goal; none after a reset), else the one after the step."""
        return [self.frame(env, 0)]


class DomainVectorEnv(VectorEnv):
    """``num_envs`` copies of a :class:`Domain`, stepped together, with Gymnasium's next-step autoreset.

    Actions are batched like ``batch_space`` of the scalar action space (what
    :meth:`pamdp.spaces.HybridActionSpace.to_env_batch` produces). The step that ends an episode returns its
    last observation with ``terminated`` or ``truncated`` set; the next ``step`` ignores that copy's action,
    resets it, and returns the reset observation with reward 0 and both flags false.

    Args:
        num_envs: number of copies N.
        max_episode_steps: episodes are truncated after this many agent steps (default: the domain's,
            which the registration also sets; ``make_vec`` passes it in). ``None`` leaves the end to the domain.
        render_mode: ``None`` or ``"rgb_array"``; :meth:`render` then returns one frame per copy.
        **variant: the domain's constructor arguments.
    """

    metadata = {"render_modes": ["rgb_array"], "autoreset_mode": AutoresetMode.NEXT_STEP}
    domain_class: type[Domain]
    variant: dict = {}
    """Constructor arguments of the domain fixed by the class (Hard Goal's ``hard=True``)."""

    def __init__(
        self,
        num_envs: int = 1,
        max_episode_steps: int | str | None = "domain",
        render_mode: str | None = None,
        **variant: object,
    ):
        if isinstance(num_envs, bool) or not isinstance(num_envs, (int, np.integer)) or num_envs < 1:
            raise ValueError(f"num_envs must be a positive integer, got {num_envs!r}")
        self.domain = domain = build_domain(self.domain_class, {**self.variant, **variant})
        max_episode_steps = time_limit(max_episode_steps, domain)
        check_render_mode(render_mode, self.metadata["render_modes"])
        self.metadata = {**self.metadata, "render_fps": domain.render_fps}
        self.num_envs = int(num_envs)
        self.max_episode_steps = max_episode_steps
        self.render_mode = render_mode
        self.single_action_space = domain.action_space
        self.single_observation_space = domain.observation_space
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.streams = RandomStreams(self.num_envs, domain.draw, domain.buffer_size)
        self._states = domain.initial_states(self.num_envs)
        self.draws_per_step = max(domain.reset_draws, domain.step_draws)
        self._elapsed = np.zeros(self.num_envs, dtype=np.int64)
        self._autoreset = np.zeros(self.num_envs, dtype=bool)
        self._started = False

    def __getattr__(self, name: str):
        # The domain's variant and tables (``n``, ``motions``, ``settings``...) read as the env's own.
        if name == "np_random":  # its property refused it; Python then asks here, so the hint is given here
            raise AttributeError("each copy has its own generator: read or assign np_randoms (one per copy)")
        if name == "domain":
            raise AttributeError(name)
        return getattr(self.domain, name)

    @property
    def states(self) -> np.ndarray:
        """A copy of the copies' state rows ``(N, state_size)`` (indices in the domain's dynamics module)."""
        return self._states.copy()

    @property
    def state(self):
        """The domain's view of the state rows, one entry per copy."""
        return self.domain.state(self._states)

    # -- the copies' generators -------------------------------------------------------------------
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
        raise AttributeError("each copy has its own generator: read or assign np_randoms (one per copy)")

    @np_random.setter
    def np_random(self, value):
        raise AttributeError("each copy has its own generator: assign np_randoms (one per copy) instead")

    # -- Gymnasium API ----------------------------------------------------------------------------
    def reset(self, *, seed=None, options: dict | None = None):
        """Reset all copies, or with ``options={"reset_mask": mask}`` only those where ``mask`` is true.

        ``seed``: None, an int (copy i gets ``seed + i``) or a list with one seed (or None) per copy. The seed and
        the options are checked whole before any copy is seeded or reset: a refused reset changes nothing.
        """
        check_options(self.domain, options, self.num_envs, shell_keys=("reset_mask",))
        seeded = np.array([s is not None for s in copy_seeds(seed, self.num_envs)])
        mask = np.ones(self.num_envs, dtype=bool)
        if options is not None and "reset_mask" in options:
            mask = np.asarray(options["reset_mask"])
            if mask.shape != (self.num_envs,) or mask.dtype != np.bool_:
                raise ValueError(f"reset_mask must be a bool array of shape ({self.num_envs},), got {mask!r}")
        self.streams.seed(seed)
        self.streams.refill(self.draws_per_step)
        obs, infos = self.domain.reset(self, mask, options, seeded)
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
        obs, rewards, terminated, truncated, infos = self.domain.step(self, parsed, resetting)
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
    """Whether any of ``a`` lies outside ``0..n_actions - 1`` (one compiled pass: ``min`` and ``max`` are two
    NumPy calls, a good part of checking one action)."""
    for i in range(a.shape[0]):
        if a[i] < 0 or a[i] >= n_actions:
            return True
    return False


@_jit
def _end_step(resetting, rewards, terminated, truncated, elapsed, max_steps, autoreset) -> None:
    """The end of a batched step, copy by copy: a copy that was reset this step gets reward 0, both flags false
    and its step count back to 0; the others count the step and are truncated at ``max_steps`` (0: never);
    ``autoreset`` is whether each copy's episode has ended (to be reset on the next step)."""
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
