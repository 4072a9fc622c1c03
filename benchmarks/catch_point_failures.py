"""Where trained Catch Point agents fail (issue 26): greedy episodes of saved models beside a scripted controller.

    python benchmarks/catch_point_failures.py LABEL=MODEL [LABEL=MODEL ...] [--episodes 1000] [--record FILE]

MODEL is a run directory or a checkpoint (``pamdp evaluate`` reads the same). Every model, and the scripted
controller, plays the same episodes (``reset(seed=10_000 + k)``, seeds no training run evaluates on), greedy.
The record (default ``benchmarks/catch_point_failures.md``, its hand-written notes kept) tables for each: the
success rate; how the failed episodes ended (the 25-step limit, or 11 failed catches); the failure rate by the
target's starting distance and by its direction; the median heading error of the moves (the angle between the
push and the straight line to the target) and the failed catches per episode.

The scripted controller pushes straight at the target and catches when the force-free next position (the
velocity decays by 0.75 before the move, catch_point.md §4) is within the catch radius: no learner, an
estimate of what the domain allows within 25 steps.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import gymnasium
import numpy as np

import pamdp  # noqa: F401  (registers the envs)
from pamdp.algos import load_model
from pamdp.envs import particle

sys.path.insert(0, str(Path(__file__).parent))
from _record import HERE, record_head, write_record  # noqa: E402

ENV = "pamdp/CatchPoint-v0"
FIRST_SEED = 10_000
DISTANCE_BINS = np.array([0.0, 0.4, 0.8, 1.2, 1.6, 2.0, 2 * math.sqrt(2)])
DIRECTION_BINS = 8
"""Target directions, measured like the heading (radians from +y towards +x), in bins of 45 degrees from -pi."""


def scripted(obs: np.ndarray) -> tuple[int, float]:
    """Push straight at the target; catch when the force-free next position is within the catch radius."""
    vx, vy, dx, dy = obs
    nx, ny = dx - (1.0 - particle.DAMPING) * vx * particle.DT, dy - (1.0 - particle.DAMPING) * vy * particle.DT
    if nx * nx + ny * ny <= particle.RADIUS_SQUARED:
        return particle.CATCH, 0.0
    return particle.MOVE, math.atan2(dx, dy)


def play(policy, episodes: int) -> np.ndarray:
    """One row per episode: start distance, target direction, success, ended by the step limit, failed
    catches, median heading error of its moves (nan without moves)."""
    env = gymnasium.make(ENV)
    rows = []
    for k in range(episodes):
        obs, _ = env.reset(seed=FIRST_SEED + k)
        distance, direction = math.hypot(obs[2], obs[3]), math.atan2(obs[2], obs[3])
        errors, catches = [], 0
        while True:
            a, theta = policy(obs)
            if a == particle.MOVE:
                errors.append(abs((theta - math.atan2(obs[2], obs[3]) + math.pi) % (2 * math.pi) - math.pi))
            else:
                catches += 1
            action = (a, (np.array([theta], dtype=np.float32), np.zeros(0, dtype=np.float32)))
            obs, _, terminated, truncated, info = env.step(action)
            if terminated or truncated:
                success = bool(info["is_success"])
                error = np.median(errors) if errors else np.nan
                rows.append((distance, direction, success, truncated, catches - success, error))
                break
    env.close()
    return np.array(rows, dtype=float)


def model_policy(path: str):
    model = load_model(path)

    def policy(obs):
        a, params = model.predict(obs, deterministic=True)
        return int(np.asarray(a).item()), float(np.asarray(params[0]).ravel()[0])

    return policy


def rates_by(values: np.ndarray, failed: np.ndarray, edges: np.ndarray) -> str:
    """``failure rate (episodes)`` per bin of ``values``."""
    idx = np.clip(np.digitize(values, edges) - 1, 0, len(edges) - 2)
    cells = []
    for b in range(len(edges) - 1):
        n = int((idx == b).sum())
        cells.append(f"{failed[idx == b].mean():.2f} ({n})" if n else "- (0)")
    return " / ".join(cells)


def row(label: str, r: np.ndarray) -> str:
    failed = r[:, 2] == 0
    f = r[failed]
    directions = np.linspace(-math.pi, math.pi, DIRECTION_BINS + 1)
    moves = r[~np.isnan(r[:, 5]), 5]
    return (
        f"| {label} | {1 - failed.mean():.3f} | {int(f[:, 3].sum())} / {int((f[:, 3] == 0).sum())} | "
        f"{rates_by(r[:, 0], failed, DISTANCE_BINS)} | {rates_by(r[:, 1], failed, directions)} | "
        f"{np.median(moves):.3f} | {r[:, 4].mean():.2f} |"
    )


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("models", nargs="+", help="LABEL=MODEL: a run directory or checkpoint, and its row's label")
    p.add_argument("--episodes", type=int, default=1000)
    p.add_argument("--record", default=str(HERE / "catch_point_failures.md"))
    a = p.parse_args()
    pairs = []
    for item in a.models:
        label, sep, path = item.partition("=")
        if not sep or not label or not path:
            p.error(f"model {item!r}: expected LABEL=PATH")
        pairs.append((label, path))
    rows = [row("scripted controller", play(scripted, a.episodes))]
    print(rows[-1], flush=True)
    for label, path in pairs:
        rows.append(row(label, play(model_policy(path), a.episodes)))
        print(rows[-1], flush=True)
    distance = " / ".join(f"{lo:.1f}-{hi:.1f}" for lo, hi in zip(DISTANCE_BINS[:-1], DISTANCE_BINS[1:]))
    lines = record_head("Where trained Catch Point agents fail", f"python {' '.join(sys.argv)}") + [
        f"- {a.episodes} greedy episodes each, `reset(seed={FIRST_SEED} + k)`, the same for every row",
        "",
        f"| agent | success | failures: 25 steps / 11 failed catches | failure rate by start distance ({distance}) "
        f"| failure rate by target direction (45-degree bins from -pi, radians from +y towards +x) "
        "| median heading error of a move (rad) | failed catches per episode |",
        "|---|---|---|---|---|---|---|",
        *rows,
    ]
    write_record(lines, a.record)


if __name__ == "__main__":
    main()
