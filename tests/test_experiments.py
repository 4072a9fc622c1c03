"""The experiment runner end to end on tiny budgets: layout, aggregation, figures, resume, failures."""

import csv
import dataclasses
import hashlib
import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from pamdp.algos.checkpoints import CHECKPOINT
from pamdp.cli import main
from pamdp.experiments import available_experiments, load_experiment
from pamdp.experiments.runner import run_lock

TINY_SETTINGS = "settings = { hidden_sizes = [16], vf_hidden_sizes = [16], batch_size = 200, num_envs = 4 }"


def write_experiment(path, extra_run=""):
    path.write_text(f"""
description = "tiny"
env = "pamdp/Platform-v0"
total_steps = 600
seeds = [0, 1]
eval_episodes = 10

[[runs]]
label = "small delta"
algo = "patrpo"
preset = "paper"
{TINY_SETTINGS}
{extra_run}
""")
    return path


def test_the_papers_experiments_are_available_with_its_settings():
    assert {"platform", "step-size", "kl-estimators", "soccer"} <= set(available_experiments())
    exp = load_experiment("step-size")
    assert exp.total_steps == 1_000_000 and exp.seeds == (0, 1, 2, 3, 4)
    deltas = sorted(dict(s.settings)["delta"] for s in exp.specs(seeds=[0]))
    assert deltas == [0.01, 0.05]
    kl = load_experiment("kl-estimators")
    assert {dict(s.settings)["kl_estimator"] for s in kl.specs()} == {"joint_sample", "chain_sample", "chain_analytic"}
    soccer = load_experiment("soccer")
    assert soccer.seeds == (0, 1, 2) and soccer.total_steps == 100 * 50_000
    with pytest.raises(ValueError, match="unknown experiment 'nope'"):
        load_experiment("nope")


def test_runs_selects_an_experiments_arms_by_label_or_directory_name(tmp_path, capsys):
    platform = load_experiment("platform")
    assert [s.label for s in platform.specs(seeds=[0], labels=["PATRPO", "PASVG_0_"])] == ["PATRPO", "PASVG(0)"]
    assert {s.seed for s in platform.specs(labels=["PADDPG"])} == {0, 1, 2, 3, 4}
    with pytest.raises(ValueError, match=r"run labels 'PPO' not in experiment 'platform'; expected .*'PADDPG'"):
        platform.specs(labels=["PATRPO", "PPO"])
    exp = write_experiment(tmp_path / "two.toml", '[[runs]]\nlabel = "other"\nalgo = "patrpo"\n' + TINY_SETTINGS)
    out = tmp_path / "results"
    assert main(["reproduce", str(exp), "--out", str(out), "--seeds", "0", "--runs", "other"]) == 0
    assert (out / "two" / "other" / "seed0" / "evaluation.json").exists()
    assert not (out / "two" / "small_delta").exists()
    assert main(["reproduce", str(exp), "--out", str(out), "--runs", "nope"]) == 2
    assert "run labels 'nope' not in experiment 'two'" in capsys.readouterr().err


def test_tiny_experiment_end_to_end(tmp_path, capsys):
    exp = write_experiment(tmp_path / "tiny.toml")
    out = tmp_path / "results"
    assert main(["reproduce", str(exp), "--out", str(out), "--workers", "2"]) == 0
    for seed in (0, 1):
        run = out / "tiny" / "small_delta" / f"seed{seed}"
        for name in ("run.json", "progress.csv", "final_model.pt", "evaluation.json"):
            assert (run / name).exists(), run / name
    for name in ("curves.png", "curves.svg", "curves.csv", "results.md"):
        assert (out / "tiny" / name).exists(), name
    assert (out / "tiny" / "curves.png").stat().st_size < 1_000_000
    with open(out / "tiny" / "curves.csv", newline="") as f:
        agg = list(csv.DictReader(f))
    # Figures and tables name an arm by its label, not by its directory's file-name-safe form.
    assert {r["setting"] for r in agg} == {"small delta"} and all(r["seeds"] == "2" for r in agg)
    svg = (out / "tiny" / "curves.svg").read_text()
    assert "small delta (2 seeds)" in svg and "small_delta" not in svg
    table = capsys.readouterr().out
    assert "| small delta | 2 |" in table
    # Each seed's greedy return is listed after the mean and std, in seed order.
    returns = [json.loads((out / "tiny" / "small_delta" / f"seed{s}" / "evaluation.json").read_text()) for s in (0, 1)]
    assert "evaluated: {:.3f}, {:.3f})".format(*(r["mean_return"] for r in returns)) in table
    # A second call skips the finished runs, and labels one recorded before run.json held labels.
    run_json = out / "tiny" / "small_delta" / "seed0" / "run.json"
    recorded = json.loads(run_json.read_text())
    assert recorded.pop("label") == "small delta"
    run_json.write_text(json.dumps(recorded))
    assert main(["reproduce", str(exp), "--out", str(out)]) == 0
    assert "already finished" in (out / "tiny" / "small_delta" / "seed0" / "stdout.log").read_text()
    assert json.loads(run_json.read_text()) == {**recorded, "label": "small delta"}
    assert not list(run_json.parent.glob(".run.json.*"))  # no temporary file left beside it
    # `pamdp plot` redraws from the directories, under the same labels.
    assert main(["plot", str(out / "tiny"), "--out", str(tmp_path / "fig")]) == 0
    assert "small delta (2 seeds)" in (tmp_path / "fig" / "curves.svg").read_text()


def test_a_failing_run_is_reported_and_the_others_finish(tmp_path, capsys):
    broken = f"""
[[runs]]
label = "broken"
algo = "patrpo"
env = "pamdp/HalfFieldOffense-v0"
env_kwargs = {{ profile = "no_such_profile" }}   # of the right type: refused by the env as the run starts
{TINY_SETTINGS}
"""
    exp = write_experiment(tmp_path / "mixed.toml", broken)
    out = tmp_path / "results"
    assert main(["reproduce", str(exp), "--out", str(out), "--seeds", "0"]) == 1
    err = capsys.readouterr().err
    assert "FAILED" in err and "no_such_profile" in err and "1 of 2 runs failed" in err
    assert (out / "mixed" / "small_delta" / "seed0" / "evaluation.json").exists()
    # An env that is not registered is refused before any run starts.
    exp.write_text(exp.read_text().replace('env = "pamdp/HalfFieldOffense-v0"', 'env = "pamdp/NoSuchEnv-v0"'))
    assert main(["reproduce", str(exp), "--out", str(tmp_path / "other"), "--seeds", "0"]) == 2
    assert "env 'pamdp/NoSuchEnv-v0' is not registered" in capsys.readouterr().err
    assert not (tmp_path / "other").exists()


