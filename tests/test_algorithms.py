"""The contract every algorithm of the registry keeps, checked over each one (MP-DQN and Hybrid SAC's two forms too):
save -> load -> predict gives the same model and the same actions, the same seed the same weights to the bit, a
resumed run goes on from its checkpoint, ``pamdp train`` -> again -> ``pamdp evaluate`` works end to end, and a bad
setting is refused naming its value.

What one algorithm alone does is tested in its own file. A resumed run is not the uninterrupted run (docs/algorithms.md,
"Checkpoints and resuming": env states are not saved, so it starts new episodes), and that is not asserted here.
"""

from __future__ import annotations

import dataclasses
import json
import shutil

import gymnasium
import numpy as np
import pytest
import torch
from conftest import ENV, module_bytes, progress_rows, small_settings

import pamdp
from pamdp.algos import ALGORITHMS, algorithm_class, load_model
from pamdp.algos.checkpoints import CHECKPOINT, read_checkpoint
from pamdp.cli import main

STEPS = 200  # two 100-sample epochs: updates in both


@dataclasses.dataclass(frozen=True)
class Case:
    algo: str
    settings: dict = dataclasses.field(default_factory=dict)
    replay: bool = False
    """Whether it learns from a replay buffer: its checkpoint then holds the buffer (``save_replay``), and one update
    (``_update()``) from the same buffer, weights and random streams is the same update."""

    @property
    def cls(self):
        return algorithm_class(self.algo)

    def config(self, **extra):
        return self.cls.config_class.from_dict(small_settings(self.cls, **self.settings, **extra))


OFF = {"save_replay": True}
CASES = {
    "patrpo": Case("patrpo"),
    "pappo": Case("pappo"),
    "pasvg0": Case("pasvg0", OFF, replay=True),
    "paddpg": Case("paddpg", OFF, replay=True),
    "pdqn": Case("pdqn", OFF, replay=True),
    "mpdqn": Case("pdqn", {**OFF, "multi_pass": True}, replay=True),
    "hyar": Case("hyar", OFF, replay=True),
    "hsac-flat": Case("hsac", {**OFF, "form": "flat"}, replay=True),
    "hsac-hierarchical": Case("hsac", {**OFF, "form": "hierarchical"}, replay=True),
}


def test_every_registered_algorithm_has_a_case_and_is_importable_from_pamdp():
    assert {case.algo for case in CASES.values()} == set(ALGORITHMS)
    for name in ALGORITHMS:
        cls = algorithm_class(name)
        assert getattr(pamdp, cls.__name__) is cls and cls.__name__ in pamdp.__all__


@dataclasses.dataclass
class Trained:
    case: Case
    model: object
    run_dir: object
    initial: dict[str, bytes]
    final: dict[str, bytes]
    steps: int
    """The samples it took: ``STEPS`` or a few more (each epoch ends on a step of every env copy)."""


@pytest.fixture(scope="module", params=list(CASES), ids=list(CASES))
def trained(request, tmp_path_factory) -> Trained:
    """A model of each case trained ``STEPS`` samples from seed 0, with its run directory (its last checkpoint is
    the model as it ended), and its modules' bytes before and after. A test may act with the model or update it: the
    others compare with the bytes and the checkpoint."""
    case = CASES[request.param]
    run_dir = tmp_path_factory.mktemp(request.param)
    model = case.cls(ENV, case.config())
    initial = module_bytes(model)
    model.learn(STEPS, progress_bar=False, run_dir=run_dir)
    assert STEPS <= model.num_timesteps < STEPS + 2 * model.config.num_envs and model.epoch == 2
    return Trained(case, model, run_dir, initial, module_bytes(model), model.num_timesteps)


