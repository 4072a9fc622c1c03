"""Callbacks of ``learn`` and the Weights & Biases tracker (issue 47): each hook runs when the module says, a stop
leaves a checkpoint that resumes, the ready-made callbacks save, evaluate and stop where an independent count of the
run's epochs says they must, and the tracker logs what ``progress.csv`` holds."""

from __future__ import annotations

import json
import struct
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import ENV, module_bytes, progress_rows, small_config

from pamdp.algos import ALGORITHMS, algorithm_class, load_model
from pamdp.algos.checkpoints import CHECKPOINT
from pamdp.callbacks import (
    BaseCallback,
    CallbackList,
    CheckpointCallback,
    EvalCallback,
    StopTrainingOnRewardThreshold,
    WandbCallback,
)
from pamdp.cli import main
from pamdp.evaluation import evaluate

OBS = np.random.default_rng(0).uniform(0, 1, size=(16, 9)).astype(np.float32)  # Platform's observations: 9 numbers


def patrpo(**extra):
    cls = algorithm_class("patrpo")
    return cls(ENV, small_config(cls, **extra))  # 100-sample epochs over 4 copies


class Recorder(BaseCallback):
    """Writes ``(name, hook, epoch)`` of every hook into a shared list; stops at epoch ``stop_at`` (by its return)."""

    def __init__(self, name: str, log: list, stop_at: int | None = None):
        super().__init__()
        self.name, self.log, self.stop_at = name, log, stop_at
        self.stats: list[dict] = []
        self.actions: dict[int, tuple] = {}  # num_timesteps -> the greedy actions on OBS then

    def on_training_start(self):
        self.log.append((self.name, "start", self.model.epoch))

    def on_epoch(self, stats):
        self.log.append((self.name, "epoch", self.model.epoch))
        self.stats.append(dict(stats))
        self.actions[self.num_timesteps] = self.model.predict(OBS)
        return False if self.model.epoch == self.stop_at else None

    def on_evaluation(self, result):
        self.log.append((self.name, "evaluation", self.model.epoch))

    def on_training_end(self):
        self.log.append((self.name, "end", self.model.epoch))


def same_actions(a, b) -> bool:
    return np.array_equal(a[0], b[0]) and all(np.array_equal(x, y) for x, y in zip(a[1], b[1]))


def crossings(ends: list[int], every: int, start: int = 0) -> list[int]:
    """The epoch ends (environment steps) at which a multiple of ``every`` was passed since the epoch before."""
    return [t for before, t in zip([start, *ends], ends) if any(before < k * every <= t for k in range(1, t + 1))]


def test_a_list_calls_each_hook_on_every_callback_in_order_and_a_stop_lets_the_others_see_that_epoch():
    log: list = []
    first, second = Recorder("a", log, stop_at=3), Recorder("b", log)
    model = patrpo().learn(10_000, progress_bar=False, eval_every=2, eval_episodes=2, callback=[first, second])
    assert model.epoch == 3
    epoch = [(n, "epoch", e) for e in (1, 2, 3) for n in "ab"]
    evaluation = [("a", "evaluation", 2), ("b", "evaluation", 2)]
    start, end = [("a", "start", 0), ("b", "start", 0)], [("a", "end", 3), ("b", "end", 3)]
    assert log == [*start, *epoch[:2], *evaluation, *epoch[2:], *end]
    nested: list = []
    patrpo().learn(200, progress_bar=False, callback=CallbackList([Recorder("x", nested), [Recorder("y", nested)]]))
    assert [n for n, hook, _ in nested if hook == "epoch"] == ["x", "y", "x", "y"]


def test_a_plain_function_still_gets_the_model_and_the_logged_figures_and_stops_it(tmp_path):
    seen = []

    def function(model, stats):
        seen.append((model.num_timesteps, dict(stats)))
        return model.epoch < 2

    model = patrpo().learn(10_000, progress_bar=False, run_dir=tmp_path, callback=function)
    rows = progress_rows(tmp_path)
    assert model.epoch == 2 and [t for t, _ in seen] == [int(float(r["time/total_timesteps"])) for r in rows]
    assert [set(s) for _, s in seen] == [set(r) for r in rows]