def test_resume_after_a_killed_worker(tmp_path):
    exp = write_experiment(tmp_path / "tiny.toml")
    exp.write_text(exp.read_text().replace("total_steps = 600", "total_steps = 3000"))
    out = tmp_path / "results"
    cmd = [sys.executable, "-m", "pamdp.cli", "reproduce", str(exp), "--out", str(out), "--workers", "2"]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    ckpt = out / "tiny" / "small_delta" / "seed0" / "checkpoint.pt"
    deadline = time.time() + 120
    while not ckpt.exists() and time.time() < deadline:
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)  # the runner and its workers
    proc.wait()
    assert ckpt.exists()
    status = subprocess.run(cmd + ["--status"], capture_output=True, text=True, timeout=60)
    assert status.returncode == 0, status.stderr
    row0 = next(line for line in status.stdout.splitlines() if line.startswith("| small delta | 0 |"))
    assert "| partial" in row0 and "/ 3,000 |" in row0
    # seed 1 may have finished in the meantime (its process can start seconds before seed 0's on an idle machine)
    assert "tiny: 0 of 2 runs done" in status.stdout or "tiny: 1 of 2 runs done" in status.stdout, status.stdout
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    log = (out / "tiny" / "small_delta" / "seed0" / "stdout.log").read_text()
    assert "resuming" in log
    with open(out / "tiny" / "small_delta" / "seed0" / "progress.csv", newline="") as f:
        steps = [float(r["time/total_timesteps"]) for r in csv.DictReader(f)]
    assert steps == sorted(set(steps)) and steps[-1] >= 3000
    status = subprocess.run(cmd + ["--status"], capture_output=True, text=True, timeout=60)
    assert "tiny: 2 of 2 runs done, 0 partial, 0 not started" in status.stdout
    greedy = json.loads((out / "tiny" / "small_delta" / "seed0" / "evaluation.json").read_text())["mean_return"]
    assert "| small delta | 0 | done | 3,000 |" in status.stdout and f"| {greedy:.3f} |" in status.stdout


def test_status_estimates_the_training_left_from_each_runs_own_pace():
    from pamdp.experiments.status import RunStatus, format_status, remaining_seconds

    def run(label, seed, state, steps, seconds):
        pace = seconds / steps if steps else None
        return RunStatus(label, seed, "", state, steps, 1000, seconds, None, None, None, None, pace)

    statuses = [
        run("a", 0, "done", 1000, 100.0),  # 0.1 s a sample; finished, nothing left
        run("a", 1, "partial", 500, 100.0),  # 0.2 s a sample: 500 left -> 100 s
        run("a", 2, "not started", 0, 0.0),  # label a's median (0.15) x 1000 -> 150 s
        run("b", 0, "not started", 0, 0.0),  # no b has run: a's pace says nothing of b's; counted, not guessed
        run("b", 1, "not started", 0, 0.0),
    ]
    left, unknown = remaining_seconds(statuses)
    assert left == pytest.approx(250.0) and unknown == {"b": 2}
    text = format_status("x", statuses, workers=2)
    assert "x: 1 of 5 runs done, 1 partial, 3 not started; 3 min of training so far;" in text
    assert "; about 4 min of training to go" in text
    assert "(~2 min with 2 side by side)" in text
    assert "; not counted, as none of their runs has trained yet: b (2 runs)" in text


def test_status_counts_cpu_time_where_an_epoch_logged_it(tmp_path):
    """A run suspended with SIGSTOP keeps its wall clock going; its CPU time, logged since 2026-11-29, does not."""
    from pamdp.experiments.status import run_status

    exp = load_experiment(write_experiment(tmp_path / "tiny.toml"))
    spec = exp.specs(None, 1.0, None)[0]
    out = tmp_path / "run"
    out.mkdir()
    rows = [
        "time/total_timesteps,time/epoch_seconds,time/epoch_cpu_seconds",
        "200,100.0,",  # an epoch logged before CPU time was: its wall time counts
        "400,500.0,40.0",  # suspended for most of its wall time
    ]
    (out / "progress.csv").write_text("\n".join(rows) + "\n")
    status = run_status(spec, out)
    assert status.steps == 400 and status.train_seconds == pytest.approx(140.0)


def test_status_paces_a_run_by_its_last_epochs(tmp_path):
    """A run that sped up (new code, a freed core) is paced by its last RECENT_EPOCHS epochs, not its history."""
    from pamdp.experiments.status import RECENT_EPOCHS, remaining_seconds, run_status

    exp = load_experiment(write_experiment(tmp_path / "tiny.toml"))
    spec = dataclasses.replace(exp.specs(None, 1.0, None)[0], total_steps=10_000)
    out = tmp_path / "run"
    out.mkdir()
    slow, fast = 3, RECENT_EPOCHS  # epochs of 100 samples: 10 s each, then 1 s each
    rows = ["time/total_timesteps,time/epoch_cpu_seconds"]
    rows += [f"{100 * (i + 1)},10.0" for i in range(slow)]
    rows += [f"{100 * (slow + i + 1)},1.0" for i in range(fast)]
    (out / "progress.csv").write_text("\n".join(rows) + "\n")
    status = run_status(spec, out)
    assert status.steps == 800 and status.train_seconds == pytest.approx(35.0)
    assert status.seconds_per_step == pytest.approx(0.01)  # the last epochs' pace, not 35 / 800
    assert remaining_seconds([status])[0] == pytest.approx(9200 * 0.01)
    # with fewer epochs than RECENT_EPOCHS, all of them count
    (out / "progress.csv").write_text("\n".join(rows[:3]) + "\n")
    assert run_status(spec, out).seconds_per_step == pytest.approx(0.1)


