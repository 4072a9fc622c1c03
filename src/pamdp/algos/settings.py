"""The settings system: typed, frozen, documented configs whose values are checked when they are made.

An algorithm's config subclasses :class:`AlgoConfig` and declares each setting with :func:`setting`: a
default, a one-line help (the field's documentation, its CLI help and its row in ``docs/algorithms.md``) and a
:class:`Check` of its valid values. A value that fails its check, a non-finite float, an unknown name or a
value of the wrong type is a ``ValueError`` naming the setting, the value and what was expected.

A config's presets are its own (:meth:`AlgoConfig.presets`) and those the envs define, which live above the
algorithms (``pamdp.presets``, allowed to know the envs): :meth:`AlgoConfig.preset` and :meth:`AlgoConfig.for_env`
answer for both through the lookup that ``import pamdp`` installs (:func:`install_preset_lookup`).
"""

from __future__ import annotations

import dataclasses
import math
import re
import types
import typing
import warnings
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from pamdp.hints import type_name, type_ok

if TYPE_CHECKING:
    from typing_extensions import Self  # typing.Self from Python 3.11

__all__ = [
    "AlgoConfig",
    "setting",
    "redeclared",
    "Check",
    "at_least",
    "interval",
    "one_of",
    "POSITIVE",
    "NON_NEGATIVE",
    "LAYERS",
    "DEVICE",
    "install_preset_lookup",
]


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
DEVICE = Check(lambda v: re.fullmatch(r"auto|cpu|cuda(:[0-9]+)?", v) is not None, "'auto', 'cpu', 'cuda' or 'cuda:N'")


PresetLookup = Callable[[type, str | None, str | None, dict | None], tuple]
"""``(config class, preset name or None, env id or None, env arguments or None) -> (name, config, warning or
None)``: the preset of that name (``None``: the one a run on the env gets), and a warning where it was made for
another env."""
_preset_lookup: PresetLookup | None = None


def install_preset_lookup(lookup: PresetLookup) -> None:
    """Answer :meth:`AlgoConfig.preset` and :meth:`AlgoConfig.for_env` with ``lookup`` (``pamdp.presets.choose``,
    installed by ``import pamdp``): the algorithms' package reaches the env presets without importing them."""
    global _preset_lookup
    _preset_lookup = lookup


def setting(default: Any, help: str, check: Check | None = None) -> Any:
    """A documented dataclass field: the ``help`` text is the field's documentation and its CLI help; a
    config rejects a value that fails ``check`` with an error naming the value and ``check.expected``."""
    if isinstance(default, (list, dict)):
        raise TypeError("use tuples for sequence settings, so that configs stay immutable")
    return dataclasses.field(default=default, metadata={"help": help, "check": check})


def redeclared(base: type, name: str, default: Any, source: str | None = None) -> Any:
    """Setting ``name`` of the family config ``base`` declared again with an algorithm's own ``default``, with the
    help and the check written there; ``source`` says where the value comes from and joins the help ("Transitions
    per gradient update (Hausknecht & Stone: 32).")."""
    meta = base.__dataclass_fields__[name].metadata
    help = meta["help"] if source is None else f"{meta['help'].rstrip('.')} ({source})."
    return setting(default, help, meta["check"])


@dataclasses.dataclass(frozen=True)
class AlgoConfig:
    """Settings every algorithm has. Subclasses add their own and a :attr:`PRESETS` table."""

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
        "slower (what it buys each algorithm: benchmarks/denormals.md).",
    )
    vector_mode: str = setting(
        "auto",
        "How env copies are stepped: batched (one compiled loop over copies), sync (scalar copies in turn) or auto "
        "(batched wherever the env has a batched version, even for one copy).",
        one_of(("auto", "batched", "sync")),
    )
    device: str = setting(
        "auto",
        "Where the networks, optimisers and updates run: auto (CUDA when available, else the CPU), cpu, cuda or "
        "cuda:N; the envs step on the CPU either way (what a GPU buys: benchmarks/gpu_speed.md).",
        DEVICE,
    )
    action_mask: bool = setting(
        False,
        'Use the env\'s info["action_mask"] (True where a discrete action has an effect now), where it reports '
        "one, in acting and in targets: masked actions are never chosen, greedily or at random, and the targets "
        "and the policy's probabilities range over the allowed ones only. Off: every action, as the papers do.",
    )

    def __post_init__(self):
        """Each setting against its type and its ``check`` (in declaration order); subclasses add checks across
        settings."""
        hints = self.field_types()
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if not type_ok(value, hints[f.name]):  # before the check, which would fail on it with a TypeError
                raise ValueError(f"{type(self).__name__}.{f.name} = {value!r}; expected {type_name(hints[f.name])}")
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

    PRESETS: typing.ClassVar[dict[str, dict[str, Any]]] = {"default": {}}
    """A subclass's presets as the settings each changes from the defaults; :meth:`presets` makes them."""

    @classmethod
    def presets(cls) -> dict[str, Self]:
        """Named settings, e.g. ``"paper"``; the first one is the default."""
        return {name: cls(**changes) for name, changes in cls.PRESETS.items()}

    @classmethod
    def preset(cls, name: str, env_id: str | None = None, env_kwargs: dict | None = None) -> Self:
        """Preset ``name``, as ``pamdp train --preset NAME [--env ENV_ID]`` gives it: one of :meth:`presets`, or one
        an env defines (``pamdp.presets.domains``). Given ``env_id``, a preset made for another env is a
        ``UserWarning`` naming both; an unknown name is a ``ValueError`` naming the valid ones."""
        _, config, warning = cls._look_up(name, env_id, env_kwargs)
        if warning is not None:
            warnings.warn(warning, UserWarning, stacklevel=2)
        return config

    @classmethod
    def for_env(cls, env_id: str | None, env_kwargs: dict | None = None) -> tuple[str, Self]:
        """``(name, config)`` of the preset a run on ``env_id`` (with arguments ``env_kwargs``) gets when none is
        named, as ``pamdp train`` picks it: the env's where it has one, else the algorithm's default."""
        name, config, _ = cls._look_up(None, env_id, env_kwargs)
        return name, config

    @classmethod
    def _look_up(cls, name: str | None, env_id: str | None, env_kwargs: dict | None):
        if _preset_lookup is None:  # only while pamdp/__init__.py has not yet run to its end
            raise RuntimeError("no preset lookup is installed: import pamdp (it installs pamdp.presets') first")
        return _preset_lookup(cls, name, env_id, env_kwargs)

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
        try:
            return tuple(_coerce(name, v, item) for v in value)
        except ValueError:  # name the whole value, not the one bad element
            raise ValueError(f"setting {name!r} = {value!r}; expected {type_name(hint)}") from None
    if hint is float and isinstance(value, (int, float)) and not isinstance(value, bool):
        return float(value)
    if not type_ok(value, hint):
        raise ValueError(f"setting {name!r} = {value!r}; expected {type_name(hint)}")
    return int(value) if hint is int else value  # plain data: an np.int64 is no JSON
