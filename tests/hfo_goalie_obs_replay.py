"""Observation replay of HFO 1v1 (the goalie, ``defense_npcs=1``) against a recording of the real server.

``tests/data/hfo_goalie_episodes_seed42.json.gz`` (made by ``tests/data/strip_hfo_goalie_episodes.py``) holds,
per episode of the seed-42 recording (LARG/HFO b8b2a1d, mhauskn/rcssserver 82212ee, mhauskn/librcsc d222758;
``--offense-agents 1 --defense-npcs 1 --deterministic --fullstate``), the placement, the goalie's body angle at
the reset, the actions sent and the statuses and 68 features returned. Each episode is replayed on its own
through the public interface: ``reset(options={"ball", "player", "body", "goalie_body"})``, then the recorded
actions. Compared: the first observation and every observation returned with IN_GAME, feature by feature
within :data:`TOLERANCE`; and the ending: the same status on the same step. Episode 0 is skipped (its first
observation is the server's stale pre-kick-off state). An episode's comparison stops at its first differing
status.

Run ``python tests/hfo_goalie_obs_replay.py`` for the figures (``-v``: the worst feature of each mismatch).
"""

from __future__ import annotations

import gzip
import json
import pathlib
import sys
from dataclasses import dataclass, field

import gymnasium as gym
import numpy as np

import pamdp  # noqa: F401  (registers the envs)

DATA = pathlib.Path(__file__).parent / "data" / "hfo_goalie_episodes_seed42.json.gz"
TOLERANCE = 2e-3
N_FEATURES = 68
ACTION_IDS = {"DASH": 0, "TURN": 1, "KICK": 2}


@dataclass
class Figures:
    compared: int = 0
    """Observations compared (first ones and those returned with IN_GAME)."""
    matching: int = 0
    """... with all 68 features within the tolerance."""
    feature_matching: np.ndarray = field(default_factory=lambda: np.zeros(N_FEATURES, dtype=np.int64))
    """Per feature: compared observations where that feature is within the tolerance."""
    episodes: int = 0
    endings_matching: int = 0
    """Episodes ending with the recorded status on the recorded step."""
    messages: list[str] = field(default_factory=list)


def load() -> dict:
    with gzip.open(DATA, "rt") as f:
        return json.load(f)


def recorded_features(episode: dict, scale: float) -> np.ndarray:
    """The episode's observations (first one, then one per step), undoing the stripped file's encoding."""
    return np.cumsum(np.array(episode["features"], dtype=np.int64), axis=0) / scale


def action(name: str, params) -> tuple:
    a = ACTION_IDS[name]
    boxes = [np.array([50.0, 0.0], np.float32), np.array([0.0], np.float32), np.array([50.0, 0.0], np.float32)]
    boxes[a] = np.asarray(params, dtype=np.float32)
    return a, tuple(boxes)


def reset_options(episode: dict) -> dict:
    wm = episode["initial_wm"]
    return {"ball": (wm[7], wm[8]), "player": (wm[1], wm[2]), "body": wm[5], "goalie_body": episode["goalie_body_deg"]}


def replay(trace: dict | None = None) -> Figures:
    trace = trace or load()
    env = gym.make("pamdp/HalfFieldOffense-v0", defense_npcs=1, deterministic=True, profile="hfo2019")
    figures = Figures()

    def compare(ep: int, t: int, obs: np.ndarray, recorded: np.ndarray) -> None:
        close = np.abs(obs.astype(np.float64) - recorded) <= TOLERANCE
        figures.compared += 1
        figures.feature_matching += close
        figures.matching += bool(close.all())
        if not close.all():
            k = int(np.argmax(np.abs(obs - recorded)))
            figures.messages.append(f"episode {ep} step {t}: feature {k} {obs[k]:.5f} recorded {recorded[k]:.5f}")

    for episode in trace["episodes"][1:]:
        ep = episode["episode"]
        figures.episodes += 1
        rows = recorded_features(episode, trace["feature_scale"])
        obs, info = env.reset(options=reset_options(episode))
        compare(ep, 0, obs, rows[0])
        for t, ((name, params), status) in enumerate(zip(episode["actions"], episode["statuses"]), start=1):
            obs, _, terminated, truncated, info = env.step(action(name, params))
            if info["status"] != status:
                figures.messages.append(f"episode {ep} step {t}: status {info['status']}, recorded {status}")
                break
            if status == "IN_GAME":
                compare(ep, t, obs, rows[t])
            else:
                figures.endings_matching += t == len(episode["statuses"])
                break
    env.close()
    return figures


def main() -> None:
    figures = replay()
    print(f"observations within {TOLERANCE} on every feature: {figures.matching} / {figures.compared} "
          f"({figures.matching / figures.compared:.4f})")  # fmt: skip
    rates = figures.feature_matching / figures.compared
    print(f"worst per-feature rate: {rates.min():.4f} (feature {int(rates.argmin())}); per feature:")
    print(" ".join(f"{k}:{r:.3f}" for k, r in enumerate(rates)))
    print(f"endings matching: {figures.endings_matching} / {figures.episodes}")
    if "-v" in sys.argv:
        print("\n".join(figures.messages))


if __name__ == "__main__":
    main()