def assert_same(a, b, where="payload"):
    """``a`` and ``b`` (checkpoint payloads: nested dicts, lists, tensors, arrays, plain values) equal to the bit."""
    assert type(a) is type(b), where
    if isinstance(a, dict):
        assert a.keys() == b.keys(), where
        for key in a:
            assert_same(a[key], b[key], f"{where}.{key}")
    elif isinstance(a, (list, tuple)):
        assert len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            assert_same(x, y, f"{where}[{i}]")
    elif isinstance(a, (torch.Tensor, np.ndarray)):  # bytes: a NaN (a return not yet known) equals itself
        a, b = (x.numpy() if isinstance(x, torch.Tensor) else x for x in (a, b))
        assert a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes(), where
    elif isinstance(a, float) and np.isnan(a):
        assert np.isnan(b), where
    else:
        assert a == b, where


def assert_same_actions(first, second):
    a1, p1 = first
    a2, p2 = second
    np.testing.assert_array_equal(a1, a2)
    assert len(p1) == len(p2)
    for x, y in zip(p1, p2):
        np.testing.assert_array_equal(x, y)


def test_the_weights_learnt(trained):
    """Every saved module changes in the short run (the trained networks, their targets, the temperatures), so the
    checks below compare models that learnt, not initial weights."""
    unchanged = [name for name in trained.final if trained.final[name] == trained.initial[name]]
    assert unchanged == []


def test_save_load_predict_round_trip(trained, tmp_path):
    model, cls = trained.model, trained.case.cls
    model.save(tmp_path / "m.pt")
    for loaded in (cls.load(tmp_path / "m.pt", env=ENV), load_model(tmp_path / "m.pt")):
        assert type(loaded) is cls and loaded.config == model.config
        assert (loaded.num_timesteps, loaded.epoch) == (model.num_timesteps, model.epoch) == (trained.steps, 2)
        assert module_bytes(loaded) == module_bytes(model)
    # What the loaded model saves is what it was loaded from: optimiser states, replay, random streams, counters.
    loaded.save(tmp_path / "again.pt")
    saved = read_checkpoint(tmp_path / "m.pt")
    assert_same(saved, read_checkpoint(tmp_path / "again.pt"))
    if trained.case.replay:
        assert len(loaded.replay) == len(model.replay) == trained.steps
        model.save(tmp_path / "acting.pt", replay=False)  # a run directory's final model: for acting only
        assert len(cls.load(tmp_path / "acting.pt").replay) == 0
        assert (tmp_path / "acting.pt").stat().st_size < (tmp_path / "m.pt").stat().st_size

    obs = np.random.default_rng(0).uniform(0, 1, size=(32, model.obs_dim)).astype(np.float32)
    for deterministic in (True, False):  # sampled actions continue the same random streams
        torch.manual_seed(0)
        ours = model.predict(obs, deterministic=deterministic)
        torch.manual_seed(0)
        assert_same_actions(ours, loaded.predict(obs, deterministic=deterministic))
    if trained.case.replay:  # the same next update: the buffer and the random streams came back too
        assert model._update() == loaded._update()
        assert module_bytes(loaded) == module_bytes(model)
    env = gymnasium.make(ENV)
    o, _ = env.reset(seed=0)
    for deterministic in (True, False):  # one observation: an action the scalar env takes
        action = loaded.predict(o, deterministic=deterministic)
        assert env.action_space.contains(action)
        env.step(action)


def test_same_seed_same_weights_to_the_bit_other_seed_others(trained):
    case = trained.case
    again = case.cls(ENV, case.config()).learn(STEPS, progress_bar=False)
    assert module_bytes(again) == trained.final
    other = case.cls(ENV, case.config(seed=1)).learn(STEPS, progress_bar=False)
    assert [n for n, b in module_bytes(other).items() if b == trained.final[n]] == []


def test_greedy_evaluations_during_training_leave_the_run_as_it_was(trained):
    """An evaluation after epoch 1 plays its own env copies with its own seed: epoch 2 trains as without it, so a
    run's greedy curve can be logged without changing the run it describes."""
    case = trained.case
    evaluated = case.cls(ENV, case.config()).learn(STEPS, progress_bar=False, eval_every=1, eval_episodes=3)
    assert module_bytes(evaluated) == trained.final


