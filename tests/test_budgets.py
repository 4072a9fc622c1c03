"""A run trains the budget it is asked for, says how many gradient updates it made and warns when a budget cannot
train; input found bad only late (a callback, an env of another shape, a fractional episode count) is refused
before anything runs, in one line naming it (issue 46). Over every algorithm of the registry."""

from __future__ import annotations

import re
import sys
import warnings

import gymnasium
import pytest
from conftest import ENV, progress_rows, small_settings

from pamdp.algos import ALGORITHMS, algorithm_class
from pamdp.algos.checkpoints import read_checkpoint
from pamdp.cli import main
from pamdp.evaluation import evaluate


def small(algo: str, **extra):
    cls = algorithm_class(algo)
    return cls, cls.config_class.from_dict(small_settings(cls, **extra))


@pytest.mark.parametrize("algo", list(ALGORITHMS))
def test_a_budget_not_a_whole_number_of_epochs_ends_at_the_budget_and_counts_its_updates(algo, tmp_path):
    """100-sample epochs (or batches) over 4 copies: 150 steps end within a vector step of 150, not at 200."""
    cls, config = small(algo)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a budget that trains warns of nothing
        model = cls(ENV, config).learn(150, progress_bar=False, run_dir=tmp_path)
    assert 150 <= model.num_timesteps < 150 + config.num_envs
    rows = progress_rows(tmp_path)
    assert model.num_updates > 0
    assert model.num_updates == sum(int(float(row["train/updates"])) for row in rows)
    model.save(tmp_path / "m.pt")
    assert read_checkpoint(tmp_path / "m.pt")["num_updates"] == model.num_updates
    assert cls.load(tmp_path / "m.pt").num_updates == model.num_updates


OFF_POLICY = [algo for algo in ALGORITHMS if algo not in ("patrpo", "pappo")]


@pytest.mark.parametrize("algo", OFF_POLICY)
def test_a_budget_that_cannot_train_is_said_at_the_start_and_makes_no_update(algo):
    """Below the warm-up (``learning_starts``, HyAR's ``warmup_steps``: 64 here)."""
    cls, config = small(algo)
    with pytest.warns(UserWarning, match=r"total_timesteps = 50 ") as caught:
        model = cls(ENV, config).learn(50, progress_bar=False)
    name = "warmup_steps" if algo == "hyar" else "learning_starts"
    assert f"{name} = 64" in str(caught[0].message) and "makes no gradient update" in str(caught[0].message)
    assert 50 <= model.num_timesteps < 54 and model.num_updates == 0


@pytest.mark.parametrize("algo", ["patrpo", "pappo"])
def test_an_on_policy_run_trains_its_budget_exactly_even_below_one_vector_step(algo):
    """64 copies asked for 50 samples train on 50 (not on the 64 of a whole vector step), with one update; 100-sample
    batches over 4 copies asked for 150 then 37 more end at 150 and 187, whatever the autoresets."""
    cls, config = small(algo, num_envs=64)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        model = cls(ENV, config).learn(50, progress_bar=False)
    assert model.num_timesteps == 50 and model.num_updates > 0
    cls, config = small(algo)
    model = cls(ENV, config).learn(150, progress_bar=False)
    assert model.num_timesteps == 150
    assert model.learn(37, progress_bar=False).num_timesteps == 187


@pytest.mark.parametrize("algo", list(ALGORITHMS))
def test_a_callback_that_cannot_be_called_is_refused_before_training(algo):
    cls, config = small(algo)
    model = cls(ENV, config)
    with pytest.raises(ValueError, match=r"callback = 'stop'; expected a function"):
        model.learn(150, progress_bar=False, callback="stop")
    assert model.num_timesteps == 0


def test_evaluate_refuses_a_fractional_episode_count_naming_episodes():
    cls, config = small("patrpo")
    model = cls(ENV, config)
    for bad in (2.5, "3", float("nan"), True):
        with pytest.raises(ValueError, match=r"^episodes = .*; expected an integer >= 1$"):
            evaluate(model, episodes=bad)
    assert evaluate(model, episodes=2.0, num_envs=2)["episodes"] == 2


