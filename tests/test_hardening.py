"""Bad input of every kind gets one line ``pamdp COMMAND: error: ...`` naming the value, exit status 2, and leaves
nothing behind; no silent wrong setting, no lost or overwritten data, one writer per run directory (issue 30)."""

import csv
import errno
import json
import os
import shutil
from pathlib import Path

import gymnasium
import numpy as np
import pytest
from gymnasium import spaces

from pamdp.cli import build_parser, main

TINY = ["--hidden-sizes", "16", "--vf-hidden-sizes", "16", "--batch-size", "500", "--num-envs", "4", "--no-progress"]


def refusal(argv, capsys) -> str:
    """The one line ``main(argv)`` refuses ``argv`` with (exit status 2, whether argparse or a command refuses)."""
    capsys.readouterr()
    try:
        code = main(argv)
    except SystemExit as exc:
        code = exc.code
    err = capsys.readouterr().err
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"pamdp {argv[0]}"), err
    return lines[0]


def guarded(argv, tmp_path):
    """``argv`` with a small budget and an output in ``tmp_path`` put first (so that ``argv``'s own options win): if
    the code failed to refuse it, the command would end in seconds and write nothing outside ``tmp_path``."""
    if argv[0] == "train":
        return [*argv[:2], "--total-steps", "300", "--eval-episodes", "0", "--out", str(tmp_path / "r"), *argv[2:]]
    if argv[0] == "render":
        return [argv[0], "--out", str(tmp_path / "x.gif"), *argv[1:]]
    return argv


@pytest.fixture(scope="module")
def trained(tmp_path_factory):
    """A finished tiny PATRPO run (1 000 steps, evaluated over 10 episodes); tests that change it take a copy."""
    out = tmp_path_factory.mktemp("trained") / "run"
    argv = ["train", "patrpo", "--total-steps", "1000", "--out", str(out), "--eval-episodes", "10", *TINY]
    assert main(argv) == 0
    return out


def copy_of(run, tmp_path):
    return shutil.copytree(run, tmp_path / "copy")


# -- silent wrong settings --------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "argv, flag",
    [
        (["train", "patrpo", "--delt", "0.1"], "--delt"),
        (["train", "patrpo", "--total", "100"], "--total"),
        (["evaluate", "run", "--epi", "5"], "--epi"),
        (["reproduce", "step-size", "--stat"], "--stat"),
        (["plot", "results", "--ti", "x"], "--ti"),
        (["render", "pamdp/Platform-v0", "--se", "1"], "--se"),
    ],
)
def test_an_abbreviated_option_is_refused_not_taken_for_the_one_it_begins(argv, flag, tmp_path, capsys):
    assert f"unrecognized arguments: {flag}" in refusal(guarded(argv, tmp_path), capsys)


@pytest.mark.parametrize(
    "argv, value",
    [
        (["train", "patrpo", "--hidden-sizes", "64,,32"], "'64,,32'"),
        (["train", "patrpo", "--hidden-sizes", "64,"], "'64,'"),
        (["train", "pdqn", "--hidden-sizes", ",128"], "',128'"),
        (["reproduce", "platform", "--runs", "PATRPO,,PADDPG", "--status"], "'PATRPO,,PADDPG'"),
    ],
)
def test_a_comma_list_with_an_empty_item_is_refused_not_shortened(argv, value, tmp_path, capsys):
    assert f"{value} has an empty item" in refusal(guarded(argv, tmp_path), capsys)


