"""Starting a model from another's networks (``transfer_weights``, ``pamdp train --init-from``, an experiment's
``init_from``): Half Field Offense 1v1 extends 1v0's observation by the goalie's block, so a 1v1 model started from a
1v0 one must act, on any 1v1 observation, as the 1v0 model acts on that observation without the goalie's features."""

from __future__ import annotations

import dataclasses

import gymnasium as gym
import numpy as np
import pytest
import torch

import pamdp  # noqa: F401  (registers the envs)
from pamdp.algos import ALGORITHMS, algorithm_class
from pamdp.algos.checkpoints import transfer_weights
from pamdp.experiments import load_experiment
from pamdp.experiments.runner import _warm_start

ONE_V_ZERO, ONE_V_ONE = "pamdp/HalfFieldOffense-v0", "pamdp/HalfFieldOffenseGoalie-v0"


@pytest.fixture(scope="module")
def goalie_observations():
    """Observations of 1v1 play under random actions: the goalie's features vary."""
    env = gym.make(ONE_V_ONE)
    env.action_space.seed(3)
    obs, _ = env.reset(seed=3)
    seen = [obs]
    for _ in range(120):
        obs, _, terminated, truncated, _ = env.step(env.action_space.sample())
        seen.append(obs)
        if terminated or truncated:
            obs, _ = env.reset()
    env.close()
    return np.array(seen[::10], dtype=np.float32)


def _without_goalie(obs: np.ndarray) -> np.ndarray:
    """The 1v0 observation of the same state (the feature table of HFO's low-level set): the 58 basic features,
    then the last-action flag; the goalie's eight features and its uniform number (58-66) dropped."""
    return np.concatenate([obs[:, :58], obs[:, 67:]], axis=1)


@pytest.mark.parametrize("algo", sorted(ALGORITHMS))
def test_a_1v1_model_started_from_a_1v0_one_acts_as_it(algo, tmp_path, goalie_observations):
    cls = algorithm_class(algo)
    source = cls(ONE_V_ZERO, cls.config_class.preset("tuned" if "tuned" in cls.config_class.presets() else "paper"))
    source.save(tmp_path / "source.pt")
    model = cls(ONE_V_ONE, source.config)
    _warm_start(model, str(tmp_path / "source.pt"), log=lambda msg: None)
    k_new, p_new = model.predict(goalie_observations, deterministic=True)[0], model.predict(goalie_observations)[1]
    k_old, p_old = source.predict(_without_goalie(goalie_observations), deterministic=True)
    np.testing.assert_array_equal(k_new, k_old)
    for new, old in zip(p_new, p_old):
        np.testing.assert_allclose(new, old, rtol=1e-4, atol=1e-3)  # float32 sums in another order


def test_refused_sources_name_what_differs(tmp_path):
    patrpo = algorithm_class("patrpo")
    platform = patrpo("pamdp/Platform-v0")
    platform.save(tmp_path / "platform.pt")
    model = patrpo(ONE_V_ONE)
    with pytest.raises(ValueError, match=r"parameter counts \[1, 1, 1\].*\[2, 1, 2\]"):
        transfer_weights(model, tmp_path / "platform.pt", [None] * 68)
    pappo = algorithm_class("pappo")(ONE_V_ZERO)
    pappo.save(tmp_path / "pappo.pt")
    with pytest.raises(ValueError, match="holds a PAPPO model; expected a PATRPO one"):
        transfer_weights(model, tmp_path / "pappo.pt")
    source = patrpo(ONE_V_ZERO)
    source.save(tmp_path / "source.pt")
    before = {k: v.clone() for k, v in model.policy.state_dict().items()}
    with pytest.raises(ValueError, match="expected 68 entries, each an index below 59 or None"):
        transfer_weights(model, tmp_path / "source.pt", [0] * 67)
    with pytest.raises(ValueError, match="expected 68 entries"):
        transfer_weights(model, tmp_path / "source.pt", [59] * 68)
    assert all((before[k] == v).all() for k, v in model.policy.state_dict().items())  # refused before any change


