"""Presets chosen by the env (``pamdp.presets``): one lookup for the Python API, the command line and the runner,
picking the env's preset where none is named, an explicit preset winning, other envs falling back to the
algorithm's default, a preset made for another env used with a warning."""

import dataclasses
import json
import re
import warnings

import pytest

from pamdp.algos import algorithm_class
from pamdp.algos.patrpo import PATRPO, PATRPOConfig
from pamdp.algos.pdqn import PDQNConfig
from pamdp.cli import _train_spec, build_parser, main
from pamdp.experiments import load_experiment
from pamdp.experiments.runner import RunSpec
from pamdp.presets import default_preset, preset_names
from pamdp.presets.domains import DOMAIN_PRESETS, domain_presets_of, when

HFO = "pamdp/HalfFieldOffense-v0"
HARD_MOVE = "pamdp/HardMove-v0"

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
    _, preset, config, _ = config_of(["pdqn", "--env", HFO])
    assert preset == "hfo"
    assert {k: getattr(config, k) for k in MPDQN_HFO} == MPDQN_HFO
    # The runner (pamdp reproduce) picks it the same way.
    _, preset, config, _ = RunSpec("pdqn", HFO, 1000, seed=3).config()
    assert preset == "hfo" and config.seed == 3 and config.buffer_size == 500_000
    _, preset, config, _ = config_of(["paddpg", "--env", HFO])
    assert preset == "hausknecht_stone" and config.hidden_sizes == (1024, 512, 256, 128)


def test_python_and_the_command_line_give_one_config(tmp_path):
    # Config.preset answers for the env's presets as --preset does: the config pamdp train records in run.json.
    out = tmp_path / "run"
    small = {"epoch_steps": 8, "num_envs": 1}
    flags = [f"--{k.replace('_', '-')}={v}" for k, v in small.items()]
    argv = ["train", "pdqn", "--env", HFO, "--total-steps", "8", "--eval-episodes", "0", "--no-progress"]
    with pytest.warns(UserWarning, match="makes no gradient update"):  # 8 steps: the config, not training
        assert main([*argv, *flags, "--out", str(out)]) == 0
    run = json.loads((out / "run.json").read_text())
    assert run["preset"] == "hfo" and "preset_warning" not in run
    expected = dataclasses.replace(PDQNConfig.preset("hfo"), **small)
    assert PDQNConfig.from_dict(run["config"]) == expected
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # on its own env: no warning
        assert PDQNConfig.preset("hfo", HFO) == PDQNConfig.preset("hfo")
    # An algorithm given no config trains with what pamdp train picks for its env, and says which.
    model = PATRPO(HFO)
    assert model.preset == "hfo" and model.config == PATRPOConfig.preset("hfo") and model.config.action_mask
    assert RunSpec("patrpo", HFO, 10).config().config == model.config
    model.save(tmp_path / "m.pt")
    assert PATRPO.load(tmp_path / "m.pt").preset == "hfo"  # the file keeps it
    model = PATRPO("pamdp/Platform-v0")  # the main job's preset: the tuned one with the paper's parameter noise
    assert model.preset == "platform" and model.config == dataclasses.replace(
        PATRPOConfig.preset("tuned"), init_log_std=0.0
    )
    # An explicit config is never overridden.
    model = PATRPO(HFO, PATRPOConfig.preset("paper"))
    assert model.preset is None and model.config == PATRPOConfig.preset("paper") and not model.config.action_mask


def test_a_preset_made_for_another_env_warns_and_the_run_records_it(tmp_path):
    message = (  # both ids of Half Field Offense, 1v0 and against the goalie, take it
        r"preset 'hfo' of PDQNConfig was made for pamdp/HalfFieldOffense-v0, pamdp/HalfFieldOffenseGoalie-v0, "
        r"not pamdp/Platform-v0"
    )
    with pytest.warns(UserWarning, match=message):
        config = PDQNConfig.preset("hfo", "pamdp/Platform-v0")
    assert config == PDQNConfig.preset("hfo")  # used as asked
    out = tmp_path / "run"
    argv = ["train", "pdqn", "--preset", "hfo", "--total-steps", "8", "--eval-episodes", "0", "--no-progress"]
    with pytest.warns(UserWarning, match=message), pytest.warns(UserWarning, match="makes no gradient update"):
        assert main([*argv, "--epoch-steps", "8", "--num-envs", "1", "--out", str(out)]) == 0
    run = json.loads((out / "run.json").read_text())
    assert run["preset"] == "hfo" and re.search(message, run["preset_warning"])
    # An algorithm's own presets suit any env, and an env's choice among them is no other env's.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        PDQNConfig.preset("tuned", HFO)
        algorithm_class("paddpg").config_class.preset("hausknecht_stone", "pamdp/Platform-v0")