@pytest.mark.parametrize(
    "argv, expected",
    [
        (["train", "patrpo", "--eval-episodes", "-1"], "--eval-episodes: '-1'; expected an integer >= 0"),
        (["train", "patrpo", "--eval-every", "-2"], "--eval-every: '-2'; expected an integer >= 0"),
        (["train", "patrpo", "--seed", "-1"], "--seed: '-1'; expected a seed from 0"),
        (["train", "patrpo", "--total-steps", "0"], "--total-steps: '0'; expected a number of steps from 1 to"),
        (["train", "patrpo", "--total-steps", "2e12"], "--total-steps: '2e12'; expected a number of steps from 1"),
        (["train", "patrpo", "--total-steps", "1.5"], "--total-steps: '1.5'; expected a number of steps"),
        (["evaluate", "run", "--episodes", "0"], "--episodes: '0'; expected an integer >= 1"),
        (["evaluate", "run", "--seed", "-3"], "--seed: '-3'; expected a seed"),
        (["render", "pamdp/Platform-v0", "--seed", "x"], "--seed: 'x'; expected a seed"),
        (["reproduce", "step-size", "--scale", "nan"], "--scale: 'nan'; expected a positive finite number"),
        (["reproduce", "step-size", "--scale", "inf"], "--scale: 'inf'; expected a positive finite number"),
        (["reproduce", "step-size", "--scale", "0"], "--scale: '0'; expected a positive finite number"),
    ],
)
def test_a_count_out_of_its_range_is_refused_naming_the_flag(argv, expected, tmp_path, capsys):
    assert expected in refusal(guarded(argv, tmp_path), capsys)


def test_whole_numbers_may_be_written_as_floats():
    args = build_parser().parse_args(["train", "patrpo", "--total-steps", "1e6", "--batch-size", "5e3"])
    assert args.total_steps == 1_000_000 and args.cfg_batch_size == 5000
    assert build_parser().parse_args(["train", "patrpo", "--total-steps", "2_000"]).total_steps == 2000