def test_an_experiment_starts_only_from_an_earlier_run(tmp_path):
    body = """
description = "curriculum"
env = "pamdp/Platform-v0"
total_steps = 1000
seeds = [0, 1]
[[runs]]
label = "second"
algo = "patrpo"
init_from = "{source}"
[[runs]]
label = "first"
algo = "patrpo"
"""
    bad = tmp_path / "bad.toml"
    bad.write_text(body.format(source="first"))
    with pytest.raises(ValueError, match=r"runs\[0\].init_from = 'first'; expected the label of a run listed before"):
        load_experiment(bad)
    good = tmp_path / "good.toml"
    good.write_text(body.replace('label = "second"', 'label = "zero"\nalgo = "patrpo"\n[[runs]]\nlabel = "second"', 1)
                    .format(source="zero"))  # fmt: skip
    exp = load_experiment(good)
    jobs = exp.jobs(tmp_path / "out", exp.specs())
    second = [(spec, out) for spec, out in jobs if spec.label == "second"]
    sources = [str(tmp_path / "out" / "good" / "zero" / f"seed{s}") for s in (0, 1)]
    assert [spec.init_from for spec, _ in second] == sources


@pytest.mark.parametrize("workers", [1, 2])
def test_a_curriculum_runs_its_stages_in_order_whatever_the_jobs_order(tmp_path, workers):
    """Given the second stage first, and with two workers, which could start it before the first ends, it waits
    for the first and starts from that stage's final model."""
    from pamdp.experiments.runner import run_all

    (tmp_path / "c.toml").write_text("""
description = "two stages"
env = "pamdp/Platform-v0"
total_steps = 600
seeds = [0]
eval_episodes = 0
[[runs]]
label = "first"
algo = "patrpo"
settings = { num_envs = 2, batch_size = 200 }
[[runs]]
label = "second"
algo = "patrpo"
init_from = "first"
settings = { num_envs = 2, batch_size = 200 }
""")
    exp = load_experiment(tmp_path / "c.toml")
    jobs = exp.jobs(tmp_path / "out", exp.specs())
    outcomes = run_all(list(reversed(jobs)), workers=workers, log=lambda msg: None)
    assert [o.error for o in outcomes] == [None, None]
    first, second = (tmp_path / "out" / "c" / label / "seed0" for label in ("first", "second"))
    log = (second / "stdout.log").read_text()
    assert f"networks started from {first}" in log
    assert (first / "final_model.pt").stat().st_mtime < (second / "run.json").stat().st_mtime
    (first / "final_model.pt").rename(first / "checkpoint.pt")  # as a run still training leaves it
    with pytest.raises(ValueError, match="holds no final_model.pt"):
        _warm_start(algorithm_class("patrpo")("pamdp/Platform-v0"), str(first), log=lambda msg: None)


def test_kept_tensors_stay_the_new_models_own(tmp_path):
    """PATRPO's exploration (``policy.log_std``) kept from the new model's settings while the rest is the source's."""
    patrpo = algorithm_class("patrpo")
    source = patrpo(ONE_V_ZERO, patrpo.config_class.preset("tuned"))
    source.save(tmp_path / "source.pt")
    model = patrpo(ONE_V_ONE, dataclasses.replace(source.config, init_log_std=-2.0))
    report = transfer_weights(
        model, tmp_path / "source.pt", list(range(58)) + [None] * 9 + [58], keep=("policy.log_std",)
    )
    assert report["policy.log_std"] == "kept" and report["policy.pi_d.0.weight"] == "inputs mapped"
    torch.testing.assert_close(model.policy.log_std.detach(), torch.full_like(model.policy.log_std, -2.0))
    torch.testing.assert_close(model.policy.pi_c[2].weight, source.policy.pi_c[2].weight)
    with pytest.raises(ValueError, match="keep names policy.bogus; expected tensors of the model"):
        transfer_weights(model, tmp_path / "source.pt", [None] * 68, keep=("policy.bogus",))


GOALIE_START = [[-0.75, -2.56], [-0.97, -0.5], [-0.52, -3.69]]  # the 1v0 stage's log-stds (DASH, TURN, KICK)


