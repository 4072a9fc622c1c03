"""A scripted striker against HFO's goalie (1v1, issue 43): the reference a learned agent is measured against.

    nice python benchmarks/hfo_goalie_striker.py [--distances 12,16,20] [--aims 0.05,0.15] [--episodes 1000]

It reads only the observation. Ball not kickable: turn to the ball when it is more than 10 degrees off the body,
else dash at full power. Ball kickable: farther than ``distance`` metres from the goal's centre, dribble (a kick of
power 25 towards the goal's centre); within it, shoot at full power at the post farther, in bearing, from the
goalie, aimed ``aim`` of the way from that post towards the goal's centre. Writes benchmarks/hfo_goalie_striker.md
(goal rate and each other ending's share per setting, noise on, the registered env's defaults).
"""

from __future__ import annotations

import argparse
import sys

import gymnasium as gym
import numpy as np
from _record import HERE, record_head, write_record

import pamdp  # noqa: F401  (registers the envs)
from pamdp.envs.hfo.dynamics import BALL_COS, BALL_SIN, GOAL_COS, GOAL_SIN, KICKABLE

ENV = "pamdp/HalfFieldOffenseGoalie-v0"
DMAX = 62.548  # the default profile's (hfo2017) distance normaliser: proximity = 1 - 2 d / DMAX
POST_TOP, POST_BOTTOM, GOAL_PROXIMITY, GOALIE_SIN = 16, 19, 15, 58  # feature indices (docs/environments.md)


def _bearing(obs: np.ndarray, sin_index: int, cos_index: int | None = None) -> np.ndarray:
    return np.degrees(np.arctan2(obs[:, sin_index], obs[:, sin_index + 1 if cos_index is None else cos_index]))


def _wrap(angle: np.ndarray) -> np.ndarray:
    return (angle + 180.0) % 360.0 - 180.0


def striker(obs: np.ndarray, distance: float, aim: float, dribble: float = 25.0) -> tuple:
    """Batched actions of the striker for observations ``(N, 68)``."""
    n = len(obs)
    ball, goal = _bearing(obs, BALL_SIN, BALL_COS), _bearing(obs, GOAL_SIN, GOAL_COS)
    top, bottom, goalie = _bearing(obs, POST_TOP), _bearing(obs, POST_BOTTOM), _bearing(obs, GOALIE_SIN)
    post = np.where(np.abs(_wrap(top - goalie)) > np.abs(_wrap(bottom - goalie)), top, bottom)
    shoot = (1.0 - obs[:, GOAL_PROXIMITY]) / 2.0 * DMAX < distance
    a = np.where(obs[:, KICKABLE] > 0, 2, np.where(np.abs(ball) > 10.0, 1, 0))
    dash = np.tile(np.array([100.0, 0.0], dtype=np.float32), (n, 1))
    kick = np.stack([np.where(shoot, 100.0, dribble), np.where(shoot, post + aim * _wrap(goal - post), goal)], 1)
    return a, (dash, ball[:, None].astype(np.float32), kick.astype(np.float32))


def endings(distance: float, aim: float, episodes: int, copies: int = 100, seed: int = 1) -> dict[str, float]:
    """Each ending's share over ``episodes`` episodes of the striker, ``copies`` env copies stepped together."""
    env = gym.make_vec(ENV, num_envs=copies, vectorization_mode="vector_entry_point")
    obs, _ = env.reset(seed=seed)
    counts: dict[str, int] = {}
    ended_before = np.zeros(copies, dtype=bool)
    quota = np.full(copies, episodes // copies) + (np.arange(copies) < episodes % copies)
    done = np.zeros(copies, dtype=int)
    while (done < quota).any():
        obs, _, terminated, truncated, info = env.step(striker(obs, distance, aim))
        ended = (terminated | truncated) & ~ended_before  # next-step autoreset: the step after an end is a reset
        for i in np.flatnonzero(ended & (done < quota)):
            counts[str(info["status"][i])] = counts.get(str(info["status"][i]), 0) + 1
            done[i] += 1
        ended_before = terminated | truncated
    env.close()
    return {name: count / episodes for name, count in sorted(counts.items())}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--distances", default="12,16,20,24", help="comma-separated shooting distances, metres")
    p.add_argument("--aims", default="0.05,0.15", help="comma-separated aims (0: at the post, 1: at the centre)")
    p.add_argument("--episodes", type=int, default=1000, help="episodes per setting")
    args = p.parse_args()
    lines = record_head("A scripted striker against HFO's goalie (1v1)", "python " + " ".join(sys.argv)) + [
        f"- env: `{ENV}` (noise on), {args.episodes} episodes per setting; the striker: this script's docstring",
        "",
        "| shooting distance (m) | aim | goal rate | captured | out of bounds | out of time |",
        "|---|---|---|---|---|---|",
    ]
    for distance in (float(d) for d in args.distances.split(",")):
        for aim in (float(a) for a in args.aims.split(",")):
            share = endings(distance, aim, args.episodes)
            lines.append(
                f"| {distance:g} | {aim:g} | {share.get('GOAL', 0):.3f} | {share.get('CAPTURED_BY_DEFENSE', 0):.3f} "
                f"| {share.get('OUT_OF_BOUNDS', 0):.3f} | {share.get('OUT_OF_TIME', 0):.3f} |"
            )
            print(lines[-1], flush=True)
    write_record(lines, HERE / "hfo_goalie_striker.md")


if __name__ == "__main__":
    main()