def test_resumed_runs_go_on_from_the_checkpoint_alike(trained, tmp_path):
    """Loading the last checkpoint and training on continues the counters and the log; two resumptions of one
    checkpoint train alike, so a resumed run is as reproducible as one from the start."""
    resumed = []
    for i in range(2):
        run_dir = shutil.copytree(trained.run_dir, tmp_path / f"resumed{i}")
        model = trained.case.cls.load(run_dir / CHECKPOINT)
        assert (model.num_timesteps, model.epoch) == (trained.steps, 2) and module_bytes(model) == trained.final
        model.learn(100, progress_bar=False, run_dir=run_dir)
        assert trained.steps + 100 <= model.num_timesteps and model.epoch == 3
        rows = progress_rows(run_dir)
        assert [float(r["time/epoch"]) for r in rows] == [1.0, 2.0, 3.0]
        assert float(rows[1]["time/total_timesteps"]) == trained.steps
        assert float(rows[2]["time/total_timesteps"]) == model.num_timesteps
        if trained.case.replay:  # the buffer came back and goes on: the checkpoint's samples and the new ones
            assert len(model.replay) == model.num_timesteps
        resumed.append(module_bytes(model))
    assert resumed[0] == resumed[1]
    assert [n for n, b in resumed[0].items() if b == trained.final[n]] == []  # it went on learning


