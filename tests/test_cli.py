"""The command line: train writes a run directory, a killed run resumes, evaluate prints JSON."""

import csv
import json
import os
import signal
import subprocess
import sys
import time

import pytest

from pamdp.algos import ALGORITHMS
from pamdp.cli import main

TINY = ["--hidden-sizes", "16", "--vf-hidden-sizes", "16", "--batch-size", "500", "--num-envs", "4", "--no-progress"]


def rows(path):
    with open(path / "progress.csv", newline="") as f:
        return list(csv.DictReader(f))


def test_train_writes_run_directory_and_evaluation(tmp_path, capsys):
    out = tmp_path / "run"
    code = main(["train", "patrpo", "--total-steps", "1000", "--out", str(out), "--eval-episodes", "20", *TINY])
    assert code == 0
    for name in ("run.json", "progress.csv", "checkpoint.pt", "final_model.pt", "evaluation.json"):
        assert (out / name).exists(), name
    assert any((out / "tb").iterdir())
    assert len(rows(out)) == 2
    printed = capsys.readouterr().out
    assert "greedy return over 20 episodes" in printed
    run = json.loads((out / "run.json").read_text())
    assert run["config"]["hidden_sizes"] == [16] and run["preset"] == "platform"

    assert main(["evaluate", str(out), "--episodes", "30", "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["episodes"] == 30 and {"mean_return", "std_return"} <= set(result)

    # Asking for more steps in the same directory continues the run.
    assert main(["train", "patrpo", "--total-steps", "1500", "--out", str(out), "--eval-episodes", "0", *TINY]) == 0
    assert len(rows(out)) == 3
    # Other settings in the same directory are refused, naming what differs.
    assert main(["train", "patrpo", "--total-steps", "1500", "--out", str(out), "--delta", "0.5", *TINY]) == 2
    assert "other settings (delta: 0.02 in the run, 0.5 asked)" in capsys.readouterr().err


def test_config_file_and_flags(tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text('preset = "paper"\ndelta = 0.05\nkl_estimator = "chain_sample"\n')
    out = tmp_path / "run"
    argv = ["train", "patrpo", "--config", str(cfg), "--delta", "0.01", "--total-steps", "500", "--out", str(out)]
    assert main([*argv, "--eval-episodes", "0", *TINY]) == 0
    run = json.loads((out / "run.json").read_text())
    assert run["preset"] == "paper"
    assert run["config"]["delta"] == 0.01 and run["config"]["kl_estimator"] == "chain_sample"


def test_bad_values_give_clear_errors(tmp_path, capsys):
    assert main(["train", "patrpo", "--kl-estimator", "exact", "--out", str(tmp_path / "r")]) == 2
    assert "kl_estimator = 'exact'" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["train", "patrpo", "--batch-size", "lots"])
    assert main(["evaluate", str(tmp_path / "nothing")]) == 2
    assert "no pamdp model" in capsys.readouterr().err


@pytest.mark.parametrize(
    "argv, message",
    [
        (["reproduce", "step-size", "--seeds", "0,x", "--status"], "--seeds: '0,x'; expected comma-separated seeds"),
        (["reproduce", "step-size", "--seeds", "-1", "--status"], "--seeds: '-1'; expected comma-separated seeds"),
        (["reproduce", "step-size", "--seeds", "5-3", "--status"], "--seeds: '5-3': '5-3' is not a range first-last"),
        (["reproduce", "step-size", "--seeds", "0-2,2", "--status"], "--seeds: '0-2,2' names seed 2 twice"),
        (["reproduce", "step-size", "--seeds", "0-5000", "--status"], "'0-5000' names 5001 seeds; expected at most"),
        (["reproduce", "step-size", "--workers", "0", "--status"], "--workers: '0'; expected an integer >= 1"),
        (["train", "patrpo", "--env-kwargs", "{bad"], "--env-kwargs: '{bad' is not valid JSON"),
        (["train", "patrpo", "--env-kwargs", "[1]"], "--env-kwargs: '[1]'; expected a JSON object"),
    ],
)
def test_bad_arguments_are_refused_before_anything_runs(argv, message, capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(argv)
    assert exit_info.value.code == 2 and message in capsys.readouterr().err


def test_seeds_take_ranges_as_well_as_lists():
    from pamdp.cli import build_parser

    args = build_parser().parse_args(["reproduce", "step-size", "--seeds", "2-4,7,9-9"])
    assert args.seeds == [2, 3, 4, 7, 9]


@pytest.mark.parametrize(
    "name, text, message",
    [
        ("missing.toml", None, "config file '{path}': No such file or directory; expected a TOML or JSON file"),
        ("bad.toml", "delta = \n", "config file '{path}' is not valid TOML"),
        ("bad.json", "{", "config file '{path}' is not valid JSON"),
        ("list.json", "[1, 2]", "config file '{path}' holds a list; expected a table of settings"),
    ],
)
def test_bad_config_files_give_errors_naming_them(name, text, message, tmp_path, capsys):
    path = tmp_path / name
    if text is not None:
        path.write_text(text)
    assert main(["train", "patrpo", "--config", str(path), "--out", str(tmp_path / "run")]) == 2
    assert message.format(path=path) in capsys.readouterr().err
    assert not (tmp_path / "run").exists()


def test_killed_run_resumes_from_its_checkpoint(tmp_path):
    out = tmp_path / "run"
    cmd = [
        sys.executable,
        "-m",
        "pamdp.cli",
        "train",
        "patrpo",
        "--total-steps",
        "4000",
        "--out",
        str(out),
        "--eval-episodes",
        "0",
        *TINY,
    ]
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 120
    while not (out / "checkpoint.pt").exists() and time.time() < deadline:
        time.sleep(0.05)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert (out / "checkpoint.pt").exists() and not (out / "final_model.pt").exists()
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert "resuming" in done.stderr
    steps = [float(r["time/total_timesteps"]) for r in rows(out)]
    assert steps == sorted(steps) and len(set(steps)) == len(steps)  # one clean log, no repeated epochs
    assert steps[-1] >= 4000 and (out / "final_model.pt").exists()


def test_render_writes_a_gif(tmp_path):
    gif = tmp_path / "ep.gif"
    assert main(["render", "pamdp/Platform-v0", "--out", str(gif)]) == 0
    assert gif.read_bytes()[:6] in (b"GIF87a", b"GIF89a")


def test_soccer_evaluation_reports_its_success_rate_as_a_goal_rate(tmp_path, capsys):
    out = tmp_path / "hfo"
    argv = ["train", "patrpo", "--env", "pamdp/HalfFieldOffense-v0", "--total-steps", "500", "--out", str(out)]
    assert main([*argv, "--eval-episodes", "0", *TINY]) == 0
    assert main(["evaluate", str(out), "--episodes", "8", "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["episodes"] == 8 and 0.0 <= result["success_rate"] <= 1.0
    assert result["mean_steps_to_success"] is None or result["mean_steps_to_success"] > 0
    assert main(["evaluate", str(out), "--episodes", "8"]) == 0
    assert f"; goal rate {result['success_rate']:.3f}" in capsys.readouterr().out  # the same 8 episodes


def test_evaluation_lines_name_success_by_the_env_and_read_old_keys():
    from pamdp.cli import _format_evaluation

    base = {"episodes": 4, "mean_return": 1.0, "std_return": 0.0, "mean_length": 9.0}
    new = {**base, "success_rate": 0.75, "mean_steps_to_success": 8.0}
    assert _format_evaluation(new, env_id="pamdp/CatchPoint-v0").endswith("; success rate 0.750, 8.0 steps to success")
    assert _format_evaluation(new, env_id="pamdp/Goal-v0").endswith("; goal rate 0.750, 8.0 steps to goal")
    # an evaluation.json written before the general name, and one whose env never succeeded
    old = {**base, "goal_rate": 0.5, "mean_steps_to_goal": None}
    assert _format_evaluation(old, env_id="pamdp/HalfFieldOffense-v0").endswith(
        "(mean length 9.0 steps); goal rate 0.500"
    )
    assert "rate" not in _format_evaluation(base, env_id="pamdp/Platform-v0")


def test_config_file_preset_and_seed_with_flags(tmp_path):
    cfg = tmp_path / "c.json"
    cfg.write_text(json.dumps({"preset": "tuned", "seed": 7, "delta": 0.03}))
    out = tmp_path / "run"
    argv = ["train", "patrpo", "--config", str(cfg), "--preset", "paper", "--total-steps", "500", "--out", str(out)]
    assert main([*argv, "--eval-episodes", "0", *TINY]) == 0
    run = json.loads((out / "run.json").read_text())
    assert run["preset"] == "paper" and run["config"]["seed"] == 7 and run["config"]["delta"] == 0.03


def test_env_kwargs_reach_the_env(tmp_path):
    out = tmp_path / "hfo2016"
    argv = ["train", "patrpo", "--env", "pamdp/HalfFieldOffense-v0", "--env-kwargs", '{"profile": "hfo2016"}']
    assert main([*argv, "--total-steps", "300", "--out", str(out), "--eval-episodes", "0", *TINY]) == 0
    from pamdp.algos import load_model

    model = load_model(out)
    assert model.obs_dim == 58 and model.env_kwargs == {"profile": "hfo2016"}
    assert json.loads((out / "run.json").read_text())["env_kwargs"] == {"profile": "hfo2016"}


USER_ENV_MODULE = '''
import gymnasium
import numpy as np
from gymnasium import spaces


class Line(gymnasium.Env):
    """Reach x = 3 on [0, 10]: action 0 steps by dx in [-1, 1], action 1 jumps to a point in [0, 10]."""

    observation_space = spaces.Box(0.0, 10.0, (1,), np.float32)
    action_space = spaces.Tuple(
        (spaces.Discrete(2), spaces.Tuple((spaces.Box(-1.0, 1.0, (1,)), spaces.Box(0.0, 10.0, (1,)))))
    )

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.x = float(self.np_random.uniform(0.0, 10.0))
        return np.array([self.x], np.float32), {}

    def step(self, action):
        a, params = action
        p = float(np.asarray(params[a]).item())
        self.x = float(np.clip(self.x + p if a == 0 else p, 0.0, 10.0))
        return np.array([self.x], np.float32), -abs(self.x - 3.0), abs(self.x - 3.0) < 0.1, False, {}


gymnasium.register("PamdpTestLine-v0", entry_point=Line, max_episode_steps=10)
'''


def test_a_users_env_given_as_module_and_id_is_imported_for_training_and_for_loading(tmp_path, capsys, monkeypatch):
    (tmp_path / "pamdp_test_user_env.py").write_text(USER_ENV_MODULE)
    monkeypatch.syspath_prepend(str(tmp_path))
    out = tmp_path / "run"
    env = "pamdp_test_user_env:PamdpTestLine-v0"
    argv = ["train", "patrpo", "--env", env, "--total-steps", "600", "--out", str(out), "--eval-episodes", "5"]
    assert main([*argv, *TINY]) == 0
    assert json.loads((out / "run.json").read_text())["env"] == env
    # A fresh process knows nothing of the module: loading the model imports it again from the stored id.
    evaluated = subprocess.run(
        [sys.executable, "-m", "pamdp.cli", "evaluate", str(out), "--episodes", "5", "--json"],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "PYTHONPATH": str(tmp_path)},
    )
    assert evaluated.returncode == 0, evaluated.stderr
    assert json.loads(evaluated.stdout)["episodes"] == 5
    capsys.readouterr()
    assert main(["train", "patrpo", "--env", "no_such_module_xyz:Line-v0", "--out", str(tmp_path / "r2")]) == 2
    assert "cannot import module 'no_such_module_xyz'" in capsys.readouterr().err
    assert main(["train", "patrpo", "--env", "NoSuchEnvXyz-v0", "--out", str(tmp_path / "r3")]) == 2
    assert "env 'NoSuchEnvXyz-v0' is not registered" in capsys.readouterr().err


def test_version_is_the_installed_distributions(capsys):
    from importlib.metadata import version

    with pytest.raises(SystemExit) as exit_info:
        main(["--version"])
    assert exit_info.value.code == 0
    assert capsys.readouterr().out.strip() == f"pamdp {version('pamdp')}"


def test_train_resolves_its_config_once(tmp_path, monkeypatch):
    import pamdp.experiments.runner as runner

    calls = []
    choose = runner.choose
    monkeypatch.setattr(runner, "choose", lambda *args: calls.append(args) or choose(*args))
    argv = ["train", "patrpo", "--total-steps", "500", "--eval-episodes", "0", "--out", str(tmp_path / "run")]
    assert main([*argv, *TINY]) == 0
    assert len(calls) == 1


def test_help_lists_every_algorithm_and_every_experiment(capsys):
    """Issue 46: ``hsac`` and ``benchmark-suite`` were missing from the help, written out by hand."""
    from pamdp.experiments import available_experiments

    with pytest.raises(SystemExit):
        main(["--help"])
    top = capsys.readouterr().out
    with pytest.raises(SystemExit):
        main(["reproduce", "--help"])
    reproduce = " ".join(capsys.readouterr().out.split())  # argparse wraps the lines
    assert [name for name in ALGORITHMS if name not in top] == []
    assert [name for name in available_experiments() if name not in reproduce] == []


@pytest.mark.parametrize("env_id, fps", [("pamdp/Goal-v0", 30), ("pamdp/CatchPoint-v0", 10)])
def test_render_writes_the_gif_at_the_envs_own_frame_rate(env_id, fps, tmp_path, capsys):
    from PIL import Image

    out = tmp_path / "x.gif"
    assert main(["render", env_id, "--out", str(out)]) == 0
    assert capsys.readouterr().out.rstrip().endswith(f", {fps} frames a second)")
    with Image.open(out) as gif:
        assert abs(gif.info["duration"] - 1000 / fps) < 10  # GIFs keep hundredths of a second
