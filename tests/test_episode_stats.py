"""Training's per-epoch episode statistics, and the success rate on envs that report ``info["is_success"]``."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest
import torch
from gymnasium import spaces
from loop_stub import stub_algorithm

from pamdp import PATRPO
from pamdp.algos.offpolicy import OffPolicyLoop
from pamdp.algos.paddpg import PADDPGConfig
from pamdp.algos.patrpo import PATRPOConfig
from pamdp.envs.stepping import EpisodeTracker
from pamdp.evaluation import evaluate


def test_tracker_by_hand_with_successes_and_an_autoreset_step():
    tracker = EpisodeTracker(2)
    tracker.step(np.array([1.0, 2.0]), np.array([False, False]), np.array([True, True]), {})
    # copy 1 ends without success; Gymnasium's mask says which copies reported is_success this step
    info = {"is_success": np.array([False, False]), "_is_success": np.array([False, True])}
    tracker.step(np.array([1.0, 2.0]), np.array([False, True]), np.array([True, True]), info)
    # copy 1's autoreset step is not valid: neither its reward nor its success counts
    info = {"is_success": np.array([True, True]), "_is_success": np.array([True, True])}
    tracker.step(np.array([3.0, 9.0]), np.array([True, True]), np.array([True, False]), info)
    stats = tracker.pop()
    assert stats["charts/episodes"] == 2
    assert stats["charts/episodic_return"] == pytest.approx((5.0 + 4.0) / 2)
    assert stats["charts/episodic_length"] == pytest.approx((3 + 2) / 2)
    assert stats["charts/success_rate"] == 0.5 and stats["charts/steps_to_success"] == 3.0
    assert tracker.pop() == {}


def test_no_success_figures_without_reports_and_no_steps_to_success_without_one():
    tracker = EpisodeTracker(1)
    tracker.step(np.array([1.0]), np.array([True]), np.array([True]))
    assert "charts/success_rate" not in tracker.pop()
    tracker.step(np.array([1.0]), np.array([True]), np.array([True]), {"is_success": np.array([False])})
    stats = tracker.pop()
    assert stats["charts/success_rate"] == 0.0 and "charts/steps_to_success" not in stats


def test_success_figures_count_only_the_episodes_whose_end_reported_it():
    tracker = EpisodeTracker(1)
    tracker.step(np.array([0.0]), np.array([True]), np.array([True]))  # no is_success: not counted
    tracker.step(np.array([0.0]), np.array([False]), np.array([True]), {})
    tracker.step(np.array([1.0]), np.array([True]), np.array([True]), {"is_success": np.array([True])})
    stats = tracker.pop()
    assert stats["charts/episodes"] == 2
    assert stats["charts/success_rate"] == 1.0 and stats["charts/steps_to_success"] == 2.0


class Coin(gymnasium.Env):
    """Episodes of 1 to 6 steps; an episode that ends by termination succeeds with probability 0.6 and says so
    in ``info["is_success"]``; one cut off by truncation reports nothing. Two actions, one parameter each."""

    observation_space = spaces.Box(-1.0, 1.0, (2,), np.float32)
    action_space = spaces.Tuple(
        (spaces.Discrete(2), spaces.Tuple((spaces.Box(-1.0, 1.0, (1,)), spaces.Box(-1.0, 1.0, (1,)))))
    )

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.t, self.length = 0, int(self.np_random.integers(1, 7))
        return np.zeros(2, np.float32), {}

    def step(self, action):
        self.t += 1
        obs = np.array([self.t / 6, 0.0], np.float32)
        if self.t < self.length:
            return obs, 0.0, False, False, {}
        if self.np_random.random() < 0.2:
            return obs, 0.0, False, True, {}
        success = bool(self.np_random.random() < 0.6)
        return obs, float(success), True, False, {"is_success": success}


class Outcomes(gymnasium.vector.VectorWrapper):
    """Counts each finished episode's success and length itself, from the scalar envs' own step results."""

    def __init__(self, env):
        super().__init__(env)
        self.prev_done = np.zeros(env.num_envs, dtype=bool)
        self.length = np.zeros(env.num_envs, dtype=np.int64)
        self.reports: list[bool | None] = []
        self.lengths: list[int] = []

    def step(self, actions):
        obs, reward, terminated, truncated, info = self.env.step(actions)
        valid = ~self.prev_done
        self.length += valid
        done = (terminated | truncated) & valid
        for i in np.flatnonzero(done):
            self.reports.append(bool(reward[i]) if terminated[i] else None)  # reward 1 exactly on a success
            self.lengths.append(int(self.length[i]))
            self.length[i] = 0
        self.prev_done = done
        return obs, reward, terminated, truncated, info

    def expected(self) -> tuple[float, float]:
        known = [(n, s) for n, s in zip(self.lengths, self.reports) if s is not None]
        return np.mean([s for _, s in known]), np.mean([n for n, s in known if s])


def coins(n: int) -> Outcomes:
    return Outcomes(gymnasium.vector.SyncVectorEnv([Coin for _ in range(n)]))


def test_off_policy_epoch_reports_the_success_rate_the_env_saw():
    env = coins(8)
    env.reset(seed=0)

    def act(obs, step, episode_start, mask):
        return torch.zeros(len(obs), dtype=torch.int64), torch.zeros(len(obs), 1), {}

    config = PADDPGConfig(epoch_steps=600, learning_starts=10**9, buffer_size=10_000)
    algo = stub_algorithm(config, env, act, dict)
    stats = OffPolicyLoop(algo).run_epoch()
    rate, steps = env.expected()
    assert stats["charts/episodes"] == len(env.lengths) >= 100
    assert 0 < sum(s is None for s in env.reports) < len(env.reports)  # truncated episodes, not counted
    assert stats["charts/success_rate"] == pytest.approx(rate) and stats["charts/steps_to_success"] == pytest.approx(
        steps
    )


def test_patrpo_logs_the_success_rate_only_where_the_env_reports_it():
    config = PATRPOConfig(hidden_sizes=(16,), vf_hidden_sizes=(16,), batch_size=500, num_envs=4)
    for env, expected in ((coins(4), True), ("pamdp/Platform-v0", False)):
        seen: list[dict] = []
        PATRPO(env, config).learn(500, progress_bar=False, callback=lambda algo, stats, seen=seen: seen.append(stats))
        assert ("charts/success_rate" in seen[-1]) == expected, env
        if expected:
            assert seen[-1]["charts/success_rate"] == pytest.approx(env.expected()[0])


def test_evaluation_reports_the_success_rate_the_env_saw():
    model = PATRPO(coins(1), PATRPOConfig(hidden_sizes=(8,), vf_hidden_sizes=(8,), num_envs=1))
    gymnasium.register("test/Coin-v0", entry_point=Coin)
    try:
        result = evaluate(model, episodes=400, seed=5, num_envs=4, env_id="test/Coin-v0")
    finally:
        gymnasium.registry.pop("test/Coin-v0")
    assert result["episodes"] == 400
    # success probability 0.6 among the terminated episodes (80%): within 5 standard errors
    assert abs(result["success_rate"] - 0.6) < 5 * np.sqrt(0.24 / 320)
    assert 1 <= result["mean_steps_to_success"] <= 6


def test_evaluation_counts_each_ending_that_the_env_reports():
    """HFO 1v1 reports ``info["status"]`` at every episode's end: the endings' shares are counts over the episodes
    played, and GOAL's share is the goal rate computed from ``is_success``, another key of the same infos."""
    model = PATRPO("pamdp/HalfFieldOffenseGoalie-v0", PATRPOConfig(seed=4, num_envs=4, batch_size=200))
    result = evaluate(model, episodes=12, seed=4, deterministic=False, num_envs=4)
    endings = result["endings"]
    assert set(endings) <= {"GOAL", "OUT_OF_BOUNDS", "OUT_OF_TIME", "CAPTURED_BY_DEFENSE"}
    assert sum(endings.values()) == pytest.approx(1.0)
    assert all((share * 12) == pytest.approx(round(share * 12)) for share in endings.values())
    assert endings.get("GOAL", 0.0) == pytest.approx(result["success_rate"])
    assert "endings" not in evaluate(PATRPO("pamdp/Platform-v0", PATRPOConfig(seed=4)), episodes=3)  # no status