# Settings out of their range, each algorithm's own, and what the refusal must name (the device setting: test_device).
BAD_SETTINGS = [
    ("patrpo", {"delta": -0.1}, "delta = -0.1"),
    ("patrpo", {"kl_estimator": "exact"}, "kl_estimator = 'exact'"),
    ("patrpo", {"hidden_sizes": ()}, "hidden_sizes"),
    ("patrpo", {"gamma": float("nan")}, "gamma = nan"),
    ("patrpo", {"baseline": "zero"}, "baseline = 'zero'"),
    ("patrpo", {"fvp": "exact"}, "fvp = 'exact'"),
    ("patrpo", {"pi_c_input": "one_hot"}, "pi_c_input = 'one_hot'; expected one of 'onehot', 'state'"),
    ("patrpo", {"fvp": "gauss_newton", "kl_estimator": "joint_sample"}, "fvp = 'gauss_newton'.*joint_sample"),
    ("pappo", {"clip_range": 0.0}, "PAPPOConfig.clip_range = 0.0"),
    ("pappo", {"clip_range": 1.5}, "clip_range = 1.5"),
    ("pappo", {"n_epochs": 0}, "n_epochs = 0"),
    ("pappo", {"minibatch_size": 8192}, "minibatch_size = 8192; expected an integer in \\[1, batch_size=4096\\]"),
    ("pappo", {"lr": -1e-3}, "lr = -0.001"),
    ("pappo", {"ent_coef_d": -0.1}, "ent_coef_d = -0.1"),
    ("pappo", {"ent_coef_c": -1.0}, "ent_coef_c = -1.0"),
    ("pappo", {"vf_coef": 0.0}, "vf_coef = 0.0"),
    ("pappo", {"max_grad_norm": 0.0}, "max_grad_norm = 0.0"),
    ("pappo", {"target_kl": -0.01}, "target_kl = -0.01"),
    ("pappo", {"gae_lambda": 1.5}, "gae_lambda = 1.5"),
    ("pappo", {"gamma": float("nan")}, "gamma = nan"),
    ("pappo", {"activation": "sigmoid"}, "activation = 'sigmoid'"),
    ("pappo", {"vf_hidden_sizes": (0,)}, "vf_hidden_sizes = \\(0,\\)"),
    ("pappo", {"num_envs": 0}, "num_envs = 0"),
    ("pasvg0", {"temperature": 0.0}, "temperature = 0.0"),
    ("pasvg0", {"tau": 1.5}, "tau = 1.5"),
    ("pasvg0", {"updates_per_step": -1.0}, "updates_per_step = -1.0"),
    ("pasvg0", {"activation": "swish"}, "activation = 'swish'"),
    ("pasvg0", {"policy_lr": float("inf")}, "policy_lr = inf"),
    ("pasvg0", {"target_entropy": -0.1, "entropy_coef": 0.1}, "target_entropy = -0.1"),
    ("pasvg0", {"target_entropy": 0.5, "entropy_coef": 0.0}, "entropy_coef = 0.0"),
    ("pasvg0", {"explore_epsilon": 1.5}, "explore_epsilon = 1.5"),
    ("pasvg0", {"policy_delay": 0}, "policy_delay = 0"),
    ("pasvg0", {"discrete_gradient": "reinforce"}, "discrete_gradient = 'reinforce'"),
    ("pasvg0", {"discrete_gradient": "expected", "straight_through": False}, "straight_through = False"),
    ("paddpg", {"bound": "clip"}, "bound = 'clip'"),
    ("paddpg", {"beta": 1.5}, "beta = 1.5"),
    ("paddpg", {"epsilon_end": -0.1}, "epsilon_end = -0.1"),
    ("paddpg", {"batch_size": 0}, "batch_size = 0"),
    ("paddpg", {"hidden_sizes": (0,)}, "hidden_sizes"),
    ("pdqn", {"bound": "clip"}, "bound = 'clip'"),
    ("pdqn", {"tau_q": 0.0}, "tau_q = 0.0"),
    ("pdqn", {"tau_actor": 1.5}, "tau_actor = 1.5"),
    ("pdqn", {"epsilon_end": 1.5}, "epsilon_end = 1.5"),
    ("pdqn", {"updates_per_step": 0.0}, "updates_per_step = 0.0"),
    ("pdqn", {"beta": -0.1}, "beta = -0.1"),
    ("pdqn", {"ou_theta": 0.0}, "ou_theta = 0.0"),
    ("pdqn", {"hidden_sizes": ()}, "hidden_sizes = \\(\\)"),
    ("pdqn", {"activation": "gelu"}, "activation = 'gelu'"),
    ("hyar", {"relabel": "some"}, "relabel = 'some'"),
    ("hyar", {"lsc_percent": 0.0}, "lsc_percent = 0.0"),
    ("hyar", {"lsc_percent": 101.0}, "lsc_percent = 101.0"),
    ("hyar", {"embed_dim": 0}, "embed_dim = 0"),
    ("hyar", {"warmup_steps": 0}, "warmup_steps = 0"),
    ("hyar", {"policy_delay": 0}, "policy_delay = 0"),
    ("hyar", {"tau": 0.0}, "tau = 0.0"),
    ("hyar", {"buffer_size": 100}, "buffer_size = 100"),
    ("hyar", {"vae_hidden_sizes": ()}, "vae_hidden_sizes = \\(\\)"),
    ("hyar", {"kl_weight": -1.0}, "kl_weight = -1.0"),
    ("hyar", {"epsilon_start": 1.5}, "epsilon_start = 1.5"),
    ("hyar", {"exploration_noise_steps": -1}, "exploration_noise_steps = -1"),
    ("hyar", {"exploration_noise_start": -0.1}, "exploration_noise_start = -0.1"),
    ("hyar", {"bound": "zero"}, "bound = 'zero'"),
    ("hyar", {"lsc_remap": True}, "lsc_remap = True.*squash"),
    (
        "hyar",
        {"td3_replay": 6_000, "buffer_size": 5_000, "warmup_steps": 150},
        "td3_replay = 6000.*<= buffer_size \\(5000\\)",
    ),
    ("hyar", {"td3_replay": -1}, "td3_replay = -1"),
    ("hsac", {"form": "tree"}, "form = 'tree'; expected one of 'flat', 'hierarchical'"),
    ("hsac", {"target_entropy_d": 1.5}, "target_entropy_d = 1.5"),
    ("hsac", {"target_entropy_c": 0.7}, "target_entropy_c = 0.7; expected a number below log 2"),
    ("hsac", {"init_alpha_c": 0.0}, "init_alpha_c = 0.0"),
    ("hsac", {"alpha_lr": -1e-3}, "alpha_lr = -0.001"),
    ("hsac", {"tau": 0.0}, "tau = 0.0"),
]