def test_stochastic_evaluation_is_labelled_stochastic(trained, capsys):
    capsys.readouterr()
    assert main(["evaluate", str(trained), "--episodes", "4", "--stochastic"]) == 0
    assert capsys.readouterr().out.startswith("stochastic return over 4 episodes")
    assert main(["evaluate", str(trained), "--episodes", "4", "--stochastic", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["policy"] == "stochastic"
    assert main(["evaluate", str(trained), "--episodes", "4"]) == 0
    assert capsys.readouterr().out.startswith("greedy return over 4 episodes")


def test_evaluate_seeds_its_env_as_train_does_unless_told(trained, capsys):
    """docs/cli.md: ``--seed`` defaults to 10000 + the training seed (0 here), the seed of train's own evaluation."""
    results = []
    for extra in ([], ["--seed", "10000"], ["--seed", "3"]):
        capsys.readouterr()
        assert main(["evaluate", str(trained), "--episodes", "6", "--stochastic", "--json", *extra]) == 0
        results.append(json.loads(capsys.readouterr().out))
    assert results[0] == results[1] and results[0] != results[2]


@pytest.mark.parametrize(
    "kwargs, expected",
    [
        ({"deterministic": "no"}, "argument deterministic = 'no'; expected bool"),
        ({"profile": 2016}, "argument profile = 2016; expected str"),
        (
            {"deterministc": True},
            "takes no argument 'deterministc'; expected some of body_reset, defense_npcs, deterministic",
        ),
    ],
)
def test_env_arguments_of_the_wrong_name_or_type_are_refused(kwargs, expected, tmp_path, capsys):
    out = tmp_path / "runs" / "hfo"
    argv = ["train", "patrpo", "--env", "pamdp/HalfFieldOffense-v0", "--env-kwargs", json.dumps(kwargs)]
    assert expected in refusal(
        [*argv, "--out", str(out), "--total-steps", "300", "--eval-episodes", "0", *TINY], capsys
    )
    assert not (tmp_path / "runs").exists()


def test_env_arguments_are_checked_for_a_model_made_in_python_too():
    from pamdp.algos.pdqn import PDQN

    with pytest.raises(ValueError, match="argument deterministic = 'no'; expected bool"):
        PDQN("pamdp/HalfFieldOffense-v0", env_kwargs={"deterministic": "no"})


def write_run(path, algo, env, returns, label=None):
    """A run directory as pamdp train leaves it: run.json and one progress.csv row per epoch."""
    path.mkdir(parents=True)
    info = {"algo": algo, "env": env, "env_kwargs": {}, "config": {}}
    if label:
        info["label"] = label
    (path / "run.json").write_text(json.dumps(info))
    with open(path / "progress.csv", "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["time/total_timesteps", "charts/episodic_return"])
        writer.writerows([1000 * (i + 1), r] for i, r in enumerate(returns))


def test_plot_averages_only_runs_of_one_algorithm_and_env(tmp_path):
    from pamdp.experiments.plots import find_groups
    from pamdp.experiments.report import write_report

    write_run(tmp_path / "runs" / "a", "patrpo", "pamdp/Platform-v0", [0.2, 0.4])
    write_run(tmp_path / "runs" / "b", "pdqn", "pamdp/HalfFieldOffense-v0", [0.8, 1.0])
    write_run(tmp_path / "runs" / "c", "patrpo", "pamdp/Platform-v0", [0.4, 0.6])
    groups = find_groups([tmp_path / "runs"])
    assert sorted(groups) == ["runs (patrpo on pamdp/Platform-v0)", "runs (pdqn on pamdp/HalfFieldOffense-v0)"]
    report = write_report([tmp_path / "runs"], tmp_path / "report")
    with open(report["csv"], newline="") as f:
        means = {(r["setting"], r["epoch"]): (float(r["mean_return"]), r["seeds"]) for r in csv.DictReader(f)}
    assert means[("runs (patrpo on pamdp/Platform-v0)", "2")] == (pytest.approx(0.5), "2")
    assert means[("runs (pdqn on pamdp/HalfFieldOffense-v0)", "2")] == (pytest.approx(1.0), "1")
    # Runs labelled alike by an experiment are kept apart the same way.
    write_run(tmp_path / "exp" / "x" / "seed0", "patrpo", "pamdp/Platform-v0", [0.1], label="A")
    write_run(tmp_path / "exp" / "y" / "seed0", "paddpg", "pamdp/Platform-v0", [0.3], label="A")
    assert sorted(find_groups([tmp_path / "exp"])) == [
        "A (paddpg on pamdp/Platform-v0)",
        "A (patrpo on pamdp/Platform-v0)",
    ]


def test_plot_follows_symbolic_links_and_counts_each_run_once(tmp_path):
    """Runs gathered from several places by links (a directory of runs, or one run) are read, a run reached twice
    is one seed, and a link back up the tree does not loop."""
    from pamdp.experiments.plots import find_groups

    write_run(tmp_path / "elsewhere" / "A" / "seed0", "patrpo", "pamdp/Platform-v0", [0.1])
    write_run(tmp_path / "elsewhere" / "A" / "seed1", "patrpo", "pamdp/Platform-v0", [0.3])
    write_run(tmp_path / "other" / "seed2", "patrpo", "pamdp/Platform-v0", [0.5])
    tree = tmp_path / "tree"
    (tree / "A").mkdir(parents=True)
    (tree / "A" / "seed0").symlink_to(tmp_path / "elsewhere" / "A" / "seed0")
    (tree / "A" / "seed1").symlink_to(tmp_path / "elsewhere" / "A" / "seed1")
    (tree / "A" / "seed2").symlink_to(tmp_path / "other" / "seed2")
    (tree / "A" / "again").symlink_to(tmp_path / "elsewhere" / "A" / "seed0")
    (tree / "A" / "loop").symlink_to(tree)
    groups = find_groups([tree])
    assert list(groups) == ["A"]
    assert sorted(os.path.realpath(p) for p in groups["A"]) == sorted(
        os.path.realpath(tmp_path / d) for d in ("elsewhere/A/seed0", "elsewhere/A/seed1", "other/seed2")
    )


@pytest.mark.parametrize("x", ["epochs", "samples"])
def test_a_curve_of_one_epoch_shows_as_a_point_on_ticks_that_do_not_overlap(x, tmp_path):
    """A reproduce at ``--scale 0.01`` trains one epoch per run: one point per curve."""
    from pamdp.experiments.plots import draw_curves, find_groups

    write_run(tmp_path / "A" / "seed0", "patrpo", "pamdp/Platform-v0", [0.5])
    write_run(tmp_path / "B" / "seed0", "paddpg", "pamdp/Platform-v0", [0.25])
    fig = draw_curves(find_groups([tmp_path]), x=x)
    ax = fig.axes[0]
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    left, right = ax.get_xlim()
    ticks = [t for t in ax.get_xticklabels() if t.get_text() and left <= t.get_position()[0] <= right]
    boxes = sorted((t.get_window_extent(renderer) for t in ticks), key=lambda b: b.x0)
    assert len(boxes) >= 2 and all(a.x1 < b.x0 for a, b in zip(boxes, boxes[1:])), [t.get_text() for t in ticks]
    assert all(line.get_marker() == "o" and left < line.get_xdata()[0] < right for line in ax.lines)


def test_ctrl_c_in_reproduce_says_how_to_go_on_instead_of_a_traceback(tmp_path, monkeypatch, capsys):
    import pamdp.experiments.runner as runner

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(runner, "run_all", interrupted)
    assert main(["reproduce", "step-size", "--seeds", "0", "--out", str(tmp_path)]) == 130
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1] == "pamdp reproduce: interrupted; run the same command to resume (finished runs are skipped)"


# -- lost or overwritten data -----------------------------------------------------------------------------------


def test_a_second_writer_of_a_run_directory_is_refused(tmp_path, capsys):
    from pamdp.experiments.runner import run_lock

    out = tmp_path / "run"
    with run_lock(out):  # another process training there: its lock is held
        message = refusal(["train", "patrpo", "--total-steps", "300", "--out", str(out), *TINY], capsys)
        assert f"{out} is in use: pamdp process {os.getpid()} on" in message
    assert "names seed 0 twice" in refusal(["reproduce", "step-size", "--seeds", "0,0"], capsys)


def test_a_finished_run_is_not_retrained_to_a_smaller_budget(trained, tmp_path, capsys):
    run = copy_of(trained, tmp_path)
    evaluation = (run / "evaluation.json").read_bytes()
    argv = ["train", "patrpo", "--total-steps", "500", "--out", str(run), "--eval-episodes", "3", *TINY]
    assert "more than the 500 asked; give its own budget of 1,000 steps to resume or skip it" in refusal(argv, capsys)
    assert (run / "evaluation.json").read_bytes() == evaluation


def test_a_log_without_a_checkpoint_is_not_replaced_by_a_new_run(trained, tmp_path, capsys):
    run = copy_of(trained, tmp_path)
    (run / "checkpoint.pt").unlink()
    (run / "final_model.pt").unlink()
    log = (run / "progress.csv").read_bytes()
    argv = ["train", "patrpo", "--total-steps", "1000", "--out", str(run), *TINY]
    assert "holds a progress.csv of 2 epochs but no checkpoint to resume from" in refusal(argv, capsys)
    assert (run / "progress.csv").read_bytes() == log
    other = tmp_path / "notes"
    other.mkdir()
    (other / "notes.txt").write_text("mine")
    argv = ["train", "patrpo", "--total-steps", "1000", "--out", str(other), *TINY]
    assert "holds notes.txt and no pamdp checkpoint" in refusal(argv, capsys)
    assert sorted(os.listdir(other)) == ["notes.txt"]


def test_a_kill_before_the_first_checkpoint_starts_again_keeping_its_log(trained, tmp_path):
    run = copy_of(trained, tmp_path)
    argv = ["train", "patrpo", "--total-steps", "1000", "--out", str(run), "--eval-episodes", "3", *TINY]
    cut_short = []
    for _ in range(2):  # killed twice in the same window: both logs are kept
        for name in ("checkpoint.pt", "final_model.pt", "evaluation.json"):
            (run / name).unlink()
        lines = (run / "progress.csv").read_text().splitlines(keepends=True)
        (run / "progress.csv").write_text("".join(lines[:2]))  # the header and epoch 1, killed before its checkpoint
        cut_short.append((run / "progress.csv").read_bytes())
        assert main(argv) == 0
    assert (run / "progress.csv.cut-short").read_bytes() == cut_short[0]
    assert (run / "progress.csv.cut-short.2").read_bytes() == cut_short[1]
    assert (run / "tb.cut-short").is_dir() == (run / "tb.cut-short.2").is_dir() == (run / "tb").is_dir()
    with open(run / "progress.csv", newline="") as f:
        assert [int(float(r["time/epoch"])) for r in csv.DictReader(f)] == [1, 2]
    assert (run / "evaluation.json").exists()


# -- errors naming the value, and nothing left behind ------------------------------------------------------------


@pytest.mark.parametrize(
    "extra, expected",
    [
        (["--env", "NoSuchEnv-v0"], "env 'NoSuchEnv-v0' is not registered"),
        (["--env-kwargs", '{"nope": 1}'], "env 'pamdp/Platform-v0' takes no argument 'nope'"),
        (["--out", "{file}/run"], "{file}/run: Not a directory"),
        (["--out", "{file}"], "{file} is a file; expected a run directory"),
        (["--out", "/sys/pamdp-test-run/r"], "/sys/pamdp-test-run: "),  # sysfs takes no new directory
    ],
)
def test_a_refused_run_leaves_nothing_behind(extra, expected, tmp_path, capsys):
    (tmp_path / "file").write_text("")
    extra = [e.replace("{file}", str(tmp_path / "file")) for e in extra]
    argv = ["train", "patrpo", "--total-steps", "300", "--out", str(tmp_path / "runs" / "r"), *extra, *TINY]
    assert expected.replace("{file}", str(tmp_path / "file")) in refusal(argv, capsys)
    assert sorted(os.listdir(tmp_path)) == ["file"]


@pytest.mark.parametrize("command", ["reproduce", "plot"])
def test_an_output_directory_under_a_file_is_refused_in_one_line(command, trained, tmp_path, capsys):
    (tmp_path / "file").write_text("")
    out = str(tmp_path / "file" / "results")
    argv = ["reproduce", "step-size", "--scale", "0.0001", "--seeds", "0", "--out", out]
    assert str(tmp_path / "file") in refusal(
        argv if command == "reproduce" else ["plot", str(trained), "--out", out], capsys
    )
    assert sorted(os.listdir(tmp_path)) == ["file"]


def test_a_full_disk_is_one_line_naming_the_file(tmp_path, monkeypatch, capsys):
    import pamdp.atomic

    def full(path, text):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))

    monkeypatch.setattr(pamdp.atomic, "atomic_write_text", full)
    out = tmp_path / "run"
    message = refusal(["train", "patrpo", "--total-steps", "300", "--out", str(out), *TINY], capsys)
    assert f"{out / 'run.json'}: No space left on device" in message


