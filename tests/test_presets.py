"""Presets chosen by the env (``pamdp.algos.domain_presets``): picked by the command line and the runner where
no preset is named, an explicit preset winning, other envs falling back to the algorithm's default."""

import dataclasses

import pytest

from pamdp.algos import algorithm_class, default_preset, preset_config, preset_names
from pamdp.algos.domain_presets import DOMAIN_PRESETS
from pamdp.cli import _train_spec, build_parser
from pamdp.experiments.runner import RunSpec

HFO = "pamdp/HalfFieldOffense-v0"

# Bester et al.'s Half Field Offense settings as issue 27 writes them (and their run_soccer_pdqn.py has them).
MPDQN_HFO = {
    "multi_pass": True,
    "gamma": 0.99,
    "hidden_sizes": (256, 128, 64),
    "activation": "leaky_relu",
    "q_lr": 1e-3,
    "actor_lr": 1e-5,
    "batch_size": 32,
    "tau_q": 0.001,
    "tau_actor": 0.001,
    "beta": 0.2,
    "epsilon_start": 1.0,
    "epsilon_end": 0.1,
    "epsilon_steps": 100_000,
    "explore_params": True,
    "buffer_size": 500_000,
    "updates_per_step": 0.1,
    "grad_clip": 1.0,
}


def config_of(argv, tmp_path=None):
    args = build_parser().parse_args(["train", *argv])
    return _train_spec(args, algorithm_class(args.algo)).config()


def test_the_command_line_picks_the_envs_preset_and_its_published_values():
    _, preset, config = config_of(["pdqn", "--env", HFO])
    assert preset == "hfo"
    assert {k: getattr(config, k) for k in MPDQN_HFO} == MPDQN_HFO
    # The runner (pamdp reproduce) picks it the same way.
    _, preset, config = RunSpec("pdqn", HFO, 1000, seed=3).config()
    assert preset == "hfo" and config.seed == 3 and config.buffer_size == 500_000
    _, preset, config = config_of(["paddpg", "--env", HFO])
    assert preset == "hausknecht_stone" and config.hidden_sizes == (1024, 512, 256, 128)


def test_an_explicit_preset_wins_over_the_envs(tmp_path):
    cls = algorithm_class("pdqn").config_class
    _, preset, config = config_of(["pdqn", "--env", HFO, "--preset", "tuned"])
    assert preset == "tuned" and config == cls.preset("tuned")
    file = tmp_path / "c.toml"
    file.write_text('preset = "paper"\n')
    _, preset, config = config_of(["pdqn", "--env", HFO, "--config", str(file)])
    assert preset == "paper" and config.gamma == 0.9
    # A flag still overrides the env's preset's value.
    _, preset, config = config_of(["pdqn", "--env", HFO, "--gamma", "0.5"])
    assert preset == "hfo" and config.gamma == 0.5 and config.buffer_size == 500_000
    _, preset, _ = RunSpec("pdqn", HFO, 1000, preset="paper").config()
    assert preset == "paper"


@pytest.mark.parametrize("env", ["pamdp/Platform-v0", "CartPole-v1", None])
def test_an_env_without_a_preset_falls_back_to_the_algorithms_default(env):
    for algo, expected in (("pdqn", "tuned"), ("patrpo", "tuned"), ("hyar", "cpu"), ("paddpg", "paper")):
        assert default_preset(algorithm_class(algo).config_class, env) == expected
    if env is not None:
        assert RunSpec("pdqn", env, 10).config()[1] == "tuned"


@pytest.mark.parametrize("key", list(DOMAIN_PRESETS), ids=lambda k: f"{k[0]}-{k[1].split('/')[-1]}")
def test_each_domain_preset_is_its_base_with_its_overrides(key):
    algo, env = key
    entry = DOMAIN_PRESETS[key]
    cls = algorithm_class(algo).config_class
    assert default_preset(cls, env) == entry.name and entry.name in preset_names(cls)
    config = preset_config(cls, entry.name)  # a config: every value passed its check
    base = cls.preset(entry.base)
    for f in dataclasses.fields(cls):
        expected = entry.settings.get(f.name, getattr(base, f.name))
        assert getattr(config, f.name) == expected, f.name
    assert all(source for _, _, source in entry.overrides)  # every value says where it comes from
    assert entry.overrides or entry.name == entry.base  # a new name is a new set of values
    # --preset takes the name, and a run given it gets the same config.
    build_parser().parse_args(["train", algo, "--env", env, "--preset", entry.name])
    assert RunSpec(algo, env, 10, preset=entry.name).config()[2] == config


def test_an_unknown_preset_is_refused_naming_the_valid_ones(capsys):
    cls = algorithm_class("pdqn").config_class
    with pytest.raises(ValueError, match=r"unknown preset 'hfoo' for PDQNConfig; expected one of paper, tuned, hfo"):
        preset_config(cls, "hfoo")
    with pytest.raises(SystemExit):
        build_parser().parse_args(["train", "patrpo", "--preset", "goal"])  # another algorithm's preset
    assert "invalid choice: 'goal'" in capsys.readouterr().err