def test_training_logs_the_cpu_time_of_each_epoch(tmp_path):
    from pamdp import PATRPO
    from pamdp.algos.patrpo import PATRPOConfig

    model = PATRPO("pamdp/Platform-v0", PATRPOConfig(hidden_sizes=(8,), batch_size=200, num_envs=4))
    model.learn(400, progress_bar=False, run_dir=tmp_path)
    with open(tmp_path / "progress.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 2
    for r in rows:  # one torch thread: CPU time is positive and at most the wall time (plus clock granularity)
        assert 0 < float(r["time/epoch_cpu_seconds"]) <= float(r["time/epoch_seconds"]) + 0.05


def _alive(pid: int) -> bool:
    """Whether process ``pid`` still runs: any of its threads not a zombie (ended, not yet reaped). The main thread
    of an ending process can be a zombie while its other threads, and the files they hold, are still being torn
    down."""
    try:
        tasks = os.listdir(f"/proc/{pid}/task")
    except OSError:
        return False
    for task in tasks:
        try:
            with open(f"/proc/{pid}/task/{task}/stat") as f:
                if f.read().rsplit(")", 1)[1].split()[0] != "Z":
                    return True
        except OSError:
            continue
    return False


def _two_workers(tmp_path, steps: int):
    """The tiny experiment at ``steps`` samples a run: its seeds' run directories' parent and the command that runs
    its two seeds side by side."""
    exp = write_experiment(tmp_path / "tiny.toml")
    exp.write_text(exp.read_text().replace("total_steps = 600", f"total_steps = {steps}"))
    out = tmp_path / "results"
    cmd = [sys.executable, "-m", "pamdp.cli", "reproduce", str(exp), "--out", str(out), "--workers", "2"]
    return out / "tiny" / "small_delta", cmd


@pytest.mark.skipif(not os.path.isdir("/proc/self/fd"), reason="finds the workers through /proc")
def test_workers_stop_when_their_runner_is_killed_leaving_their_runs_to_resume(tmp_path):
    runs, cmd = _two_workers(tmp_path, 20000)
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    deadline, workers = time.time() + 120, {}
    while len(workers) < 2 and time.time() < deadline:
        time.sleep(0.1)
        for seed in (0, 1):
            if seed not in workers and (runs / f"seed{seed}" / "checkpoint.pt").exists():
                pid = _writer_of(runs / f"seed{seed}" / "stdout.log")
                if pid is not None:
                    workers[seed] = pid
    assert len(workers) == 2 and proc.pid not in workers.values()
    os.kill(proc.pid, signal.SIGKILL)  # the runner alone, as `kill -9 PID` would; its workers are not signalled
    proc.wait()
    deadline = time.time() + 30
    while any(map(_alive, workers.values())) and time.time() < deadline:
        time.sleep(0.1)
    assert not any(map(_alive, workers.values())), "a worker trained on after its runner was killed"
    for seed in (0, 1):  # stopped, not finished, with a checkpoint to resume from and no lock left held
        assert not (runs / f"seed{seed}" / "evaluation.json").exists() and (runs / f"seed{seed}" / CHECKPOINT).exists()
        with run_lock(runs / f"seed{seed}"):
            pass


def _writer_of(log) -> int | None:
    """The process that holds ``log`` open (a worker writing its run's log)."""
    for fd_dir in (f"/proc/{pid}/fd" for pid in os.listdir("/proc") if pid.isdigit()):
        try:
            if any(os.readlink(os.path.join(fd_dir, fd)) == str(log) for fd in os.listdir(fd_dir)):
                return int(fd_dir.split("/")[2])
        except OSError:
            continue
    return None


@pytest.mark.skipif(not os.path.isdir("/proc/self/fd"), reason="finds the worker through /proc")
def test_a_killed_worker_fails_its_run_alone(tmp_path):
    runs, cmd = _two_workers(tmp_path, 3000)
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)

    deadline, victim = time.time() + 120, None
    while victim is None and time.time() < deadline:
        time.sleep(0.1)
        if (runs / "seed1" / "checkpoint.pt").exists():
            victim = _writer_of(runs / "seed1" / "stdout.log")
    assert victim is not None and victim != proc.pid
    os.kill(victim, signal.SIGKILL)
    _, err = proc.communicate(timeout=300)
    assert proc.returncode == 1, err
    assert "FAILED" in err and "seed1" in err and "1 of 2 runs failed" in err
    assert (runs / "seed0" / "evaluation.json").exists()  # the run beside it finished
    assert not (runs / "seed1" / "evaluation.json").exists()
    again = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert again.returncode == 0, again.stderr
    assert "resuming" in (runs / "seed1" / "stdout.log").read_text()


def test_greedy_evaluations_get_their_own_figure(tmp_path):
    from pamdp.experiments.plots import GREEDY_METRIC, aggregate
    from pamdp.experiments.report import write_report

    header = "time/total_timesteps,charts/episodic_return,eval/mean_return\n"
    evals = {0: [0.2, 0.6], 1: [0.4, 1.0]}  # every second epoch of four
    for seed, (e1, e2) in evals.items():
        run = tmp_path / "exp" / "with_eval" / f"seed{seed}"
        run.mkdir(parents=True)
        rows = [f"{1000 * (i + 1)},{0.1 * i},{v}" for i, v in enumerate(["", e1, "", e2])]
        (run / "progress.csv").write_text(header + "\n".join(rows) + "\n")
    plain = tmp_path / "exp" / "without" / "seed0"
    plain.mkdir(parents=True)
    (plain / "progress.csv").write_text("time/total_timesteps,charts/episodic_return\n1000,0.1\n2000,0.2\n")

    agg = aggregate(sorted((tmp_path / "exp" / "with_eval").iterdir()), GREEDY_METRIC)
    assert agg["mean"][1] == pytest.approx(0.3) and agg["mean"][3] == pytest.approx(0.8)
    assert agg["std"][3] == pytest.approx(0.2) and all(map(lambda v: v != v, agg["mean"][[0, 2]]))  # NaN
    report = write_report([tmp_path / "exp"], tmp_path / "fig")
    assert report["greedy_png"].exists() and report["greedy_svg"].exists()
    assert "without" not in report["greedy_svg"].read_text() and "with_eval" in report["greedy_svg"].read_text()


