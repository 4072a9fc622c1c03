"""Values checked against type hints as plain data (JSON, TOML, a command line) gives them: the one check of an
algorithm's settings (:mod:`pamdp.algos.settings`) and of an env's arguments
(:func:`pamdp.envs.backends.check_env_kwargs`), below both: it imports nothing of pamdp.
"""

from __future__ import annotations

import numbers
import types
import typing
from typing import Any

__all__ = ["type_ok", "type_name"]


def type_ok(value: Any, hint: Any) -> bool:
    """Whether ``value`` has type ``hint`` as plain data (JSON, TOML) gives it: a bool is no number, an int is a
    float, a list is a tuple."""
    origin = typing.get_origin(hint)
    if origin in (typing.Union, types.UnionType):
        return any(type_ok(value, option) for option in typing.get_args(hint))
    if origin is typing.Literal:
        return value in typing.get_args(hint)
    if origin in (tuple, list):
        items = [a for a in typing.get_args(hint) if a is not Ellipsis]
        return isinstance(value, (list, tuple)) and (len(items) != 1 or all(type_ok(v, items[0]) for v in value))
    if hint is type(None):
        return value is None
    if hint is bool:
        return isinstance(value, bool)
    if hint in (int, float):  # NumPy's scalars too (a size computed with NumPy is an np.int64)
        kind = numbers.Integral if hint is int else numbers.Real
        return isinstance(value, kind) and not isinstance(value, bool)
    return not isinstance(hint, type) or isinstance(value, hint)


def type_name(hint: Any) -> str:
    """``hint`` in words, for an error's "expected ...": ``float``, ``str or None``, ``a list of int``."""
    origin = typing.get_origin(hint)
    if origin in (typing.Union, types.UnionType):
        return " or ".join(type_name(option) for option in typing.get_args(hint))
    if origin in (tuple, list):
        items = [a for a in typing.get_args(hint) if a is not Ellipsis]
        return f"a list of {type_name(items[0])}" if len(items) == 1 else "a list"
    return "None" if hint is type(None) else getattr(hint, "__name__", str(hint))