def test_an_explicit_preset_wins_over_the_envs(tmp_path):
    cls = algorithm_class("pdqn").config_class
    _, preset, config, _ = config_of(["pdqn", "--env", HFO, "--preset", "tuned"])
    assert preset == "tuned" and config == cls.preset("tuned")
    file = tmp_path / "c.toml"
    file.write_text('preset = "paper"\n')
    _, preset, config, _ = config_of(["pdqn", "--env", HFO, "--config", str(file)])
    assert preset == "paper" and config.gamma == 0.9
    # A flag still overrides the env's preset's value.
    _, preset, config, _ = config_of(["pdqn", "--env", HFO, "--gamma", "0.5"])
    assert preset == "hfo" and config.gamma == 0.5 and config.buffer_size == 500_000
    assert RunSpec("pdqn", HFO, 1000, preset="paper").config().preset == "paper"


@pytest.mark.parametrize("env", ["CartPole-v1", None])
def test_an_env_without_a_preset_falls_back_to_the_algorithms_default(env):
    for algo, expected in (("pdqn", "tuned"), ("patrpo", "tuned"), ("hyar", "cpu"), ("paddpg", "paper")):
        assert default_preset(algorithm_class(algo).config_class, env) == expected
    if env is not None:
        assert RunSpec("pdqn", env, 10).config().preset == "tuned"


def _key_id(key):
    algo, env, match = key
    return "-".join([algo, env.split("/")[-1], *(f"{name}{'_'.join(map(str, vs))}" for name, vs in match)])


@pytest.mark.parametrize("key", list(DOMAIN_PRESETS), ids=_key_id)
def test_each_domain_preset_is_its_base_with_its_overrides(key):
    algo, env, match = key
    entry = DOMAIN_PRESETS[key]
    cls = algorithm_class(algo).config_class
    for values in zip(*(vs for _, vs in match)) if match else [()]:  # every argument value the entry names
        kwargs = dict(zip((name for name, _ in match), values))
        assert default_preset(cls, env, kwargs) == entry.name and entry.name in preset_names(cls)
    if entry.name != entry.base:  # a name of its own is one preset: no other entry's under the same name
        assert domain_presets_of(algo)[entry.name] is entry
    config = cls.preset(entry.name, env)  # a config: every value passed its check
    base = cls.preset(entry.base)
    for f in dataclasses.fields(cls):
        expected = entry.settings.get(f.name, getattr(base, f.name))
        assert getattr(config, f.name) == expected, f.name
    assert all(source for _, _, source in entry.overrides)  # every value says where it comes from
    assert entry.overrides or entry.name == entry.base  # a new name is a new set of values
    # --preset takes the name, and a run given it gets the same config.
    build_parser().parse_args(["train", algo, "--env", env, "--preset", entry.name])
    assert RunSpec(algo, env, 10, preset=entry.name).config().config == config