def test_training_success_rates_get_their_own_figure_under_either_name(tmp_path):
    from pamdp.experiments.plots import SUCCESS_METRIC, aggregate
    from pamdp.experiments.report import write_report

    # soccer's runs on disk logged the rate as charts/goal_rate; runs since as charts/success_rate
    for name, column in (("soccer", "charts/goal_rate"), ("goal", "charts/success_rate")):
        header = f"time/total_timesteps,charts/episodic_return,{column}\n"
        for seed, rates in {0: ["", 0.5, 0.7], 1: ["", 0.3, 0.9]}.items():  # the first epoch predates the column
            run = tmp_path / "exp" / name / f"seed{seed}"
            run.mkdir(parents=True)
            rows = [f"{1000 * (i + 1)},{0.1 * i},{v}" for i, v in enumerate(rates)]
            (run / "progress.csv").write_text(header + "\n".join(rows) + "\n")
        agg = aggregate(sorted((tmp_path / "exp" / name).iterdir()), SUCCESS_METRIC)
        assert agg["mean"][1:] == pytest.approx([0.4, 0.8]) and agg["std"][2] == pytest.approx(0.1)
    report = write_report([tmp_path / "exp"], tmp_path / "fig")
    svg = report["success_svg"].read_text()
    assert report["success_png"].exists() and "success rate" in svg and "soccer" in svg and "goal" in svg
    assert "greedy_png" not in report and "greedy_success_png" not in report
    plain = tmp_path / "platform" / "PATRPO" / "seed0"
    plain.mkdir(parents=True)
    (plain / "progress.csv").write_text("time/total_timesteps,charts/episodic_return\n1000,0.1\n2000,0.2\n")
    assert "success_png" not in write_report([tmp_path / "platform"], tmp_path / "fig2")


def test_an_arm_still_training_keeps_its_finished_seeds_curves(tmp_path):
    from pamdp.experiments.plots import aggregate, results_table
    from pamdp.experiments.report import write_report

    returns = {0: [0.1, 0.5, 0.9], 1: [0.3, 0.7, 1.3], 2: [0.0]}  # seed 2 has just started
    for seed, values in returns.items():
        run = tmp_path / "exp" / "arm" / f"seed{seed}"
        run.mkdir(parents=True)
        rows = "\n".join(f"{1000 * (i + 1)},{v}" for i, v in enumerate(values))
        (run / "progress.csv").write_text("time/total_timesteps,charts/episodic_return\n" + rows + "\n")
    runs = sorted((tmp_path / "exp" / "arm").iterdir())
    agg = aggregate(runs)
    assert agg["epoch"].tolist() == [1, 2, 3] and agg["seeds"].tolist() == [3, 2, 2]
    assert agg["mean"] == pytest.approx([0.4 / 3, 0.6, 1.1]) and agg["std"][2] == pytest.approx(0.2)
    assert agg["steps"].tolist() == [1000, 2000, 3000]
    # each seed's own last epoch: (0.9 + 1.3 + 0.0) / 3, with the epochs it stands on
    row = results_table({"arm": runs}).splitlines()[2]
    assert f"| {2.2 / 3:.3f} +- {np.std([0.9, 1.3, 0.0]):.3f} (epochs 3, 3, 1) |" in row
    assert "arm (3 seeds, 2 past epoch 1)" in write_report([tmp_path / "exp"], tmp_path / "fig")["svg"].read_text()


def test_curves_are_drawn_over_epochs_as_the_paper_unless_epoch_sizes_differ(tmp_path):
    from pamdp.experiments.plots import aggregate, x_axis
    from pamdp.experiments.report import write_report

    def runs(name, steps):
        run = tmp_path / name / "seed0"
        run.mkdir(parents=True)
        rows = "\n".join(f"{s},{0.1 * i}" for i, s in enumerate(steps))
        (run / "progress.csv").write_text("time/total_timesteps,charts/episodic_return\n" + rows + "\n")
        return aggregate([run])

    on_policy = runs("a", [10_000, 20_000, 30_000])
    off_policy = runs("b", [10_008, 20_016, 30_000])  # epochs end on the first whole batch past 10 000
    small = runs("c", [5_000, 10_000, 15_000])
    label, xs = x_axis({"a": on_policy, "b": off_policy})
    assert label == "training epochs (10,000 samples each)"
    assert xs["a"].tolist() == [1.0, 2.0, 3.0] and xs["b"].tolist() == [1.0, 2.0, 3.0]
    label, xs = x_axis({"a": on_policy, "c": small})
    assert label == "environment samples (millions)" and xs["c"].tolist() == [0.005, 0.01, 0.015]
    assert x_axis({"a": on_policy, "c": small}, "epochs")[0] == "training epochs (5,000 to 10,000 samples each)"
    with pytest.raises(ValueError, match="x axis 'steps'; expected one of auto, epochs, samples"):
        x_axis({"a": on_policy}, "steps")
    svg = write_report([tmp_path / "a", tmp_path / "b"], tmp_path / "fig")["svg"].read_text()
    assert "training epochs" in svg
    svg = write_report([tmp_path / "a", tmp_path / "b"], tmp_path / "fig", x="samples")["svg"].read_text()
    assert "environment samples" in svg


def test_status_paces_an_off_policy_run_by_its_epochs_after_warm_up(tmp_path):
    """Epochs filling the replay buffer (no updates) take a second where the rest take a minute: they are no pace."""
    from pamdp.experiments.status import remaining_seconds, run_status

    exp = load_experiment(write_experiment(tmp_path / "tiny.toml"))
    spec = dataclasses.replace(exp.specs(None, 1.0, None)[0], total_steps=100_000)
    out = tmp_path / "run"
    out.mkdir()
    rows = ["time/total_timesteps,time/epoch_cpu_seconds,train/updates"]
    rows += [f"{10_000 * (i + 1)},1.0,0" for i in range(3)]  # warm-up
    rows += ["40000,30.0,5000"]  # warm-up ends mid-epoch: half the updates of a full epoch
    rows += [f"{10_000 * (i + 5)},60.0,10000" for i in range(2)]
    (out / "progress.csv").write_text("\n".join(rows) + "\n")
    status = run_status(spec, out)
    assert status.seconds_per_step == pytest.approx(60.0 / 10_000)  # not (3 + 30 + 120) / 60 000
    assert remaining_seconds([status])[0] == pytest.approx(40_000 * 60.0 / 10_000)
    (out / "progress.csv").write_text("\n".join(rows[:4]) + "\n")  # warm-up only: no pace to go by yet
    assert run_status(spec, out).seconds_per_step is None
    assert remaining_seconds([run_status(spec, out)])[1] == {"small delta": 1}


