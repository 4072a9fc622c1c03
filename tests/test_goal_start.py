"""MP-DQN's start on Goal: the fixed linear passthrough of P-DQN's parameter actor (``param_passthrough``) and
the Goal preset's Masson weights, against Masson's rule worked in metres from the env's internal state."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest
import tomllib
import torch

import pamdp  # noqa: F401  (registers the envs)
from pamdp.algos.pdqn import PDQN, PDQNConfig
from pamdp.envs.goal.env import hard_goal_shot
from pamdp.experiments.runner import RunSpec
from pamdp.presets.goal_start import MASSON_GOAL_START

GOAL = "pamdp/Goal-v0"
HARD_GOAL = "pamdp/HardGoal-v0"
SMALL = {"num_envs": 1, "device": "cpu", "hidden_sizes": [16], "batch_size": 16, "learning_starts": 32}


def goal_config(env: str = GOAL, **settings) -> PDQNConfig:
    """The config ``pamdp train pdqn --env ENV`` gets, with ``settings`` over it."""
    return RunSpec("pdqn", env, 10, settings=tuple(settings.items())).config().config


def masson_in_metres(state: dict) -> tuple[float, float, float]:
    """Masson's hand-set kick-to x and shot y's (left, right) from the internal state, in metres: kick 2.5 m
    beyond the ball plus 1.25 m along the unit vector from the keeper to the ball; shoot 1 m inside a post."""
    bx, by = state["ball"][:2]
    kx, ky = state["keeper"][:2]
    n = math.hypot(bx - kx, by - ky)
    return bx + 2.5 + 1.25 * (bx - kx) / n, 14.02 / 2 - 1, -(14.02 / 2 - 1)


@pytest.mark.parametrize("seed", [0, 7])
def test_the_goal_preset_starts_at_massons_kick_and_shots(seed):
    model = PDQN(GOAL, goal_config(**SMALL))
    env = gym.make(GOAL)
    obs, _ = env.reset(seed=seed)
    obs, *_ = env.step((0, (np.array([30.0, 0.0], np.float32), np.zeros(1, np.float32), np.zeros(1, np.float32))))
    assert env.unwrapped.state["keeper"][0] > 14.5  # a worked observation off the reset line: the keeper moved
    with torch.no_grad():
        x = model.actor(torch.tensor(obs[None], dtype=torch.float32))[0]
    kick_x, left, right = masson_in_metres(env.unwrapped.state)
    h = model.hybrid
    assert h.to_env(0, x[:2].numpy())[1][0][0] == pytest.approx(kick_x, abs=1e-4)
    assert h.to_env(1, x[2:3].numpy())[1][1][0] == pytest.approx(left, abs=1e-5)
    assert h.to_env(2, x[3:4].numpy())[1][2][0] == pytest.approx(right, abs=1e-5)
    # The greedy action carries its own block of that start.
    a, params = model.predict(obs)
    assert params[a] == pytest.approx(h.to_env(a, model.actor.select(x[None], torch.tensor([a]))[0].numpy())[1][a])


def test_the_hard_goal_preset_kicks_as_on_goal_and_shoots_inside_either_post():
    model = PDQN(HARD_GOAL, goal_config(HARD_GOAL, **SMALL))
    env = gym.make(HARD_GOAL)
    obs, _ = env.reset(seed=3)
    obs, *_ = env.step((0, (np.array([30.0, 0.0], np.float32), *(np.zeros(1, np.float32),) * 10)))
    with torch.no_grad():
        x = model.actor(torch.tensor(obs[None], dtype=torch.float32))[0].numpy()
    kick_x, inside_upper, inside_lower = masson_in_metres(env.unwrapped.state)
    h = model.hybrid
    assert h.to_env(0, x[:2])[1][0][0] == pytest.approx(kick_x, abs=1e-4)
    # Through the env's own shot mapping (spec 4.2), part j = (a - 1) % 5 of the mouth for a = 1..10.
    aims = [hard_goal_shot((a - 1) % 5, h.to_env(a, x[1 + a : 2 + a])[1][a][0]) for a in range(1, 11)]
    middles = [hard_goal_shot(j, 0.0) for j in (1, 2, 3)]
    assert aims == pytest.approx([inside_lower, *middles, inside_upper] * 2, abs=1e-5)


def test_the_passthrough_stays_fixed_while_the_actor_learns_and_round_trips(tmp_path):
    model = PDQN(GOAL, goal_config(**SMALL, epoch_steps=64))
    fixed = model.actor.passthrough_weight.clone(), model.actor.passthrough_bias.clone()
    model.learn(64, progress_bar=False)
    assert torch.equal(model.actor.passthrough_weight, fixed[0]) and torch.equal(model.actor.passthrough_bias, fixed[1])
    assert model.actor.net[-1].weight.abs().sum() > 0  # the output layer started at zero and has moved
    model.save(tmp_path / "m.pt")
    loaded = PDQN.load(tmp_path / "m.pt")
    assert loaded.config.param_passthrough == MASSON_GOAL_START
    obs = torch.as_tensor(np.random.default_rng(0).uniform(-1, 1, (5, 17)), dtype=torch.float32)
    with torch.no_grad():
        assert torch.equal(loaded.actor(obs), model.actor(obs))
        assert torch.equal(loaded.actor_target(obs), model.actor_target(obs))


def test_without_a_passthrough_the_actor_is_the_network_alone():
    config = PDQNConfig.from_dict(tomllib.loads("param_passthrough = []"), base=goal_config(**SMALL))
    actor = PDQN(GOAL, config).actor
    assert actor.passthrough_weight is None and actor.net[-1].weight.abs().sum() > 0


def test_a_wrong_shape_or_value_is_refused_clearly():
    with pytest.raises(ValueError, match=r"has 10 numbers; expected 72 for this env: 4 parameters x \(17 observation"):
        PDQN(GOAL, goal_config(**SMALL, param_passthrough=[0.0] * 10))
    for bad in ((0.0, math.nan), (1.0,)):  # a row has at least a weight and a bias
        with pytest.raises(ValueError, match=rf"param_passthrough = \({bad[0]},.*; expected none, or finite numbers"):
            PDQNConfig(param_passthrough=bad)
    with pytest.raises(ValueError, match=r"setting 'param_passthrough' = \[\[0.0\]\]; expected a list of float"):
        PDQNConfig.from_dict({"param_passthrough": [[0.0]]})
    with pytest.raises(ValueError, match="bound = 'squash'; expected bound 'invert' or 'zero'"):
        goal_config(bound="squash")
