"""Training's per-epoch episode statistics, and the goal rate on envs that report an episode's outcome."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest
import torch

from pamdp import PATRPO
from pamdp.algos.logger import EpisodeTracker
from pamdp.algos.offpolicy import OffPolicyLoop
from pamdp.algos.patrpo import PATRPOConfig
from pamdp.algos.replay import ReplayBuffer
from pamdp.algos.vector_env import make_vector_env
from pamdp.envs.hfo_baseline import scripted_scorer_batch
from pamdp.spaces import HybridActionSpace


def test_tracker_by_hand_with_outcomes_and_an_autoreset_step():
    tracker = EpisodeTracker(2)
    status = np.array(["IN_GAME", "IN_GAME"])
    tracker.step(np.array([1.0, 2.0]), np.array([False, False]), np.array([True, True]), {"status": status})
    tracker.step(
        np.array([1.0, 2.0]), np.array([False, True]), np.array([True, True]), {"status": ["IN_GAME", "OUT_OF_BOUNDS"]}
    )
    # copy 1's autoreset step is not valid: neither its reward nor its status counts
    tracker.step(np.array([3.0, 9.0]), np.array([True, True]), np.array([True, False]), {"status": ["GOAL", "GOAL"]})
    stats = tracker.pop()
    assert stats["charts/episodes"] == 2
    assert stats["charts/episodic_return"] == pytest.approx((5.0 + 4.0) / 2)
    assert stats["charts/episodic_length"] == pytest.approx((3 + 2) / 2)
    assert stats["charts/goal_rate"] == 0.5 and stats["charts/steps_to_goal"] == 3.0
    assert tracker.pop() == {}


def test_no_goal_figures_without_outcomes_and_no_steps_to_goal_without_a_goal():
    tracker = EpisodeTracker(1)
    tracker.step(np.array([1.0]), np.array([True]), np.array([True]))
    assert "charts/goal_rate" not in tracker.pop()
    tracker.step(np.array([1.0]), np.array([True]), np.array([True]), {"status": np.array(["OUT_OF_TIME"])})
    stats = tracker.pop()
    assert stats["charts/goal_rate"] == 0.0 and "charts/steps_to_goal" not in stats


class Outcomes(gymnasium.vector.VectorWrapper):
    """Counts each finished episode's outcome and length itself, from the env's own step results."""

    def __init__(self, env):
        super().__init__(env)
        self.prev_done = np.zeros(env.num_envs, dtype=bool)
        self.length = np.zeros(env.num_envs, dtype=np.int64)
        self.goals: list[bool] = []
        self.lengths: list[int] = []

    def step(self, actions):
        obs, reward, terminated, truncated, info = self.env.step(actions)
        valid = ~self.prev_done
        self.length += valid
        done = (terminated | truncated) & valid
        for i in np.flatnonzero(done):
            self.goals.append(info["status"][i] == "GOAL")
            self.lengths.append(int(self.length[i]))
            self.length[i] = 0
        self.prev_done = done
        return obs, reward, terminated, truncated, info


def test_off_policy_epoch_reports_the_goal_rate_the_env_saw():
    env = Outcomes(make_vector_env("pamdp/HalfFieldOffense-v0", 16))
    hybrid = HybridActionSpace.from_gym(env.single_action_space)
    d, m = env.single_observation_space.shape[0], hybrid.max_param_size
    fields = {"obs": ((d,), np.float32), "a": ((), np.int64), "x": ((m,), np.float32), "reward": ((), np.float32)}
    fields |= {"next_obs": ((d,), np.float32), "terminated": ((), np.bool_)}
    loop = OffPolicyLoop(hybrid, ReplayBuffer(10_000, fields))

    def scripted(obs, step, episode_start):  # the scripted scorer, in the agent's [-1, 1] parameters
        a, params = scripted_scorer_batch(obs.numpy())
        x_env = np.zeros((len(a), m))
        for b, p in enumerate(params):
            x_env[a == b, : p.shape[1]] = p[a == b]
        return torch.as_tensor(a), torch.as_tensor(hybrid.unscale(a, x_env), dtype=torch.float32), {}

    stats = loop.run_epoch(env, scripted, dict, 3000, 0, 10**9, 1.0, np.random.default_rng(0))
    assert stats["charts/episodes"] == len(env.goals) >= 20
    assert stats["charts/goal_rate"] == pytest.approx(np.mean(env.goals)) and stats["charts/goal_rate"] > 0.5
    scoring = np.array(env.lengths)[np.array(env.goals)]
    assert stats["charts/steps_to_goal"] == pytest.approx(scoring.mean())


def test_patrpo_logs_the_goal_rate_on_soccer_only():
    config = PATRPOConfig(hidden_sizes=(16,), vf_hidden_sizes=(16,), batch_size=2000, num_envs=16)
    for env_id, expected in (("pamdp/HalfFieldOffense-v0", True), ("pamdp/Platform-v0", False)):
        seen: list[dict] = []
        PATRPO(env_id, config).learn(
            2000, progress_bar=False, callback=lambda algo, stats, seen=seen: seen.append(stats)
        )
        assert ("charts/goal_rate" in seen[-1]) == expected, env_id


def test_goal_figures_count_only_the_episodes_whose_end_reported_a_status():
    tracker = EpisodeTracker(1)
    tracker.step(np.array([0.0]), np.array([True]), np.array([True]))  # no status: not counted for goals
    tracker.step(np.array([0.0]), np.array([False]), np.array([True]), {"status": ["IN_GAME"]})
    tracker.step(np.array([1.0]), np.array([True]), np.array([True]), {"status": ["GOAL"]})
    stats = tracker.pop()
    assert stats["charts/episodes"] == 2
    assert stats["charts/goal_rate"] == 1.0 and stats["charts/steps_to_goal"] == 2.0