def test_runs_give_their_own_env_budget_and_evaluation_interval(tmp_path):
    path = tmp_path / "suite.toml"
    path.write_text("""
seeds = [0, 1]
eval_every = 3
[[runs]]
label = "a on Goal"
algo = "pdqn"
env = "pamdp/Goal-v0"
total_steps = 3e5
[[runs]]
label = "b on Hard Move n=6"
algo = "patrpo"
env = "pamdp/HardMove-v0"
env_kwargs = { n = 6 }
total_steps = 1_000_000
eval_every = 2
""")
    exp = load_experiment(path)
    specs = exp.specs(scale=0.01)
    assert [(s.env, s.total_steps, s.eval_every, s.seed) for s in specs] == [
        ("pamdp/Goal-v0", 3_000, 3, 0),
        ("pamdp/Goal-v0", 3_000, 3, 1),
        ("pamdp/HardMove-v0", 10_000, 2, 0),
        ("pamdp/HardMove-v0", 10_000, 2, 1),
    ]
    assert dict(specs[2].env_kwargs) == {"n": 6}
    # An experiment-wide budget is every run's that gives none; a run's own wins.
    text = path.read_text().replace("seeds", "total_steps = 50\nenv = 'pamdp/Platform-v0'\nseeds", 1)
    path.write_text(text.replace("total_steps = 3e5\n", "").replace('env = "pamdp/Goal-v0"\n', ""))
    assert [(s.env, s.total_steps) for s in load_experiment(path).specs(seeds=[0])] == [
        ("pamdp/Platform-v0", 50),
        ("pamdp/HardMove-v0", 1_000_000),
    ]


@pytest.mark.parametrize(
    "change, message",
    [
        (("total_steps = 3e5\n", ""), r"run 0 \('a'\) has no total_steps, nor has the file"),
        (('env = "x"\n', ""), r"run 0 \('a'\) has no env, nor has the file"),
        (("total_steps = 3e5", "total_steps = 0.5"), r"runs\[0\].total_steps = 0.5; expected a whole number of steps"),
        (("total_steps = 3e5", "total_steps = 3e5\neval_every = -1"), r"runs\[0\].eval_every = -1; expected an int"),
    ],
)
def test_bad_run_budgets_are_refused_naming_the_run(tmp_path, change, message):
    path = tmp_path / "bad.toml"
    text = 'seeds = [0]\n[[runs]]\nlabel = "a"\nalgo = "pdqn"\nenv = "x"\ntotal_steps = 3e5\n'
    path.write_text(text.replace(*change))
    with pytest.raises(ValueError, match=message):
        load_experiment(path)


def test_the_benchmark_suite_is_hyars_table_at_its_budgets():
    exp = load_experiment("benchmark-suite")
    budgets = {"Platform": 200_000, "Goal": 300_000, "Hard Goal": 300_000, "Catch Point": 1_000_000}
    budgets.update({f"Hard Move n={n}": 1_000_000 for n in (4, 6, 8, 10)})  # ../shared/specs/benchmarks.md
    specs = exp.specs()
    assert len(exp.seeds) >= 5 and exp.eval_episodes == 1000  # HyAR's 5 runs a cell (issue 44)
    large = {"Hard Move n=6", "Hard Move n=8", "Hard Move n=10"}  # P-DQN's single pass: MP-DQN's is out of reach
    for method, domains in (
        ("MP-DQN", budgets.keys() - large),
        ("P-DQN", large),
        ("HyAR-TD3", budgets),
        ("PATRPO", budgets),
        ("Hybrid SAC", budgets.keys() - {"Hard Move n=10"}),  # its critics diverged at n=8: the config says why
    ):
        mine = {s.label.split(" on ")[1]: s for s in specs if s.label.startswith(method + " on ")}
        assert {d: s.total_steps for d, s in mine.items()} == {d: budgets[d] for d in domains}
        assert all(s.eval_every >= 1 for s in mine.values())
    hard_move = {dict(s.env_kwargs)["n"] for s in specs if s.env == "pamdp/HardMove-v0"}
    assert hard_move == {4, 6, 8, 10}
    assert all(s.config()[2].multi_pass == s.label.startswith("MP-DQN") for s in specs if s.algo == "pdqn")


def _suite_run(root, label, env, seed, env_kwargs=None, evaluation=None, greedy=None, total_steps=None):
    run = root / label.replace(" ", "_") / f"seed{seed}"
    run.mkdir(parents=True)
    recorded = {"label": label, "algo": "x", "env": env, "env_kwargs": env_kwargs or {}}
    (run / "run.json").write_text(json.dumps(recorded | ({"total_steps": total_steps} if total_steps else {})))
    column = "eval/mean_return" if env == "pamdp/Platform-v0" else "eval/success_rate"
    rows = "".join(f"{10_000 * (i + 1)},0.0,{v}\n" for i, v in enumerate(greedy or [""]))
    (run / "progress.csv").write_text(f"time/total_timesteps,charts/episodic_return,{column}\n{rows}")
    if evaluation is not None:
        (run / "evaluation.json").write_text(json.dumps({"mean_return": 0.0, **evaluation}))


