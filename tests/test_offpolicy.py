"""The off-policy family module: the shared settings keep each algorithm's names, defaults and presets, and a diverged
critic is said."""

import dataclasses
import json
import warnings
from pathlib import Path

import numpy as np
import pytest
import torch
from conftest import ENV, progress_rows, small_config
from torch import nn

from pamdp.algos import algorithm_class
from pamdp.algos.hyar import HyARConfig
from pamdp.algos.offpolicy import OffPolicyConfig
from pamdp.algos.paddpg import PADDPGConfig
from pamdp.algos.pasvg import PASVG0Config
from pamdp.algos.pdqn import PDQNConfig

CONFIGS = [PASVG0Config, PADDPGConfig, PDQNConfig, HyARConfig]
# Every preset's settings (and the defaults), in their order, as written out by the code before OffPolicyConfig existed
# (commit 763e0d8), so that checkpoints and config files of earlier runs mean what they meant; with the settings
# added since at values that change nothing: device (issue 31) at "auto", which on a machine without CUDA is the CPU
# those runs had, action_mask off (issue 27), P-DQN's param_passthrough empty and reward_scale 1, HyAR's td3_replay
# 0 (issue 26) and beta 0 (issue 45).
RECORDED = json.loads((Path(__file__).parent / "data" / "offpolicy_presets.json").read_text())


@pytest.mark.parametrize("config_class", CONFIGS, ids=lambda c: c.__name__)
def test_presets_and_defaults_are_the_recorded_ones(config_class):
    now = {name: cfg.to_dict() for name, cfg in config_class.presets().items()}
    now["(defaults)"] = config_class().to_dict()
    assert now == RECORDED[config_class.__name__]
    assert list(now) == list(RECORDED[config_class.__name__])  # the first preset is the default
    for values in RECORDED[config_class.__name__].values():  # a recorded dict loads back as the same config
        assert config_class.from_dict(values).to_dict() == values


@pytest.mark.parametrize("config_class", CONFIGS, ids=lambda c: c.__name__)
def test_a_shared_setting_declared_again_keeps_its_check(config_class):
    shared = {f.name for f in dataclasses.fields(OffPolicyConfig)}
    for name, bad in (("batch_size", 0), ("gamma", 1.5), ("buffer_size", 0), ("updates_per_step", 0.0)):
        assert name in shared
        with pytest.raises(ValueError, match=f"{config_class.__name__}.{name} = {bad!r}; expected"):
            config_class(**{name: bad})


@pytest.mark.parametrize(
    "algo, critics",
    [
        ("pdqn", ("q_net", "q_target")),
        ("paddpg", ("critic", "critic_target")),
        ("hsac", ("critic", "critic_target")),
        ("hyar", ("critic", "critic_target")),
        ("pasvg0", ("critic", "critic_target")),
    ],
)
def test_a_diverged_critic_is_said_once_and_a_sound_one_never(algo, critics, tmp_path):
    """Every off-policy learner: a critic whose values lie within the largest discounted return of the rewards
    seen trains without a word and logs that bound; one pushed a million above it (every output layer's bias,
    critics and targets, as a critic that ran away) gets one RuntimeWarning naming the value, and no second."""
    model = algorithm_class(algo)(ENV, small_config(algo, reward_scale=1.0))
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        model.learn(300, progress_bar=False, run_dir=tmp_path)
    rewards = model.loop.buffer.data["reward"][: len(model.loop.buffer)].numpy()
    sound = float(np.abs(rewards).max()) / (1 - model.config.gamma)
    assert float(progress_rows(tmp_path)[-1]["train/q_bound"]) == pytest.approx(sound, rel=1e-5)
    with torch.no_grad():
        for name in critics:
            for seq in [m for m in getattr(model, name).modules() if isinstance(m, nn.Sequential)]:
                last = [m for m in seq if isinstance(m, nn.Linear)][-1]
                last.bias += 1e6
    with pytest.warns(RuntimeWarning, match=r"diverged: their mean value .* is \d") as caught:
        model.learn(200, progress_bar=False)
        model.learn(200, progress_bar=False)
    assert len([w for w in caught if "diverged" in str(w.message)]) == 1