def test_plot_refuses_a_progress_csv_of_other_columns(tmp_path, capsys):
    (tmp_path / "run").mkdir()
    (tmp_path / "run" / "progress.csv").write_text("step,return\n1,0.5\n")
    expected = f"{tmp_path / 'run' / 'progress.csv'} has no column 'time/total_timesteps' (columns: step, return)"
    assert expected in refusal(["plot", str(tmp_path)], capsys)


class NoFrames(gymnasium.Env):
    observation_space = spaces.Box(-1.0, 1.0, (1,), np.float32)
    action_space = spaces.Tuple((spaces.Discrete(1), spaces.Tuple((spaces.Box(-1.0, 1.0, (1,)),))))


def test_render_refuses_an_env_that_draws_no_frames(tmp_path, capsys):
    gymnasium.register("PamdpTestNoFrames-v0", entry_point=NoFrames)
    try:
        message = refusal(["render", "PamdpTestNoFrames-v0", "--out", str(tmp_path / "x.gif")], capsys)
    finally:
        del gymnasium.registry["PamdpTestNoFrames-v0"]
    assert "env 'PamdpTestNoFrames-v0' draws no frames (render modes []); expected one with 'rgb_array'" in message
    assert not (tmp_path / "x.gif").exists()


@pytest.mark.parametrize(
    "key, value, expected",
    [
        ("seeds", "[0, 0]", "seeds = [0, 0]; expected each seed once"),
        ("seeds", "[0, 'a']", "seeds = [0, 'a']; expected a list of integer seeds >= 0"),
        ("total_steps", "1e13", "total_steps = 10000000000000.0; expected a whole number of steps from 1 to 1e+12"),
        ("evaluation_episodes", "5", "evaluation_episodes = 5; expected only the keys description, env"),
    ],
)
def test_an_experiment_file_is_checked_key_by_key(key, value, expected, tmp_path, capsys):
    values = {"env": '"pamdp/Platform-v0"', "total_steps": "600", "seeds": "[0]", key: value}
    path = tmp_path / "exp.toml"
    path.write_text("".join(f"{k} = {v}\n" for k, v in values.items()) + '[[runs]]\nlabel = "A"\nalgo = "patrpo"\n')
    assert expected in refusal(["reproduce", str(path), "--out", str(tmp_path / "results")], capsys)
    assert not (tmp_path / "results").exists()


