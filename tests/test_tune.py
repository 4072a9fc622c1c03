"""``pamdp tune`` (issue 47): pruning stops a trial's training, a stopped search resumes, the best settings round-trip
through the preset file that ``pamdp train --config`` reads, bad input is one line, and every search space is valid."""

import subprocess
import sys

import pytest

optuna = pytest.importorskip("optuna")

from optuna.trial import TrialState  # noqa: E402

from pamdp.algos import ALGORITHMS, algorithm_class  # noqa: E402
from pamdp.cli import _train_spec, build_parser, main  # noqa: E402
from pamdp.experiments import tune as tuning  # noqa: E402
from pamdp.experiments.tune import SEARCH_SPACES, Search, check_space, choice, load_study, log_uniform  # noqa: E402

ENV = "pamdp/CatchPoint-v0"
STEPS = 2048


@pytest.fixture
def tiny(tmp_path):
    """A PAPPO search on Catch Point whose trials train a few epochs of 512 or 1024 samples."""
    space = {
        "lr": log_uniform(1e-4, 1e-3, "step"),
        "batch_size": choice((512, 1024), "samples per epoch"),
        "minibatch_size": choice((128, 256), "samples per step"),
        "hidden_sizes": choice(((16,), (32, 32)), "layers"),
    }
    search = Search("pappo", ENV, 2, STEPS, f"sqlite:///{tmp_path / 'study.db'}", "tiny", pruner="none")
    return tuning.dataclasses.replace(search, eval_episodes=5, space=space)


class _AlwaysPrune(optuna.pruners.BasePruner):
    def prune(self, study, trial) -> bool:
        return True


def test_a_pruned_trial_stops_training_at_its_first_evaluation(tiny):
    search = tuning.dataclasses.replace(tiny, n_trials=1)
    (trial,) = tuning.tune(search, pruner=_AlwaysPrune(), log=lambda m: None).get_trials()
    assert trial.state == TrialState.PRUNED
    assert list(trial.intermediate_values) == [1]  # one evaluation reported, then stopped
    epoch = trial.user_attrs["settings"]["batch_size"]
    assert epoch <= trial.user_attrs["steps"] < min(2 * epoch, STEPS)


def test_a_stopped_search_resumes_to_its_total_keeping_the_finished_trials(tiny):
    study = tuning.tune(tiny, log=lambda m: None)
    first = study.get_trials()
    assert [t.state for t in first] == [TrialState.COMPLETE] * 2
    # a trial left running by a search killed with it: its process is gone
    gone = subprocess.Popen([sys.executable, "-c", "pass"])
    gone.wait()
    zombie = study.ask()
    zombie.set_user_attr("host", tuning.socket.gethostname())
    zombie.set_user_attr("pid", gone.pid)

    study = tuning.tune(tuning.dataclasses.replace(tiny, n_trials=3), log=lambda m: None)
    trials = study.get_trials()
    assert [(t.params, t.value, t.user_attrs) for t in trials[:2]] == [(t.params, t.value, t.user_attrs) for t in first]
    assert trials[2].state == TrialState.FAIL and "error" not in trials[2].user_attrs  # killed, not counted
    assert [t.state for t in trials[3:]] == [TrialState.COMPLETE]
    assert trials[3].params != trials[0].params and trials[3].params != trials[1].params  # new draws, not the first's


def test_workers_share_the_storage_and_start_exactly_the_trials_asked(tiny):
    study = tuning.tune(tuning.dataclasses.replace(tiny, n_trials=3), workers=2, log=lambda m: None)
    trials = study.get_trials()
    assert [t.state for t in trials] == [TrialState.COMPLETE] * 3
    assert tuning.os.getpid() not in {t.user_attrs["pid"] for t in trials}  # each in a worker process


def test_a_study_is_resumed_only_with_its_own_terms(tiny):
    load_study(tiny)
    with pytest.raises(ValueError, match="steps_per_trial: 2048 in the study, 4096 asked"):
        load_study(tuning.dataclasses.replace(tiny, steps_per_trial=4096))


def test_the_preset_file_trains_the_best_trials_settings(tiny, tmp_path):
    study = tuning.tune(tiny, log=lambda m: None)
    info = tuning.write_preset(study, tmp_path / "best.toml")
    best = max(study.get_trials(), key=lambda t: t.value)
    assert info["best_trial"] == best.number and info["complete"] == 2
    args = build_parser().parse_args(["train", "pappo", "--env", ENV, "--config", str(tmp_path / "best.toml")])
    from_file = _train_spec(args, algorithm_class("pappo")).config().config
    settings = {k: tuple(v) if isinstance(v, list) else v for k, v in best.user_attrs["settings"].items()}
    assert from_file == tiny.trial_spec(settings).config().config
    assert (tmp_path / "best.json").exists()


@pytest.mark.parametrize(
    "argv, named",
    [
        (["tune", "nope"], "'nope'"),
        (["tune", "pappo", "--trials", "0"], "'0'"),
        (["tune", "pappo", "--steps-per-trial", "100"], "100"),
        (["tune", "pappo", "--steps-per-trial", "10000", "--out", "a_file/best.toml"], "a_file"),
    ],
)
def test_bad_input_is_one_line_naming_the_value(argv, named, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "a_file").write_text("")
    try:
        code = main(argv)
    except SystemExit as exc:  # refused by the parser
        code = exc.code
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and named in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a_file"]  # nothing made


def test_without_optuna_tune_fails_at_once_naming_the_extra(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "optuna", None)
    assert main(["tune", "pappo"]) == 2
    assert capsys.readouterr().err.strip() == (
        'pamdp tune: error: pamdp tune needs optuna, which is not installed: pip install "pamdp[tune]"'
    )


@pytest.mark.parametrize("algo", list(ALGORITHMS))
def test_every_search_space_is_valid_over_every_preset_of_its_algorithm(algo):
    config_class = algorithm_class(algo).config_class
    for config in config_class.presets().values():
        check_space(SEARCH_SPACES[algo], config)


def test_a_range_the_config_refuses_is_named():
    with pytest.raises(ValueError, match=r"gamma = 1.5; expected a number in \[0, 1\]"):
        check_space({"gamma": tuning.uniform(0.9, 1.5, "too far")}, algorithm_class("pappo").config_class())
