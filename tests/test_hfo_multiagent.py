"""HFO as a PettingZoo ParallelEnv (issue 47): PettingZoo's own API test, and the agent's trajectories checked step
by step against the single-agent env made by ``gymnasium.make`` with the same seeds and actions."""

from __future__ import annotations

import importlib.util
import subprocess
import sys

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.error import ResetNeeded

import pamdp  # noqa: F401
from pamdp.envs.hfo import scripted_scorer

needs_pettingzoo = pytest.mark.skipif(
    importlib.util.find_spec("pettingzoo") is None, reason="PettingZoo is optional: pip install 'pamdp[multiagent]'"
)


def _parallel_env(**kwargs):
    from pamdp.envs.hfo import parallel_env

    return parallel_env(**kwargs)


def test_importing_pamdp_does_not_import_pettingzoo():
    code = "import sys, pamdp, pamdp.envs.hfo; assert 'pettingzoo' not in sys.modules, 'pettingzoo imported'"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr


def test_without_pettingzoo_the_import_error_says_what_to_install():
    code = "import sys; sys.modules['pettingzoo'] = None; import pamdp.envs.hfo.multiagent"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert "ModuleNotFoundError" in done.stderr and "pip install 'pamdp[multiagent]'" in done.stderr


@needs_pettingzoo
@pytest.mark.parametrize("defense_npcs", [0, 1])
def test_pettingzoo_parallel_api_test_passes(defense_npcs):
    from pettingzoo.test import parallel_api_test

    env = _parallel_env(defense_npcs=defense_npcs)
    with pytest.warns(UserWarning, match=r"reset options \['options'\] ignored"):  # the API test's dummy option
        parallel_api_test(env, num_cycles=300)


@needs_pettingzoo
def test_the_agent_has_the_single_agent_envs_spaces():
    single = gym.make("pamdp/HalfFieldOffense-v0", defense_npcs=1)
    env = _parallel_env(defense_npcs=1)
    assert env.possible_agents == ["offense_0"]
    assert env.observation_space("offense_0") == single.observation_space
    assert env.action_space("offense_0") == single.action_space


def _random_or_scripted(rng, space, obs):
    """Random actions, and the scripted scorer's now and then, so that episodes end in goals and captures too."""
    return scripted_scorer(obs) if rng.random() < 0.5 else space.sample()


@needs_pettingzoo
@pytest.mark.parametrize("defense_npcs", [0, 1])
def test_same_seeds_give_the_single_agent_envs_trajectories(defense_npcs):
    single = gym.make("pamdp/HalfFieldOffense-v0", defense_npcs=defense_npcs)
    env = _parallel_env(defense_npcs=defense_npcs)
    space = env.action_space("offense_0")
    space.seed(3)
    rng = np.random.default_rng(3)
    statuses = set()
    for seed in (7, 8):
        seeded = {"seed": seed}
        for _ in range(3):  # the first episode seeded, the next ones continuing the env's own streams
            obs, info = single.reset(**seeded)
            multi_obs, multi_info = env.reset(**seeded)
            np.testing.assert_array_equal(multi_obs["offense_0"], obs)
            np.testing.assert_equal(multi_info["offense_0"], info)
            seeded, done = {}, False
            while not done:
                action = _random_or_scripted(rng, space, obs)
                obs, reward, terminated, truncated, info = single.step(action)
                multi = env.step({"offense_0": action})
                assert [d.keys() for d in multi] == [{"offense_0"}] * 5
                np.testing.assert_array_equal(multi[0]["offense_0"], obs)
                assert [d["offense_0"] for d in multi[1:4]] == [reward, terminated, truncated]
                np.testing.assert_equal(multi[4]["offense_0"], info)
                done = terminated or truncated
                assert env.agents == ([] if done else ["offense_0"])
            statuses.add(info["status"])
            with pytest.raises(ResetNeeded):  # the agent has left: stepping on needs a reset
                env.step({"offense_0": action})
    assert len(statuses) >= 2, statuses  # more than one kind of ending was compared


@needs_pettingzoo
def test_reset_options_go_to_the_pitch_and_to_the_agent_by_name():
    single = gym.make("pamdp/HalfFieldOffense-v0", defense_npcs=1, render_mode="rgb_array")
    env = _parallel_env(defense_npcs=1, render_mode="rgb_array")
    placed = {"ball": (40.0, 5.0), "goalie_body": 90.0}
    obs, _ = single.reset(seed=2, options={**placed, "player": (30.0, -3.0), "body": 45.0})
    multi_obs, _ = env.reset(seed=2, options={**placed, "offense_0": {"player": (30.0, -3.0), "body": 45.0}})
    np.testing.assert_array_equal(multi_obs["offense_0"], obs)
    np.testing.assert_array_equal(env.render(), single.render())


@needs_pettingzoo
@pytest.mark.parametrize(
    "actions, match",
    [
        ({"offense_1": (0, ([50, 0], [0], [50, 0]))}, r"unknown or finished agent\(s\) \['offense_1'\]"),
        ({}, r"no action for agent\(s\) \['offense_0'\]"),
        ([(0, ([50, 0], [0], [50, 0]))], "actions of type list; expected a dict"),
        ({"offense_0": (3, ([50, 0], [0], [50, 0]))}, r"^offense_0: discrete actions \[3\]"),
        ({"offense_0": (0, ([50, 0], [0]))}, r"^offense_0: malformed actions"),
        ({"offense_0": (0, ([np.nan, 0], [0], [50, 0]))}, r"^offense_0: .*non-finite parameters"),
    ],
)
def test_bad_actions_are_refused_naming_the_bad_value(actions, match):
    env = _parallel_env()
    env.reset(seed=0)
    with pytest.raises(ValueError, match=match):
        env.step(actions)


@needs_pettingzoo
def test_bad_settings_and_out_of_turn_steps_are_refused():
    with pytest.raises(ValueError, match=r"offense_agents=2; expected 1 \(more offense agents are not implemented\)"):
        _parallel_env(offense_agents=2)
    env = _parallel_env()
    with pytest.raises(ValueError, match="unknown agent 'defense_0'"):
        env.action_space("defense_0")
    with pytest.raises(ResetNeeded):
        env.step({"offense_0": (0, ([50, 0], [0], [50, 0]))})
    with pytest.raises(ValueError, match="reset option 'player' is a player's"):
        env.reset(options={"player": (30.0, 0.0)})
    with pytest.raises(ValueError, match=r"reset option offense_0=\{'ball'"):
        env.reset(options={"offense_0": {"ball": (30.0, 0.0)}})