# -- misleading messages -----------------------------------------------------------------------------------------


def test_resuming_another_algorithms_run_says_so(trained, capsys):
    argv = ["train", "pdqn", "--total-steps", "1000", "--out", str(trained), "--no-progress"]
    assert f"{trained} holds a run of algorithm 'patrpo', not 'pdqn'" in refusal(argv, capsys)


def test_ctrl_c_before_the_first_checkpoint_says_there_is_nothing_to_resume(tmp_path, monkeypatch, capsys):
    from pamdp.algos.patrpo import PATRPO

    def interrupted(self, budget):
        raise KeyboardInterrupt

    monkeypatch.setattr(PATRPO, "_run_epoch", interrupted)
    assert main(["train", "patrpo", "--total-steps", "300", "--out", str(tmp_path / "run"), *TINY]) == 130
    err = capsys.readouterr().err
    assert "interrupted before the first checkpoint; nothing to resume" in err and "last checkpoint" not in err


def test_a_log_resumed_from_a_checkpoint_keeps_the_checkpoints_epoch_in_tensorboard(tmp_path):
    from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

    from pamdp.logger import Logger

    logger = Logger(tmp_path)
    for step in (100, 200, 300):  # a run killed after logging epoch 300, whose last checkpoint was at 200
        logger.record({"time/total_timesteps": step, "charts/x": step / 100}, step)
    logger.close()
    logger = Logger(tmp_path, resume_step=200)
    for step, value in ((300, 3.5), (400, 4.0)):
        logger.record({"time/total_timesteps": step, "charts/x": value}, step)
    logger.close()
    events = EventAccumulator(str(tmp_path / "tb"))
    events.Reload()
    logged = [(e.step, e.value) for e in events.Scalars("charts/x")]
    assert logged == [(100, 1.0), (200, 2.0), (300, 3.5), (400, 4.0)]
    with open(tmp_path / "progress.csv", newline="") as f:
        assert [float(r["charts/x"]) for r in csv.DictReader(f)] == [1.0, 2.0, 3.5, 4.0]  # the CSV agrees