@pytest.mark.parametrize("algo", list(ALGORITHMS))
def test_a_stop_returns_at_that_epoch_with_a_checkpoint_that_resumes(algo, tmp_path):
    """``checkpoint_every`` 10 would write none in two epochs: the stop writes the model as it stopped."""
    cls = algorithm_class(algo)
    log: list = []
    recorder = Recorder("r", log, stop_at=2)
    model = cls(ENV, small_config(cls))
    model.learn(100_000, progress_bar=False, run_dir=tmp_path, checkpoint_every=10, callback=recorder)
    counted = [int(s["time/total_timesteps"]) for s in recorder.stats]
    assert model.epoch == 2 and len(counted) == 2 and model.num_timesteps == counted[-1] < 300
    assert [hook for _, hook, _ in log] == ["start", "epoch", "epoch", "end"]
    assert len(progress_rows(tmp_path)) == 2
    resumed = cls.load(tmp_path / CHECKPOINT)
    assert (resumed.num_timesteps, resumed.epoch) == (model.num_timesteps, 2)
    assert module_bytes(resumed) == module_bytes(model)
    model.save(tmp_path / "model.pt")  # the stopped model saves as any other
    assert module_bytes(cls.load(tmp_path / "model.pt")) == module_bytes(model)
    resumed.learn(100, progress_bar=False, run_dir=tmp_path)
    assert resumed.epoch == 3 and [int(float(r["time/epoch"])) for r in progress_rows(tmp_path)] == [1, 2, 3]


def test_checkpoints_are_written_at_each_multiple_and_hold_the_model_as_it_was(tmp_path):
    log: list = []
    saver, recorder = CheckpointCallback(250, tmp_path / "ck", name_prefix="pt"), Recorder("r", log)
    model = patrpo()
    model.learn(1000, progress_bar=False, callback=[saver, recorder])
    ends = [int(s["time/total_timesteps"]) for s in recorder.stats]
    expected = crossings(ends, 250)
    assert len(expected) == 4 and sorted(p.name for p in (tmp_path / "ck").iterdir()) == sorted(
        f"pt_{t}_steps.pt" for t in expected
    )
    for t in expected:
        saved = load_model(tmp_path / "ck" / f"pt_{t}_steps.pt")
        assert saved.num_timesteps == t
        assert same_actions(saved.predict(OBS), recorder.actions[t])
    assert not same_actions(load_model(tmp_path / "ck" / f"pt_{expected[0]}_steps.pt").predict(OBS), model.predict(OBS))
    # a second learn call counts on from where the first ended
    model.learn(600, progress_bar=False, callback=[saver, recorder])
    later = [int(s["time/total_timesteps"]) for s in recorder.stats][len(ends) :]
    assert [p.stem for p in saver.saved[4:]] == [f"pt_{t}_steps" for t in crossings(later, 250, start=ends[-1])]


def test_the_eval_callback_keeps_the_model_of_its_best_evaluation_and_leaves_training_as_it_was(tmp_path):
    log: list = []
    evaluator = EvalCallback(eval_freq=200, n_eval_episodes=8, best_model_save_path=tmp_path / "best", seed=7)
    recorder = Recorder("r", log)
    model = patrpo().learn(1500, progress_bar=False, run_dir=tmp_path / "run", callback=[evaluator, recorder])
    ends = [int(s["time/total_timesteps"]) for s in recorder.stats]
    assert [t for t, _ in evaluator.evaluations] == crossings(ends, 200)
    scores = [r["mean_return"] for _, r in evaluator.evaluations]
    assert len(set(scores)) > 1  # the scores differ, so which model is the best one says something
    best_step = evaluator.evaluations[int(np.argmax(scores))][0]  # the first of the best
    best = load_model(tmp_path / "best" / "best_model.pt")
    assert best.num_timesteps == best_step and same_actions(best.predict(OBS), recorder.actions[best_step])
    assert evaluate(best, episodes=8, seed=7)["mean_return"] == evaluator.best_score == max(scores)
    rows = {int(float(r["time/total_timesteps"])): r for r in progress_rows(tmp_path / "run")}
    assert {t: float(rows[t]["eval/mean_return"]) for t, _ in evaluator.evaluations} == dict(
        zip([t for t, _ in evaluator.evaluations], scores)
    )
    assert all(rows[t]["eval/mean_return"] == "" for t in ends if t not in dict(evaluator.evaluations))
    assert module_bytes(model) == module_bytes(patrpo().learn(1500, progress_bar=False))


def test_the_threshold_stops_at_the_first_epoch_whose_figure_reaches_it():
    log: list = []
    free = Recorder("free", log)
    patrpo().learn(1500, progress_bar=False, callback=free)
    returns = [s["charts/episodic_return"] for s in free.stats]
    threshold = max(returns[:3]) + 1e-9  # over the first three epochs, reached later
    first = next(i for i, r in enumerate(returns, 1) if r >= threshold)
    assert 3 < first < len(returns)
    stopped = Recorder("stopped", log)
    stop = StopTrainingOnRewardThreshold(threshold, key="charts/episodic_return")
    model = patrpo().learn(1500, progress_bar=False, callback=[stopped, stop])
    assert model.epoch == first and model.num_timesteps == int(free.stats[first - 1]["time/total_timesteps"])


