"""Half Field Offense: environment steps per second and the scripted scorer's goal rate.

Run ``.venv/bin/python benchmarks/bench_hfo.py`` (about a minute); it rewrites ``benchmarks/hfo_speed.md``.
Actions are sampled before timing, so the figures are the env's own cost. Each figure is the median
over repeats; another process may be using the machine's other core, so the load average is recorded.
"""

from __future__ import annotations

import argparse
import datetime
import os
import pathlib
import platform
import statistics
import sys
import time

import gymnasium
import numpy as np

import pamdp  # noqa: F401  (registers the envs)
from pamdp.envs.hfo import HalfFieldOffenseEnv, HalfFieldOffenseVectorEnv
from pamdp.envs.hfo_baseline import scripted_scorer_batch


def scalar_steps_per_second(env, steps: int, repeats: int, seed: int = 0) -> float:
    """Median steps/s of one env under uniformly random actions (resets included)."""
    env.action_space.seed(seed)
    actions = [env.action_space.sample() for _ in range(2000)]
    env.reset(seed=seed)
    rates = []
    for _ in range(repeats):
        start = time.perf_counter()
        for k in range(steps):
            _, _, terminated, truncated, _ = env.step(actions[k % len(actions)])
            if terminated or truncated:
                env.reset()
        rates.append(steps / (time.perf_counter() - start))
    return statistics.median(rates)


def batched_steps_per_second(num_envs: int, steps: int, repeats: int, seed: int = 0) -> float:
    """Median env-steps/s of the batched env under uniformly random actions (autoresets included)."""
    env = gymnasium.make_vec("pamdp/HalfFieldOffense-v0", num_envs=num_envs, vectorization_mode="vector_entry_point")
    env.action_space.seed(seed)
    actions = [env.action_space.sample() for _ in range(16)]
    env.reset(seed=seed)
    for k in range(10):
        env.step(actions[k % len(actions)])
    rates = []
    for _ in range(repeats):
        start = time.perf_counter()
        for k in range(steps):
            env.step(actions[k % len(actions)])
        rates.append(steps * num_envs / (time.perf_counter() - start))
    return statistics.median(rates)


def scorer_results(episodes: int, num_envs: int = 250, seed: int = 0) -> tuple[float, float, dict]:
    """Goal rate and mean steps to goal of the scripted scorer (actuator noise on), first ``episodes``."""
    env = HalfFieldOffenseVectorEnv(num_envs=num_envs)
    obs, _ = env.reset(seed=seed)
    outcomes, goal_steps = {}, []
    while sum(outcomes.values()) < episodes:
        obs, _, terminated, truncated, info = env.step(scripted_scorer_batch(obs))
        for i in np.flatnonzero(terminated | truncated):
            if sum(outcomes.values()) == episodes:
                break
            status = str(info["status"][i])
            outcomes[status] = outcomes.get(status, 0) + 1
            if status == "GOAL":
                goal_steps.append(int(info["step"][i]))
    return outcomes.get("GOAL", 0) / episodes, float(np.mean(goal_steps)), outcomes


def cpu_model() -> str:
    try:
        for line in pathlib.Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeats", type=int, default=5, help="timed repeats; the median is reported")
    parser.add_argument("--scalar-steps", type=int, default=20_000, help="steps per scalar repeat")
    parser.add_argument("--batched-steps", type=int, default=100, help="batched steps per repeat")
    parser.add_argument("--num-envs", type=int, default=1024, help="games in the batched env")
    parser.add_argument("--episodes", type=int, default=1000, help="scripted-scorer episodes")
    parser.add_argument("--out", default=str(pathlib.Path(__file__).with_name("hfo_speed.md")))
    args = parser.parse_args()

    load_before = os.getloadavg()[0]
    raw = scalar_steps_per_second(HalfFieldOffenseEnv(), args.scalar_steps, args.repeats)
    made = scalar_steps_per_second(gymnasium.make("pamdp/HalfFieldOffense-v0"), args.scalar_steps, args.repeats)
    batched = batched_steps_per_second(args.num_envs, args.batched_steps, args.repeats)
    goal_rate, goal_steps, outcomes = scorer_results(args.episodes)
    load_after = os.getloadavg()[0]

    command = "python benchmarks/bench_hfo.py " + " ".join(sys.argv[1:])
    rows = [
        ("scalar `HalfFieldOffenseEnv`, random actions", f"{raw:,.0f} steps/s", ">= 20 000"),
        ("scalar via `gymnasium.make` (wrappers)", f"{made:,.0f} steps/s", ""),
        (f"batched `HalfFieldOffenseVectorEnv`, N = {args.num_envs}", f"{batched:,.0f} steps/s", ">= 1 000 000"),
        (
            f"scripted scorer, {args.episodes} episodes (noise on)",
            f"goal rate {goal_rate:.3f}, {goal_steps:.1f} steps to goal",
            "real HFO: almost always, ~70 steps",
        ),
    ]
    text = [
        "# Half Field Offense: speed and scripted-scorer results",
        "",
        f"Command: `{command.strip()}`  ",
        f"Date: {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M UTC}  ",
        f"Machine: {cpu_model()}, {os.cpu_count()} cores; Python {platform.python_version()}, "
        f"NumPy {np.__version__}, Gymnasium {gymnasium.__version__}  ",
        f"Load average (1 min) before / after: {load_before:.2f} / {load_after:.2f} (other engineers' jobs "
        "may share the cores; figures are medians of "
        f"{args.repeats} repeats)",
        "",
        "| measurement | result | target |",
        "|---|---|---|",
        *[f"| {a} | {b} | {c} |" for a, b, c in rows],
        "",
        f"Scorer outcomes: {outcomes}.",
        "",
    ]
    pathlib.Path(args.out).write_text("\n".join(text))
    print("\n".join(text))


if __name__ == "__main__":
    main()