@pytest.mark.parametrize(
    "keep, widen, report, expected",
    [
        # widen: exploration at least the new settings' where the source's had narrowed, the source's elsewhere
        ((), ("policy.log_std",), "widened", [[-0.75, -2.0], [-0.97, -0.5], [-0.52, -2.0]]),
        # the goalie's recipe as names: the kick's row restarts at the new settings' -2.0 (narrower kick power,
        # wider kick direction than the 1v0 policy's), every other entry at least -2.0: the log-stds of the model
        # file the 0.906 run started from, which were set by hand
        (
            ("policy.log_std[2]",),
            ("policy.log_std",),
            "kept rows [2], widened",
            [[-0.75, -2.0], [-0.97, -0.5], [-2.0, -2.0]],
        ),
        (("policy.log_std[0]",), (), "kept rows [0], copied", [[-2.0, -2.0], [-0.97, -0.5], [-0.52, -3.69]]),
    ],
)
def test_kept_and_widened_rows_of_the_exploration(tmp_path, keep, widen, report, expected):
    patrpo = algorithm_class("patrpo")
    source = patrpo(ONE_V_ZERO, patrpo.config_class.preset("tuned"))
    with torch.no_grad():
        source.policy.log_std.copy_(torch.tensor(GOALIE_START))
    source.save(tmp_path / "source.pt")
    model = patrpo(ONE_V_ONE, dataclasses.replace(source.config, init_log_std=-2.0))
    columns = list(range(58)) + [None] * 9 + [58]
    assert transfer_weights(model, tmp_path / "source.pt", columns, keep=keep, widen=widen)["policy.log_std"] == report
    torch.testing.assert_close(model.policy.log_std.detach(), torch.tensor(expected))
    torch.testing.assert_close(model.policy.pi_c[2].weight, source.policy.pi_c[2].weight)


def test_rows_out_of_range_and_of_input_layers_are_refused(tmp_path):
    patrpo = algorithm_class("patrpo")
    patrpo(ONE_V_ZERO).save(tmp_path / "source.pt")
    model = patrpo(ONE_V_ONE)
    columns = list(range(58)) + [None] * 9 + [58]
    for name in ("policy.log_std[3]", "policy.log_std[-1]", "policy.log_std[kick]"):
        with pytest.raises(
            ValueError, match=r"keep names .*; expected policy.log_std or one of its rows, .*\[0\] to .*\[2\]"
        ):
            transfer_weights(model, tmp_path / "source.pt", columns, keep=(name,))
    with pytest.raises(ValueError, match=r"widen names rows of policy.pi_d.0.weight, which depends on the observation"):
        transfer_weights(model, tmp_path / "source.pt", columns, widen=("policy.pi_d.0.weight[0]",))


def test_a_stage_with_one_seed_starts_every_seed_of_the_next(tmp_path):
    """A run listing its own single seed is the source of every seed of the runs that start from it; a run's own
    seeds replace the experiment's."""
    body = """env = "pamdp/Platform-v0"
total_steps = 1000
seeds = [0, 1]
runs = [{{ label = "stage", algo = "patrpo", seeds = {stage} }},
        {{ label = "next", algo = "patrpo", seeds = [5, 6, 7], init_from = "stage" }}]
"""
    (tmp_path / "e.toml").write_text(body.format(stage="[100]"))
    exp = load_experiment(tmp_path / "e.toml")
    jobs = exp.jobs(tmp_path / "out", exp.specs())
    assert [(spec.label, spec.seed) for spec, _ in jobs] == [("stage", 100), ("next", 5), ("next", 6), ("next", 7)]
    stage = str(tmp_path / "out" / "e" / "stage" / "seed100")
    assert [spec.init_from for spec, _ in jobs[1:]] == [stage] * 3
    (tmp_path / "e.toml").write_text(body.format(stage="[5, 6]"))  # one stage per seed: seed 7 has none
    exp = load_experiment(tmp_path / "e.toml")
    sources = [spec.init_from for spec, _ in exp.jobs(tmp_path / "out", exp.specs()) if spec.label == "next"]
    assert sources == [str(tmp_path / "out" / "e" / "stage" / f"seed{s}") for s in (5, 6, 7)]
    (tmp_path / "e.toml").write_text(body.format(stage="[100, 100]"))
    with pytest.raises(ValueError, match=r"runs\[0\].seeds = \[100, 100\]; expected each seed once"):
        load_experiment(tmp_path / "e.toml")
    (tmp_path / "e.toml").write_text(body.format(stage="[100]"))
    exp = load_experiment(tmp_path / "e.toml")
    jobs = exp.jobs(tmp_path / "out", exp.specs(seeds=[9]))  # --seeds: the experiment's, not a run's own
    assert [(spec.label, spec.seed, spec.init_from) for spec, _ in jobs] == [
        ("stage", 100, ""),
        ("next", 5, stage),
        ("next", 6, stage),
        ("next", 7, stage),
    ]