def test_hard_move_at_large_k_gets_the_cheaper_presets_through_the_command_line():
    # n = 8, 10: P-DQN's single pass and PASVG(0)'s Gumbel-Softmax gradient, since MP-DQN's K passes a state and
    # PASVG(0)'s K critic evaluations are out of a CPU's reach there (benchmarks/large_k_cost.md); n = 4, 6 and the
    # env's default n (4) keep MP-DQN's hard_move preset and PASVG(0)'s tuned one.
    for n in (8, 10):
        _, preset, config, _ = config_of(["pdqn", "--env", HARD_MOVE, "--env-kwargs", f'{{"n": {n}}}'])
        assert preset == "hard_move_large" and not config.multi_pass and config.hidden_sizes == (256, 256)
        _, preset, config, _ = config_of(["pasvg0", "--env", HARD_MOVE, "--env-kwargs", f'{{"n": {n}}}'])
        assert preset == "hard_move_large" and config.discrete_gradient == "gumbel"
    for argv in (["--env-kwargs", '{"n": 4}'], ["--env-kwargs", '{"n": 6}'], []):
        _, preset, config, _ = config_of(["pdqn", "--env", HARD_MOVE, *argv])
        assert preset == "hard_move" and config.multi_pass and config.hidden_sizes == (256, 256)
        _, preset, config, _ = config_of(["pasvg0", "--env", HARD_MOVE, *argv])
        assert preset == "tuned" and config.discrete_gradient == "expected"
    # A flag or --preset still wins over the entry for the env's arguments.
    argv = ["pdqn", "--env", HARD_MOVE, "--env-kwargs", '{"n": 8}']
    assert config_of([*argv, "--multi-pass", "true"]).config.multi_pass
    assert config_of([*argv, "--preset", "hard_move"]).preset == "hard_move"


def test_an_experiments_env_arguments_choose_the_preset(tmp_path):
    path = tmp_path / "e.toml"
    path.write_text(
        'seeds = [0]\nenv = "pamdp/HardMove-v0"\ntotal_steps = 1000\nenv_kwargs = { n = 8 }\n'
        '[[runs]]\nlabel = "big"\nalgo = "pdqn"\n'
        '[[runs]]\nlabel = "small"\nalgo = "pdqn"\nenv_kwargs = { n = 4 }\n'
    )
    big, small = load_experiment(path).specs()
    assert big.config().preset == "hard_move_large" and small.config().preset == "hard_move"
    suite = {s.label: s for s in load_experiment("benchmark-suite").specs(seeds=[0])}
    assert suite["P-DQN on Hard Move n=10"].config().preset == "hard_move_large"
    assert suite["MP-DQN on Hard Move n=4"].config().preset == "hard_move"


def test_an_entry_or_a_run_naming_an_argument_the_env_lacks_is_refused(monkeypatch):
    cls = algorithm_class("pdqn").config_class
    expected = r"env 'pamdp/HardMove-v0' takes no argument 'N'; expected some of max_episode_steps, n, render_mode"
    with pytest.raises(ValueError, match=expected):
        config_of(["pdqn", "--env", HARD_MOVE, "--env-kwargs", '{"N": 8}'])
    entry = DOMAIN_PRESETS["pdqn", HARD_MOVE, when(n=(8, 10))]
    monkeypatch.setitem(DOMAIN_PRESETS, ("pdqn", HARD_MOVE, when(N=(8,))), entry)
    with pytest.raises(ValueError, match=r"names env argument 'N' for 'pamdp/HardMove-v0', which takes no such"):
        default_preset(cls, HARD_MOVE, {"n": 8})
    # Two entries naming as many arguments that both fit: neither is the more specific.
    monkeypatch.delitem(DOMAIN_PRESETS, ("pdqn", HARD_MOVE, when(N=(8,))))
    monkeypatch.setitem(DOMAIN_PRESETS, ("pdqn", HARD_MOVE, when(n=(6, 8))), entry)
    with pytest.raises(ValueError, match=r"two entries for \('pdqn', 'pamdp/HardMove-v0'\) that fit .*'n': 8"):
        default_preset(cls, HARD_MOVE, {"n": 8})
    assert default_preset(cls, HARD_MOVE, {"n": 10}) == entry.name


def test_an_unknown_preset_is_refused_naming_the_valid_ones(capsys):
    cls = algorithm_class("pdqn").config_class
    with pytest.raises(ValueError, match=r"unknown preset 'hfoo' for PDQNConfig; expected one of paper, tuned, hfo"):
        cls.preset("hfoo")
    with pytest.raises(SystemExit):
        build_parser().parse_args(["train", "patrpo", "--preset", "goal"])  # another algorithm's preset
    assert "invalid choice: 'goal'" in capsys.readouterr().err
