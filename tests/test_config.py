"""Settings validation shared by every algorithm's config: each setting's ``check``, and its error messages."""

from __future__ import annotations

import dataclasses
import re
import types
import typing

import pytest

from pamdp.algos.base import LAYERS, NON_NEGATIVE, POSITIVE, at_least, interval, one_of
from pamdp.algos.hyar import HyARConfig
from pamdp.algos.paddpg import PADDPGConfig
from pamdp.algos.pappo import PAPPOConfig
from pamdp.algos.pasvg import PASVG0Config
from pamdp.algos.patrpo import PATRPOConfig
from pamdp.algos.pdqn import PDQNConfig

CONFIGS = [PATRPOConfig, PAPPOConfig, PASVG0Config, PADDPGConfig, PDQNConfig, HyARConfig]
# Settings any value of their type suits: the seed, and PATRPO's and PAPPO's initial log-std (any finite number).
UNCONSTRAINED = {"seed", "init_log_std"}


def test_interval_ends_are_open_or_closed_as_asked():
    closed, left_open, both_open = interval(0, 1), interval(0, 1, low_open=True), interval(0, 1, True, True)
    assert [closed.ok(v) for v in (-1e-9, 0, 1, 1 + 1e-9)] == [False, True, True, False]
    assert [left_open.ok(v) for v in (0, 1e-9, 1)] == [False, True, True]
    assert [both_open.ok(v) for v in (0, 0.5, 1)] == [False, True, False]
    assert (closed.expected, left_open.expected, both_open.expected) == (
        "a number in [0, 1]",
        "a number in (0, 1]",
        "a number in (0, 1)",
    )


def test_other_checks_by_hand():
    assert [at_least(1).ok(v) for v in (0, 1, 2)] == [False, True, True]
    assert [POSITIVE.ok(v) for v in (-1, 0, 1e-12)] == [False, False, True]
    assert [NON_NEGATIVE.ok(v) for v in (-1e-12, 0)] == [False, True]
    assert [LAYERS.ok(v) for v in ((), (0,), (64, 0), (64,), (400, 300))] == [False, False, False, True, True]
    assert one_of(("a", "b")).ok("b") and not one_of(("a", "b")).ok("c")
    assert one_of(("a", "b")).expected == "one of 'a', 'b'"


@pytest.mark.parametrize("config_class", CONFIGS, ids=lambda c: c.__name__)
def test_every_setting_is_checked_unless_any_value_of_its_type_suits_it(config_class):
    hints = typing.get_type_hints(config_class)
    unchecked = [
        f.name
        for f in dataclasses.fields(config_class)
        if f.metadata.get("check") is None and hints[f.name] is not bool and f.name not in UNCONSTRAINED
    ]
    assert unchecked == []


# Values of each type, among which every check finds one it rejects.
CANDIDATES = {
    int: [-1, 0, 10**9],
    float: [-1.0, 0.0, 1.5, 101.0, 1e9],
    str: ["no-such-choice"],
    tuple: [(), (0,)],
}


@pytest.mark.parametrize("config_class", CONFIGS, ids=lambda c: c.__name__)
def test_each_check_rejects_a_bad_value_with_an_error_naming_it(config_class):
    hints = typing.get_type_hints(config_class)
    checked = [f for f in dataclasses.fields(config_class) if f.metadata.get("check") is not None]
    assert checked
    for f in checked:
        check = f.metadata["check"]
        kind = typing.get_origin(hints[f.name]) or hints[f.name]
        kind = float if kind in (typing.Union, types.UnionType) else kind  # float | None
        bad = [v for v in CANDIDATES[kind] if not check.ok(v)]
        assert bad, f"{f.name}: no candidate fails {check.expected!r}"
        value = bad[0]
        message = f"{config_class.__name__}.{f.name} = {value!r}; expected {check.expected}"
        with pytest.raises(ValueError, match=re.escape(message)):
            config_class(**{f.name: value})