def test_the_suite_table_puts_each_domains_runs_beside_hyars_numbers(tmp_path):
    from pamdp.experiments.report import write_report

    root = tmp_path / "benchmark-suite"
    for seed, rate in enumerate((0.5, 0.7, 0.9)):
        _suite_run(root, "MP-DQN on Goal", "pamdp/Goal-v0", seed, evaluation={"success_rate": rate})
    _suite_run(root, "MP-DQN on Platform", "pamdp/Platform-v0", 0, evaluation={"mean_return": 0.96})
    _suite_run(root, "MP-DQN on Platform", "pamdp/Platform-v0", 1, evaluation={"goal_rate": 1.0, "mean_return": 0.9})
    # a run still training: its last greedy evaluation; another domain's n tells Hard Move's rows apart
    _suite_run(
        root, "PATRPO on Hard Move n=8", "pamdp/HardMove-v0", 0, {"n": 8}, greedy=[0.1, "", 0.4], total_steps=60_000
    )
    _suite_run(root, "PATRPO on Goal", "pamdp/Goal-v0", 0)  # nothing evaluated yet
    report = write_report([root], tmp_path / "fig")
    lines = report["suite"].read_text().splitlines()
    assert lines[0] == "| domain | pamdp MP-DQN | pamdp PATRPO | HyAR's HyAR-TD3 | HyAR's PDQN | HyAR's HPPO |"
    rows = {line.split(" | ")[0][2:]: line.split(" | ")[1:] for line in lines[2:10]}
    assert list(rows) == ["Platform", "Goal", "Hard Goal", "Catch Point"] + [f"Hard Move n={n}" for n in (4, 6, 8, 10)]
    goal_std = np.std([0.5, 0.7, 0.9])
    assert rows["Goal"][:2] == [f"0.70 +- {goal_std:.2f} (3 seeds)", "-"]
    assert rows["Goal"][2:] == ["0.78 +- 0.03", "0.70 +- 0.07", "0.0 |"]
    assert rows["Platform"][0] == "0.93 +- 0.03 (2 seeds)"  # the return, not the old success key
    assert rows["Hard Move n=8"][:2] == ["-", "0.40 +- 0.00 (1 seed, 1 partial*)"]
    assert rows["Hard Move n=10"][:2] == ["-", "-"] and rows["Hard Move n=10"][2] == "0.75 +- 0.05"
    # a figure for the domain whose run logged greedy evaluations during training, none for those that logged none
    assert report["domain-hard-move-n8_png"].exists() and "domain-hard-move-n8_svg" in report
    assert not any(key.startswith(("domain-goal", "domain-platform")) for key in report)
    other = tmp_path / "other"
    _suite_run(other, "MP-DQN on CartPole", "CartPole-v1", 0, evaluation={"success_rate": 1.0})
    _suite_run(other, "MP-DQN on Hard Move n=5", "pamdp/HardMove-v0", 0, {"n": 5}, evaluation={"success_rate": 1.0})
    assert "suite" not in write_report([other], tmp_path / "fig2")


def test_an_archive_of_earlier_suite_runs_fills_the_table_where_no_run_at_hand_replaces_it(tmp_path):
    """Runs lost with a machine come back from the suite-finals.json an earlier plot wrote: the table counts an
    archived seed unless a run at hand has the same domain, method and seed, and the new file holds both."""
    from pamdp.experiments.report import write_report

    lost = tmp_path / "lost" / "benchmark-suite"
    for seed, rate in enumerate((0.2, 0.4, 0.6)):
        _suite_run(lost, "MP-DQN on Goal", "pamdp/Goal-v0", seed, evaluation={"success_rate": rate})
    archive = write_report([lost], tmp_path / "fig0")["suite_finals"]
    now = tmp_path / "now" / "benchmark-suite"
    _suite_run(now, "MP-DQN on Goal", "pamdp/Goal-v0", 1, evaluation={"success_rate": 0.9})  # seed 1 again
    _suite_run(now, "PATRPO on Catch Point", "pamdp/CatchPoint-v0", 0, evaluation={"success_rate": 0.8})
    report = write_report([now], tmp_path / "fig", suite_archive=archive)
    rows = {line.split(" | ")[0][2:]: line.split(" | ")[1:3] for line in report["suite"].read_text().splitlines()[2:10]}
    assert rows["Goal"] == [f"{np.mean([0.2, 0.9, 0.6]):.2f} +- {np.std([0.2, 0.9, 0.6]):.2f} (3 seeds)", "-"]
    assert rows["Catch Point"] == ["-", "0.80 +- 0.00 (1 seed)"]
    merged = json.loads(report["suite_finals"].read_text())
    goal = {e["seed"]: (e["value"], e["source"]) for e in merged if e["domain"] == "Goal"}
    # the sources name where each run lies under its runs' root, never the machine's own path
    assert goal == {s: (v, f"benchmark-suite/MP-DQN_on_Goal/seed{s}") for s, v in enumerate((0.2, 0.9, 0.6))}
    assert write_report([now], tmp_path / "fig2")["suite"].read_text().count("(1 seed)") == 2  # no archive


@pytest.mark.parametrize(
    "entries, message",
    [
        ({"domain": "Goal"}, "a dict; expected a list of entries"),
        ([{"domain": "Goal", "method": "MP-DQN", "seed": 0, "value": 0.5}], r"entry 0: \['domain'.*expected an object"),
        ([{"domain": "Gol", "method": "M", "seed": 0, "value": 0.5, "final": True, "source": ""}], "domain = 'Gol'"),
        ([{"domain": "Goal", "method": "M", "seed": 0, "value": "0.5", "final": True, "source": ""}], "value = '0.5'"),
        ([{"domain": "Goal", "method": "M", "seed": True, "value": 0.5, "final": True, "source": ""}], "seed = True"),
    ],
)
def test_a_bad_suite_archive_is_refused_with_the_entry_and_what_was_expected(tmp_path, capsys, entries, message):
    from pamdp.cli import main

    runs = tmp_path / "runs" / "benchmark-suite"
    _suite_run(runs, "MP-DQN on Goal", "pamdp/Goal-v0", 0, evaluation={"success_rate": 0.5})
    archive = tmp_path / "finals.json"
    archive.write_text(json.dumps(entries))
    assert main(["plot", str(runs), "--out", str(tmp_path / "fig"), "--suite-archive", str(archive)]) == 2
    assert re.search(f"suite archive {re.escape(str(archive))}.*{message}", capsys.readouterr().err)
    assert not (tmp_path / "fig").exists()  # refused before anything was written