@pytest.mark.parametrize("algo", list(ALGORITHMS))
def test_loading_into_an_env_of_another_shape_is_refused_in_one_line_naming_both(algo, tmp_path):
    cls, config = small(algo)
    cls("pamdp/HardMove-v0", config).save(tmp_path / "m.pt")
    other = gymnasium.make("pamdp/HardMove-v0", n=6)
    with pytest.raises(ValueError, match=r"trained on an env of shapes .*, this env's are .*") as raised:
        cls.load(tmp_path / "m.pt", env=other)
    assert "(observation (4,), 16 actions" in str(raised.value) and "64 actions" in str(raised.value)


def test_a_file_without_its_shapes_is_refused_naming_the_network(tmp_path):
    import torch

    cls, config = small("patrpo")
    cls("pamdp/HardMove-v0", config).save(tmp_path / "m.pt")
    payload = torch.load(tmp_path / "m.pt", weights_only=False)
    del payload["shapes"]  # as written before the shapes were kept
    torch.save(payload, tmp_path / "old.pt")
    with pytest.raises(ValueError, match=r"weights do not fit this env") as raised:
        cls.load(tmp_path / "old.pt", env=gymnasium.make("pamdp/HardMove-v0", n=6))
    assert "size mismatch" not in str(raised.value)


SMALL_CLI = ["--hidden-sizes", "16", "--num-envs", "4", "--eval-episodes", "0", "--no-progress"]


def test_the_last_line_of_a_resumed_run_says_the_steps_of_this_call_and_in_all(tmp_path, capsys):
    """Batches of 100 over 4 copies: each ends at the first vector step that reaches its count (autoreset steps
    carry no sample), so a run passes its budget by less than 4 samples."""
    out = tmp_path / "run"
    argv = ["train", "patrpo", "--batch-size", "100", "--out", str(out), *SMALL_CLI]
    last_line = re.compile(r"trained (\d+) steps in \d+ s, (\d+) of (\d+) in all \((\d+) gradient updates\)")
    assert main([*argv, "--total-steps", "300"]) == 0
    now, total, budget, updates = map(int, last_line.search(capsys.readouterr().err).groups())
    assert now == total and 300 <= total < 304 and budget == 300 and updates == 3
    assert main([*argv, "--total-steps", "450"]) == 0
    err = capsys.readouterr().err
    assert f"resuming {out} at step {total:,} of 450" in err
    now, after, budget, updates = map(int, last_line.search(err).groups())
    assert now == after - total and 450 <= after < 454 and budget == 450 and updates == 5


def test_a_run_that_makes_no_update_warns_at_the_start_and_says_so_at_the_end(tmp_path, capsys):
    argv = ["train", "pdqn", "--total-steps", "40", "--out", str(tmp_path / "run"), *SMALL_CLI]
    with pytest.warns(UserWarning, match="makes no gradient update"):
        assert main([*argv, "--learning-starts", "100"]) == 0
    assert "no gradient update: untrained" in capsys.readouterr().err


def test_the_command_line_shows_a_warning_as_one_line_of_its_own_and_the_api_keeps_pythons_form(
    tmp_path, capsys, monkeypatch
):
    """Python's default ``showwarning`` writes ``warnings.formatwarning``'s text to stderr (pytest records warnings
    instead, so the test puts that default back)."""

    def shown(message, category, filename, lineno, file=None, line=None):
        sys.stderr.write(warnings.formatwarning(message, category, filename, lineno, line))

    monkeypatch.setattr(warnings, "showwarning", shown)
    argv = ["train", "pdqn", "--preset", "hfo", "--total-steps", "40", "--learning-starts", "100", *SMALL_CLI]
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        assert main([*argv, "--out", str(tmp_path / "run")]) == 0
        err = capsys.readouterr().err.splitlines()
        warned = [line for line in err if "warning" in line.lower()]
        assert len(warned) == 2 and all(line.startswith("pamdp: warning: ") for line in warned), warned
        assert "preset 'hfo' of PDQNConfig was made for" in warned[0] and "makes no gradient update" in warned[1]
        warnings.warn("from the API", UserWarning, stacklevel=1)
        assert re.search(r"^\S+\.py:\d+: UserWarning: from the API$", capsys.readouterr().err, re.M)