# -- settings and the Python API ----------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "text, expected",
    [
        ('delta = "abc"', "setting 'delta' = 'abc'; expected float"),
        ("hidden_sizes = [64, 32.5]", "setting 'hidden_sizes' = [64, 32.5]; expected a list of int"),
        ('flush_denormal = "no"', "setting 'flush_denormal' = 'no'; expected bool"),
        ('seed = "abc"', "setting 'seed' = 'abc'; expected int"),
    ],
)
def test_a_setting_of_the_wrong_type_in_a_config_file_is_refused_naming_it(text, expected, tmp_path, capsys):
    path = tmp_path / "c.toml"
    path.write_text(text + "\n")
    argv = ["train", "patrpo", "--config", str(path), "--out", str(tmp_path / "run"), "--total-steps", "300"]
    assert expected in refusal([*argv, "--no-progress"], capsys)
    assert not (tmp_path / "run").exists()


@pytest.mark.parametrize(
    "values, expected",
    [
        ({"delta": "abc"}, "PATRPOConfig.delta = 'abc'; expected float"),
        ({"hidden_sizes": (64, "x")}, "PATRPOConfig.hidden_sizes = (64, 'x'); expected a list of int"),
        ({"num_envs": 2.0}, "PATRPOConfig.num_envs = 2.0; expected int"),
        ({"flush_denormal": 1}, "PATRPOConfig.flush_denormal = 1; expected bool"),
    ],
)
def test_a_config_made_in_python_checks_each_settings_type(values, expected):
    from pamdp.algos.patrpo import PATRPOConfig

    with pytest.raises(ValueError) as refused:
        PATRPOConfig(**values)
    assert str(refused.value) == expected