def _recorded_suite_run(root, label, env, seed, value, total_steps, preset="tuned", env_kwargs=None, **settings):
    """A finished suite run whose run.json records its budget, preset and settings, as pamdp train writes it."""
    run = root / label.replace(" ", "_") / f"seed{seed}"
    _suite_run(root, label, env, seed, env_kwargs, evaluation={"success_rate": value, "mean_return": value})
    recorded = json.loads((run / "run.json").read_text())
    recorded.update(total_steps=total_steps, preset=preset, config={"seed": seed, "delta": 0.01, **settings})
    (run / "run.json").write_text(json.dumps(recorded))
    return run


def test_the_suite_table_counts_as_seeds_only_runs_of_one_budget_and_settings(tmp_path):
    """Issue 46: a smoke test at another budget, or a run of another preset or setting, is a row of its own, never a
    seed of the full runs (nor does it replace a full run's figure of the same seed)."""
    from pamdp.experiments.report import write_report

    full, smoke = tmp_path / "full" / "benchmark-suite", tmp_path / "smoke" / "benchmark-suite"
    for seed, value in enumerate((1.0, 0.9, 0.8)):
        _recorded_suite_run(full, "PATRPO on Platform", "pamdp/Platform-v0", seed, value, 200_000)
    _recorded_suite_run(smoke, "PATRPO on Platform", "pamdp/Platform-v0", 0, 0.29, 2_000)
    _recorded_suite_run(tmp_path / "paper", "PATRPO on Platform", "pamdp/Platform-v0", 1, 0.5, 200_000, "paper")
    _recorded_suite_run(tmp_path / "delta", "PATRPO on Platform", "pamdp/Platform-v0", 2, 0.7, 200_000, delta=0.05)
    report = write_report([full, smoke, tmp_path / "paper", tmp_path / "delta"], tmp_path / "fig")
    table = [line for line in report["suite"].read_text().splitlines() if line.startswith("| ")]
    rows = {line.split(" | ")[0][2:]: line.split(" | ")[1] for line in table[1:]}
    assert rows["Platform"] == f"0.90 +- {np.std([1.0, 0.9, 0.8]):.2f} (3 seeds)"
    assert rows["Platform: 2,000 steps"] == "0.29 +- 0.00 (1 seed)"
    assert rows["Platform: 200,000 steps, preset paper"] == "0.50 +- 0.00 (1 seed)"
    digest = [label for label in rows if "settings" in label]
    assert len(digest) == 1 and rows[digest[0]] == "0.70 +- 0.00 (1 seed)"
    assert list(rows).index("Goal") == 1 + 3  # the other settings' rows follow their domain's
    assert len(json.loads(report["suite_finals"].read_text())) == 6  # every run kept, none overwritten
    # results.md groups the runs alike: the two tables agree on what a seed of a setting is
    groups = [line.split(" | ")[:3] for line in report["table"].read_text().splitlines()[2:]]
    assert sorted(seeds for _, seeds, _ in groups) == ["1", "1", "1", "3"]
    full = next(greedy for _, seeds, greedy in groups if seeds == "3")
    assert full.startswith(f"0.900 +- {np.std([1.0, 0.9, 0.8]):.3f} (3 evaluated")
    assert [name for name, _, _ in groups if "2,000 steps" in name] == ["| PATRPO on Platform (2,000 steps)"]


def test_a_plot_computes_each_runs_setting_once(tmp_path, monkeypatch):
    """The groups, the suite's table and the runs' summaries all need each run's setting (a digest of its settings
    with the defaults filled in by the algorithm's config): it is computed once per run."""
    from pamdp.experiments import plots
    from pamdp.experiments.report import write_report

    calls, setting_of = [], plots.setting_of
    monkeypatch.setattr(plots, "setting_of", lambda recorded: calls.append(1) or setting_of(recorded))
    root = tmp_path / "benchmark-suite"
    for seed in range(3):
        _recorded_suite_run(root, "PATRPO on Platform", "pamdp/Platform-v0", seed, 0.9, 200_000)
    report = write_report([root], tmp_path / "fig")
    assert len(calls) == 3
    assert "| Platform | PATRPO | 3 | 0.900 [0.900, 0.900] |" in report["stats"].read_text()


def test_the_suite_table_takes_hard_move_without_n_as_its_default_n(tmp_path):
    from pamdp.experiments.report import write_report

    root = tmp_path / "benchmark-suite"
    _suite_run(root, "PATRPO on Hard Move", "pamdp/HardMove-v0", 0, evaluation={"success_rate": 0.8})  # no n given
    _suite_run(root, "PATRPO on Hard Move n=6", "pamdp/HardMove-v0", 0, {"n": 6}, evaluation={"success_rate": 0.6})
    lines = write_report([root], tmp_path / "fig")["suite"].read_text().splitlines()
    rows = {line.split(" | ")[0][2:]: line.split(" | ")[1:3] for line in lines[2:10]}
    assert lines[0].startswith("| domain | pamdp PATRPO on Hard Move | pamdp PATRPO |")
    assert rows["Hard Move n=4"] == ["0.80 +- 0.00 (1 seed)", "-"]
    assert rows["Hard Move n=6"] == ["-", "0.60 +- 0.00 (1 seed)"]


def test_the_suite_tables_method_labels_are_not_cut(tmp_path):
    from pamdp.experiments.report import write_report

    root = tmp_path / "mine"
    label = "PATRPO (trust region on KL) on Goal"
    _suite_run(root, label, "pamdp/Goal-v0", 0, evaluation={"success_rate": 0.5})
    _suite_run(root, "a run on its own", "pamdp/Goal-v0", 0, evaluation={"success_rate": 0.25})
    head = write_report([root], tmp_path / "fig")["suite"].read_text().splitlines()[0]
    assert head.startswith("| domain | pamdp PATRPO (trust region on KL) | pamdp a run on its own | HyAR's")


def test_the_committed_suite_table_is_the_one_its_archive_gives():
    from pamdp.experiments.suite import load_finals, suite_table

    results = Path(__file__).resolve().parents[1] / "docs" / "results" / "benchmark-suite"
    table = suite_table(load_finals(results / "suite-finals.json"))
    assert (results / "suite.md").read_text() == table + "\n"