@pytest.mark.parametrize("algo, settings, match", BAD_SETTINGS, ids=[f"{a}-{'-'.join(s)}" for a, s, _ in BAD_SETTINGS])
def test_a_bad_setting_is_refused_naming_the_value(algo, settings, match):
    with pytest.raises(ValueError, match=match):
        algorithm_class(algo).config_class(**settings)


def flags(settings: dict) -> list[str]:
    """``settings`` as ``pamdp train`` flags: ``{"hidden_sizes": (16,)}`` -> ``["--hidden-sizes", "16"]``."""
    out = []
    for name, value in settings.items():
        if isinstance(value, tuple):
            value = ",".join(map(str, value))
        elif isinstance(value, bool):
            value = str(value).lower()
        out += ["--" + name.replace("_", "-"), str(value)]
    return out


@pytest.mark.parametrize("case", list(CASES))
def test_cli_trains_skips_a_finished_run_resumes_and_evaluates(case, tmp_path, capsys):
    out, name, settings = tmp_path / "run", CASES[case].algo, small_settings(CASES[case].cls, **CASES[case].settings)
    argv = ["train", name, "--out", str(out), "--eval-episodes", "3", "--no-progress", *flags(settings)]
    assert main([*argv, "--total-steps", "200"]) == 0
    assert "greedy return over 3 episodes" in capsys.readouterr().out
    run = json.loads((out / "run.json").read_text())
    config = CASES[case].config().to_dict()
    assert {k: run["config"][k] for k in settings} == {k: config[k] for k in settings}  # every flag arrived
    assert run["algo"] == name and run["total_steps"] == 200 and len(progress_rows(out)) == 2
    if CASES[case].replay:  # the checkpoint keeps the buffer for resuming; the final model, for acting, does not
        assert len(load_model(out / CHECKPOINT).replay) > 0 and len(load_model(out / "final_model.pt").replay) == 0

    checkpoint, at = (out / CHECKPOINT).read_bytes(), read_checkpoint(out / CHECKPOINT)["num_timesteps"]
    assert main([*argv, "--total-steps", "200"]) == 0  # the same command: nothing left to train
    assert "already finished" in capsys.readouterr().err and (out / CHECKPOINT).read_bytes() == checkpoint

    assert main([*argv, "--total-steps", "300"]) == 0  # a larger budget: it resumes
    assert f"resuming {out} at step {at:,} of 300" in capsys.readouterr().err
    assert [float(r["time/epoch"]) for r in progress_rows(out)] == [1.0, 2.0, 3.0]

    assert main(["evaluate", str(out), "--episodes", "3", "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["episodes"] == 3 and result["policy"] == "greedy"
    assert 0.0 <= result["mean_return"] <= 1.0 and result["mean_length"] >= 1  # Platform's returns lie in [0, 1]


def test_a_model_made_on_a_users_vector_env_keeps_the_envs_own_arguments(tmp_path):
    """``gymnasium.make_vec`` records its own arguments (num_envs, vectorization_mode, ...) in the vector env's
    ``spec.kwargs`` beside the env's; a model made on such an env keeps only the env's (Hard Move's ``n``), so that
    evaluating it (which makes copies of the env) and loading it make the same env, not a TypeError."""
    from pamdp.evaluation import evaluate

    vec = gymnasium.make_vec("pamdp/HardMove-v0", num_envs=4, vectorization_mode="sync", n=6)
    model = CASES["patrpo"].cls(vec, CASES["patrpo"].config(num_envs=4))
    assert (model.env_id, model.env_kwargs) == ("pamdp/HardMove-v0", {"n": 6})
    model.learn(STEPS, progress_bar=False)
    result = evaluate(model, episodes=4, num_envs=2)
    assert result["episodes"] == 4
    model.save(tmp_path / "m.pt")
    loaded = load_model(tmp_path / "m.pt")
    assert (loaded.env_kwargs, loaded.hybrid.n_actions) == ({"n": 6}, 2**6)