def test_the_threshold_as_the_eval_callbacks_new_best_stops_at_the_first_evaluation_that_reaches_it():
    free = EvalCallback(eval_freq=100, n_eval_episodes=4)
    patrpo().learn(1200, progress_bar=False, callback=free)
    scores = [r["mean_return"] for _, r in free.evaluations]
    threshold = max(scores[:2]) + 1e-9
    first = next(i for i, s in enumerate(scores) if s >= threshold)
    assert 2 <= first < len(scores) - 1
    stop = StopTrainingOnRewardThreshold(threshold)
    stopping = EvalCallback(eval_freq=100, n_eval_episodes=4, callback_on_new_best=stop)
    model = patrpo().learn(1200, progress_bar=False, callback=stopping)
    assert len(stopping.evaluations) == first + 1 and model.num_timesteps == free.evaluations[first][0]


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: CheckpointCallback(0, "ck"), r"^save_freq = 0; expected an integer >= 1$"),
        (lambda: CheckpointCallback(2.5, "ck"), r"^save_freq = 2.5; expected an integer >= 1$"),
        (lambda: CheckpointCallback(10, 3), r"^save_path = 3; expected a path"),
        (lambda: EvalCallback(eval_freq="100"), r"^eval_freq = '100'; expected an integer >= 1$"),
        (lambda: EvalCallback(n_eval_episodes=0), r"^n_eval_episodes = 0; expected an integer >= 1$"),
        (lambda: EvalCallback(metric="return"), r"^metric = 'return'; expected one of 'mean_return', 'success_rate'$"),
        (lambda: EvalCallback(eval_env="pamdp/Nowhere-v0"), r"Nowhere"),
        (
            lambda: EvalCallback(callback_on_new_best=print),
            r"^callback_on_new_best = <built-in function print>; expected a pamdp.callbacks.BaseCallback or None$",
        ),
        (lambda: StopTrainingOnRewardThreshold("1"), r"^reward_threshold = '1'; expected a finite number$"),
        (lambda: StopTrainingOnRewardThreshold(float("nan")), r"^reward_threshold = nan; expected a finite number$"),
    ],
)
def test_bad_settings_of_a_callback_are_refused_in_one_line_naming_them(make, message):
    with pytest.raises(ValueError, match=message) as raised:
        make()
    assert "\n" not in str(raised.value)


def test_a_list_holding_something_else_is_refused_before_training():
    model = patrpo()
    for bad in ([CheckpointCallback(100, "ck"), "stop"], (3,)):
        with pytest.raises(ValueError, match=r"^callback = .*; expected a function of \(model, stats\), a pamdp"):
            model.learn(200, progress_bar=False, callback=bad)
    assert model.num_timesteps == 0


# -- Weights & Biases -----------------------------------------------------------------------------------------------
def wandb_records(wandb_dir: Path) -> dict[str, list]:
    """What an offline run wrote (its ``run-*.wandb`` file: W&B's header, then a LevelDB log of protobuf records):
    its history rows, its config and its summary updates."""
    import wandb
    from wandb.proto import wandb_internal_pb2 as pb

    wandb.teardown()  # the service writes the file: done with it once it is down
    (path,) = wandb_dir.glob("wandb/offline-run-*/run-*.wandb")
    data = path.read_bytes()
    assert data[:4] == b":W&B"
    pos, block, part, records = 7, 32768, b"", []
    while pos + 7 <= len(data):
        room = block - pos % block
        _, length, kind = struct.unpack("<IHB", data[pos : pos + 7]) if room >= 7 else (0, 0, 0)
        if length == 0 and kind == 0:  # a block's zero-padded tail
            pos += room
            continue
        part, pos = part + data[pos + 7 : pos + 7 + length], pos + 7 + length
        if kind in (1, 4):  # a record whole, or its last part
            records.append(part)
            part = b""
    out: dict[str, list] = {"history": [], "config": [], "summary": []}
    for raw in records:
        record = pb.Record()
        record.ParseFromString(raw)
        kind = record.WhichOneof("record_type")
        if kind == "history":
            out["history"].append(
                {i.key or "/".join(i.nested_key): json.loads(i.value_json) for i in record.history.item}
            )
        elif kind == "run":
            out["config"].append({i.key: json.loads(i.value_json) for i in record.run.config.update})
        elif kind == "summary":
            out["summary"].append(
                {i.key or "/".join(i.nested_key): json.loads(i.value_json) for i in record.summary.update}
            )
    return out


