"""Settings validation shared by every algorithm's config: each setting's ``check``, and its error messages."""

from __future__ import annotations

import dataclasses
import re
import types
import typing

import pytest

from pamdp.algos import ALGORITHMS, algorithm_class
from pamdp.algos.hyar import HyARConfig
from pamdp.algos.paddpg import PADDPGConfig
from pamdp.algos.pappo import PAPPOConfig
from pamdp.algos.pasvg import PASVG0Config
from pamdp.algos.patrpo import PATRPOConfig
from pamdp.algos.pdqn import PDQNConfig
from pamdp.algos.settings import LAYERS, NON_NEGATIVE, POSITIVE, at_least, interval, one_of

CONFIGS = [algorithm_class(name).config_class for name in ALGORITHMS]  # every registered algorithm's
# Settings any value of their type suits: PATRPO's and PAPPO's initial log-std (any finite number).
UNCONSTRAINED = {(PATRPOConfig, "init_log_std"), (PAPPOConfig, "init_log_std")}


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
        if config_class.check_of(f.name) is None
        and hints[f.name] is not bool
        and (config_class, f.name) not in UNCONSTRAINED
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
    checked = [f for f in dataclasses.fields(config_class) if config_class.check_of(f.name) is not None]
    assert checked
    for f in checked:
        check = config_class.check_of(f.name)
        kind = typing.get_origin(hints[f.name]) or hints[f.name]
        kind = float if kind in (typing.Union, types.UnionType) else kind  # float | None
        bad = [v for v in CANDIDATES[kind] if not check.ok(v)]
        assert bad, f"{f.name}: no candidate fails {check.expected!r}"
        value = bad[0]
        message = f"{config_class.__name__}.{f.name} = {value!r}; expected {check.expected}"
        with pytest.raises(ValueError, match=re.escape(message)):
            config_class(**{f.name: value})


# (config, setting, a value at or just past an end of its range, accepted?)
BOUNDARIES = [
    (PADDPGConfig, "tau", 0.0, False),
    (PADDPGConfig, "tau", 1.0, True),
    (PADDPGConfig, "adam_beta1", 0.0, True),
    (PADDPGConfig, "adam_beta1", 1.0, False),
    (PADDPGConfig, "gamma", 0.0, True),
    (PADDPGConfig, "gamma", 1.0, True),
    (PADDPGConfig, "grad_clip", 0.0, True),
    (PADDPGConfig, "learning_starts", 0, True),
    (PADDPGConfig, "learning_starts", -1, False),
    (PADDPGConfig, "updates_per_step", 0.0, False),
    (PASVG0Config, "tau", 0.0, False),
    (PASVG0Config, "init_log_std", -5.0, True),
    (PASVG0Config, "init_log_std", 2.5, False),
    (PASVG0Config, "target_entropy", None, True),
    (PASVG0Config, "target_entropy", -0.1, False),
    (PATRPOConfig, "backtrack_ratio", 1.0, False),
    (PATRPOConfig, "backtrack_ratio", 0.0, False),
    (PATRPOConfig, "fvp_subsample", 1.0, True),
    (PATRPOConfig, "fvp_subsample", 0.0, False),
    (PATRPOConfig, "cg_damping", 0.0, True),
    (PATRPOConfig, "seed", 0, True),
    (PATRPOConfig, "seed", -1, False),
    (PAPPOConfig, "clip_range", 1.0, False),
    (PAPPOConfig, "target_kl", 0.0, True),
    (PAPPOConfig, "minibatch_size", 10**6, False),
    (HyARConfig, "lsc_percent", 100.0, True),
    (HyARConfig, "lsc_percent", 0.0, False),
    (HyARConfig, "warmup_updates", 0, True),
    (PDQNConfig, "tau_q", 1.0, True),
    (PDQNConfig, "epsilon_end", 1.0, True),
]


@pytest.mark.parametrize("config_class, name, value, accepted", BOUNDARIES)
def test_range_ends(config_class, name, value, accepted):
    if accepted:
        assert getattr(config_class(**{name: value}), name) == value
    else:
        with pytest.raises(ValueError, match=re.escape(f"{config_class.__name__}.{name} = {value!r}; expected")):
            config_class(**{name: value})


def test_a_setting_declared_again_without_a_check_keeps_its_base_classs():
    @dataclasses.dataclass(frozen=True)
    class MoreEnvs(PADDPGConfig):
        num_envs: int = 32  # a new default, declared without setting()

    assert MoreEnvs().num_envs == 32
    with pytest.raises(ValueError, match=re.escape("MoreEnvs.num_envs = 0; expected an integer >= 1")):
        MoreEnvs(num_envs=0)