def test_a_run_recorded_before_a_setting_existed_is_a_seed_of_one_recorded_after():
    from pamdp.algos.patrpo import PATRPOConfig
    from pamdp.experiments.plots import setting_of

    now = {**PATRPOConfig.preset("tuned").to_dict(), "seed": 1}
    before = {k: v for k, v in now.items() if k != "device"}  # written before the device setting was added
    run = {"algo": "patrpo", "total_steps": 1000, "preset": "tuned"}
    assert setting_of({**run, "config": before}) == setting_of({**run, "config": {**now, "seed": 2}})
    assert setting_of({**run, "config": before}) != setting_of({**run, "config": {**now, "delta": 0.5}})
    # the digest is made of the settings that differ from the defaults, the tuned preset's here, so that adding a
    # setting later leaves every recorded digest as it was
    tuned = {"delta": 0.02, "gae_lambda": 0.97, "batch_size": 5000, "init_log_std": -0.5, "entropy_coef": 0.01}
    text = json.dumps(["patrpo", {**tuned, "fvp_subsample": 0.2}], sort_keys=True)
    assert setting_of({**run, "config": now})["settings"] == hashlib.sha256(text.encode()).hexdigest()[:8]


def test_the_report_table_counts_each_seeds_gradient_updates_and_flags_an_untrained_arm(tmp_path, capsys):
    """The arm of a budget below its warm-up made no update: its row says so, where its returns alone look fine."""
    from pamdp.cli import main

    updates = {"trained": {0: [0, 24, 25], 1: [0, 25, 25]}, "warm-up only": {0: [0, 0, 0]}, "old": {0: None}}
    for arm, seeds in updates.items():
        for seed, counts in seeds.items():
            run = tmp_path / "exp" / arm / f"seed{seed}"
            run.mkdir(parents=True)
            if counts is None:  # a run logged before the count was
                rows = "time/total_timesteps,charts/episodic_return\n1000,0.5\n"
            else:
                rows = "time/total_timesteps,charts/episodic_return,train/updates\n" + "".join(
                    f"{1000 * (i + 1)},0.5,{n}\n" for i, n in enumerate(counts)
                )
            (run / "progress.csv").write_text(rows)
    assert main(["plot", str(tmp_path / "exp"), "--out", str(tmp_path / "fig")]) == 0
    table = {line.split(" | ")[0][2:]: line.split(" | ")[-1] for line in capsys.readouterr().out.splitlines()[2:5]}
    assert table == {"trained": "49, 50 |", "warm-up only": "0 (untrained) |", "old": "- |"}


def test_runs_whose_summaries_were_kept_are_not_trained_again(tmp_path, capsys):
    """A run tree lost with its machine: ``--recorded`` finds its committed summary, checks that it is of the same
    settings, seed and budget, and neither trains it again nor counts it as owed."""
    exp = write_experiment(tmp_path / "tiny.toml")
    out, kept = tmp_path / "results", tmp_path / "kept"
    assert main(["reproduce", str(exp), "--out", str(out), "--seeds", "0,1"]) == 0
    assert main(["summarize", str(out / "tiny"), "--out", str(kept)]) == 0
    finals = {
        s: json.loads((out / "tiny" / "small_delta" / f"seed{s}" / "evaluation.json").read_text()) for s in (0, 1)
    }
    lost = tmp_path / "lost"
    (out / "tiny").rename(lost)  # the machine goes, the summaries stay
    capsys.readouterr()
    assert main(["reproduce", str(exp), "--out", str(out), "--seeds", "0-2", "--recorded", str(kept), "--status"]) == 0
    status = capsys.readouterr().out
    for seed in (0, 1):
        assert f"| small delta | {seed} | recorded | 600 |" in status
        assert f"| {finals[seed]['mean_return']:.3f} |" in status  # the final greedy return, from the summary
    assert "| small delta | 2 | not started |" in status
    assert "tiny: 2 of 3 runs done (2 recorded in kept summaries" in status and "1 not started" in status
    assert main(["reproduce", str(exp), "--out", str(out), "--seeds", "0-2", "--recorded", str(kept)]) == 0
    assert "2 runs recorded" in capsys.readouterr().err
    assert sorted(p.name for p in (out / "tiny" / "small_delta").iterdir()) == ["seed2"]  # only the one owed
    # Another setting (a budget of 800) is not what the summaries record: each is named, and its run trains.
    exp.write_text(exp.read_text().replace("total_steps = 600", "total_steps = 800"))
    assert main(["reproduce", str(exp), "--out", str(tmp_path / "again"), "--seeds", "0", "--recorded", str(kept)]) == 0
    err = capsys.readouterr().err
    assert "seed0.json is not this run (budget: 600 in the summary, 800 asked): it trains" in err
    assert (tmp_path / "again" / "tiny" / "small_delta" / "seed0" / "evaluation.json").exists()
    exp.write_text(exp.read_text().replace("total_steps = 800", "total_steps = 600").replace("[16]", "[24]"))
    assert main(["reproduce", str(exp), "--out", str(out), "--seeds", "0", "--recorded", str(kept), "--status"]) == 0
    assert "seed0.json is not this run (settings digest: " in capsys.readouterr().err
    assert main(["reproduce", str(exp), "--out", str(out), "--recorded", str(tmp_path / "nowhere"), "--status"]) == 2
    err = capsys.readouterr().err
    assert f"--recorded {tmp_path / 'nowhere'}: not a directory; expected one of run summaries" in err


def test_a_runs_warnings_are_kept_in_its_log_and_name_it_where_shown(tmp_path):
    """A warning raised while a run trains (here: a budget below learning_starts, which trains nothing) is written
    to the run's stdout.log, which stays with it, and the one shown names the run, as runs side by side share a
    terminal."""
    from pamdp.experiments.runner import RunSpec, run_all

    settings = (("num_envs", 2), ("learning_starts", 1000), ("hidden_sizes", (8,)))
    spec = RunSpec("pdqn", "pamdp/Platform-v0", 40, seed=3, settings=settings, eval_episodes=1, label="too short")
    with pytest.warns(UserWarning, match=r"^too short, seed 3: total_timesteps = 40 makes no gradient update"):
        (outcome,) = run_all([(spec, str(tmp_path / "run"))], workers=1, log=lambda msg: None)
    assert outcome.error is None
    log = (tmp_path / "run" / "stdout.log").read_text()
    assert "UserWarning: total_timesteps = 40 makes no gradient update" in log