@pytest.fixture
def offline_wandb(tmp_path, monkeypatch):
    wandb = pytest.importorskip("wandb", reason='wandb is not installed (pip install "pamdp[wandb]")')
    monkeypatch.setenv("WANDB_MODE", "offline")
    monkeypatch.setenv("WANDB_DIR", str(tmp_path))
    monkeypatch.setenv("WANDB_SILENT", "true")
    wandb.teardown()  # wandb set up earlier in the process keeps the settings (the directory) it read then
    yield tmp_path
    wandb.teardown()


def assert_history_is_the_progress_csv(history: list[dict], run_dir: Path):
    rows = progress_rows(run_dir)
    logged = [{k: v for k, v in h.items() if not k.startswith("_")} for h in history]
    assert [h["_step"] for h in history] == [int(float(r["time/total_timesteps"])) for r in rows]
    assert [set(h) for h in logged] == [{k for k, v in r.items() if v != ""} for r in rows]
    for h, row in zip(logged, rows):
        assert h == pytest.approx({k: float(row[k]) for k in h}, rel=1e-12)


def test_wandb_logs_the_figures_of_progress_csv_with_the_eval_callbacks_and_the_config(offline_wandb, tmp_path):
    tracker = WandbCallback(project="tests", config={"note": "x"})
    evaluator = EvalCallback(eval_freq=200, n_eval_episodes=4)
    model = patrpo(seed=3)
    model.learn(600, progress_bar=False, run_dir=tmp_path / "run", callback=[tracker, evaluator])
    final = evaluate(model, episodes=5)
    tracker.finish(summary=final)
    written = wandb_records(offline_wandb)
    assert_history_is_the_progress_csv(written["history"], tmp_path / "run")
    assert any("eval/mean_return" in h for h in written["history"])  # the eval callback's, logged after the tracker
    (config,) = written["config"]
    assert config["settings"] == model.config.to_dict()
    assert {k: config[k] for k in ("algo", "env_id", "seed", "preset", "note")} == {
        "algo": "PATRPO",
        "env_id": ENV,
        "seed": 3,
        "preset": None,
        "note": "x",
    }
    summary = {k: v for update in written["summary"] for k, v in update.items()}
    assert summary["final/mean_return"] == pytest.approx(final["mean_return"], rel=1e-12)


def test_pamdp_train_wandb_logs_the_run_its_config_and_its_final_evaluation(offline_wandb, tmp_path, capsys):
    out = tmp_path / "run"
    argv = ["train", "patrpo", "--total-steps", "300", "--out", str(out), "--seed", "2", "--eval-episodes", "6"]
    tiny = ["--hidden-sizes", "16", "--vf-hidden-sizes", "16", "--batch-size", "100", "--num-envs", "4"]
    assert main([*argv, *tiny, "--no-progress", "--wandb", "--wandb-project", "tests"]) == 0, capsys.readouterr().err
    written = wandb_records(offline_wandb)
    assert_history_is_the_progress_csv(written["history"], out)
    (config,) = written["config"]
    recorded = json.loads((out / "run.json").read_text())
    assert (config["settings"], config["preset"], config["seed"]) == (recorded["config"], recorded["preset"], 2)
    assert (config["env_id"], config["total_steps"], config["run_dir"]) == (ENV, 300, str(out))
    summary = {k: v for update in written["summary"] for k, v in update.items()}
    evaluation = json.loads((out / "evaluation.json").read_text())
    assert {k: summary[f"final/{k}"] for k in ("mean_return", "std_return", "episodes")} == pytest.approx(
        {k: evaluation[k] for k in ("mean_return", "std_return", "episodes")}, rel=1e-12
    )


def test_a_wandb_that_cannot_start_is_refused_in_one_line(offline_wandb, tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("WANDB_MODE", "bogus")
    argv = ["train", "patrpo", "--total-steps", "300", "--out", str(tmp_path / "run"), "--wandb", "--no-progress"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("pamdp train: error: wandb.init failed: ") and "bogus" in err and err.count("\n") == 1


def test_train_wandb_without_wandb_installed_says_how_to_install_it_and_creates_nothing(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "wandb", None)  # import wandb: ModuleNotFoundError
    out = tmp_path / "run"
    assert main(["train", "patrpo", "--total-steps", "300", "--out", str(out), "--wandb", "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and 'pip install "pamdp[wandb]"' in err and err.startswith("pamdp train: error:")
    assert not out.exists()
    with pytest.raises(ImportError, match=r'pip install "pamdp\[wandb\]"'):
        WandbCallback()