@pytest.fixture(scope="module")
def model():
    from pamdp.algos.patrpo import PATRPO

    return PATRPO("pamdp/Platform-v0", {"hidden_sizes": (16,), "vf_hidden_sizes": (16,), "num_envs": 2})


@pytest.mark.parametrize("steps", ["100", None, -1, 1.5, True, float("nan")])
def test_learn_refuses_a_budget_that_is_no_count(model, steps):
    with pytest.raises(ValueError) as refused:
        model.learn(steps, progress_bar=False)
    assert str(refused.value) == f"total_timesteps = {steps!r}; expected an integer >= 0"
    assert model.num_timesteps == 0


@pytest.mark.parametrize("obs", [None, "abc", [0.0, 1.0], np.zeros((2, 3, 9)), {"x": 1}])
def test_predict_refuses_what_is_no_observation(model, obs):
    with pytest.raises(ValueError, match=r"^observation .*; expected an array of shape \(9,\) or \(N, 9\)$"):
        model.predict(obs)
    with pytest.raises(ValueError, match="deterministic = 'no'; expected True or False"):
        model.predict(np.zeros(model.obs_dim), deterministic="no")


def test_a_file_that_is_no_checkpoint_is_refused_without_torchs_advice_to_run_its_code(tmp_path, capsys):
    path = tmp_path / "random.pt"
    path.write_bytes(np.random.default_rng(0).bytes(4096))
    message = refusal(["evaluate", str(path)], capsys)
    assert f"{path} is not a readable pamdp checkpoint (UnpicklingError: " in message
    assert "weights_only" not in message and "expected a file written by pamdp's save" in message


def test_the_docs_count_the_tuned_patrpo_presets_differences_as_the_code_has_them():
    import re
    from pathlib import Path

    from pamdp.algos.patrpo import PATRPOConfig

    root = Path(__file__).resolve().parents[1]
    paper, tuned = PATRPOConfig.preset("paper").to_dict(), PATRPOConfig.preset("tuned").to_dict()
    differ = sum(paper[k] != tuned[k] for k in paper)
    words = {"four": 4, "five": 5, "six": 6, "seven": 7, "eight": 8}
    readme = re.search(
        r"tuned PATRPO preset differs from the paper's in (\w+) places", (root / "README.md").read_text()
    )
    algorithms = re.search(r"`tuned` changes (\w+) settings", (root / "docs" / "algorithms.md").read_text())
    assert [words[readme.group(1)], words[algorithms.group(1)]] == [differ, differ]


def test_the_cli_docs_tables_are_generated_from_the_code():
    import subprocess
    import sys
    from pathlib import Path

    script = Path(__file__).resolve().parents[1] / "docs" / "gen_cli_tables.py"
    done = subprocess.run([sys.executable, str(script), "--check"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr


def test_the_docs_index_names_every_algorithm():
    from pathlib import Path

    from pamdp.algos import ALGORITHMS

    index = (Path(__file__).resolve().parents[1] / "docs" / "index.md").read_text()
    names = [entry.help.split(":")[0].split(" (")[0] for entry in ALGORITHMS.values()]  # "P-DQN (Xiong ..."
    assert [n for n in names if n not in index] == []


# -- issue 46: runs on other systems ----------------------------------------------------------------------------


def test_the_cli_starts_where_the_system_has_no_fcntl():
    """Windows has no ``fcntl``: the command must start (and take its lock) without it."""
    import subprocess
    import sys

    code = "import sys; sys.modules['fcntl'] = None\nfrom pamdp.cli import main\nraise SystemExit(main(['--version']))"
    done = subprocess.run([sys.executable, "-W", "ignore", "-c", code], capture_output=True, text=True)
    assert done.returncode == 0 and done.stdout.startswith("pamdp "), done.stderr


def test_a_second_process_is_refused_while_the_first_writes_and_goes_on_after_it_ends(tmp_path, capsys):
    import subprocess
    import sys

    out = tmp_path / "run"
    hold = (
        "import sys\nfrom pamdp.experiments.runner import run_lock\n"
        f"with run_lock({str(out)!r}):\n    print('held', flush=True)\n    sys.stdin.read()"
    )
    first = subprocess.Popen([sys.executable, "-c", hold], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        assert first.stdout.readline() == "held\n"
        argv = ["train", "patrpo", "--total-steps", "300", "--eval-episodes", "0", "--out", str(out), *TINY]
        message = refusal(argv, capsys)
        assert f"{out} is in use: pamdp process {first.pid} on" in message
        assert sorted(os.listdir(out)) == [".lock", ".lock-holder"]  # the refused run wrote nothing
    finally:
        first.stdin.close()
        first.wait(timeout=60)
    assert main(argv) == 0  # the first has ended: its lock went with it
    assert (out / "final_model.pt").exists()


# -- issue 46: raw tracebacks ---------------------------------------------------------------------------------


def _unwritable(tmp_path) -> str:
    """A directory this process cannot write into: a read-only one, or for root (whom modes do not stop) sysfs."""
    for where in (tmp_path / "read-only", Path("/sys")):
        if where != Path("/sys"):
            where.mkdir()
            where.chmod(0o555)
        try:
            (where / "probe").mkdir()
        except OSError:
            return str(where)
        (where / "probe").rmdir()
    pytest.skip("no unwritable directory here")


def test_reproduce_into_an_unwritable_out_is_one_line_naming_it_before_any_run(tmp_path, capsys, monkeypatch):
    from pamdp.experiments import runner

    def no_run(*args, **kwargs):
        raise AssertionError("a run was started")

    monkeypatch.setattr(runner, "run_all", no_run)
    out = os.path.join(_unwritable(tmp_path), "results")
    message = refusal(["reproduce", "platform", "--scale", "0.001", "--seeds", "0", "--out", out], capsys)
    assert f"pamdp reproduce: error: {out}: " in message and "no such directory" not in message
    assert not os.path.exists(out)


def test_render_refuses_an_env_of_another_package_naming_its_action_space(tmp_path, capsys):
    message = refusal(["render", "CartPole-v1", "--out", str(tmp_path / "x.gif")], capsys)
    expected = "env 'CartPole-v1' has the action space Discrete(2), not a parameterized one; expected a pamdp env"
    assert expected in message
    assert not (tmp_path / "x.gif").exists()


def test_a_run_resumed_with_its_envs_default_arguments_spelt_out_goes_on_and_another_shape_is_refused(tmp_path, capsys):
    """Hard Move's ``{"n": 4}`` is its default ``{}``: the same run. ``{"n": 6}`` is an env of another shape, refused in
    one line naming both (loading the model into it would be torch's "size mismatch")."""
    out = tmp_path / "run"
    argv = ["train", "patrpo", "--env", "pamdp/HardMove-v0", "--eval-episodes", "0", "--out", str(out), *TINY]
    assert main([*argv, "--total-steps", "500"]) == 0
    message = refusal([*argv, "--total-steps", "1000", "--env-kwargs", '{"n": 6}'], capsys)
    assert "env_kwargs: {} in the run, {'n': 6} asked" in message
    assert main([*argv, "--total-steps", "1000", "--env-kwargs", '{"n": 4}']) == 0
    assert "resuming" in capsys.readouterr().err
