"""A mainstream library on Platform through pamdp's wrappers: Stable-Baselines3's SAC and DQN as baselines.

    pip install -c constraints.txt stable-baselines3      # not a pamdp dependency
    python benchmarks/bench_mainstream_platform.py [--steps 100000] [--seeds 0,1,2] [--bins 9] [--workers 2]
        [--out DIR]

What a user who cannot use a parameterized-action algorithm would do: SAC on the flattened action
(``FlattenHybridAction``: 3 scores and the 3 parameters in one Box, PADDPG's representation) and DQN on a
grid (``DiscretizeHybridAction``: each action's parameter on ``--bins`` values), both with SB3's default
settings, one torch thread per run. Each run ends with a greedy evaluation over 1000 episodes (the same
count as pamdp's benchmarks). Results per run go to ``DIR/mainstream_platform/ALGO/seedN/result.json``;
finished runs are skipped when the script runs again, and an interrupted run resumes from its last checkpoint
(model and replay buffer every 10 000 steps; the resumed run's random streams differ from an uninterrupted
one's). Writes ``benchmarks/mainstream_platform.md`` with the command, date and machine.
"""

from __future__ import annotations

import argparse
import concurrent.futures as cf
import datetime as dt
import json
import multiprocessing
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).parent
ALGOS = ("SAC", "DQN")


def make_env(algo: str, bins: int):
    import gymnasium

    import pamdp  # noqa: F401  (registers the envs)
    from pamdp.wrappers import DiscretizeHybridAction, FlattenHybridAction

    env = gymnasium.make("pamdp/Platform-v0")
    return FlattenHybridAction(env) if algo == "SAC" else DiscretizeHybridAction(env, bins=bins)


def greedy_return(model, env, episodes: int, seed: int) -> float:
    """Mean undiscounted return of ``model``'s deterministic actions over ``episodes`` episodes."""
    total = 0.0
    for e in range(episodes):
        obs, _ = env.reset(seed=seed + e)
        done = False
        while not done:
            action, _ = model.predict(obs, deterministic=True)
            obs, reward, terminated, truncated, _ = env.step(action)
            total += float(reward)
            done = terminated or truncated
    return total / episodes


CHECKPOINT_EVERY = 10_000  # env steps between checkpoints of a run (model, replay buffer, training time)


def run(algo: str, seed: int, steps: int, bins: int, out: str) -> dict:
    import torch
    from stable_baselines3 import DQN, SAC
    from stable_baselines3.common.callbacks import BaseCallback

    torch.set_num_threads(1)
    out = Path(out)
    result_file = out / "result.json"
    if result_file.exists():
        return json.loads(result_file.read_text())
    out.mkdir(parents=True, exist_ok=True)
    cls = SAC if algo == "SAC" else DQN
    model_file, buffer_file, clock_file = out / "checkpoint.zip", out / "replay.pkl", out / "checkpoint.json"
    if model_file.exists() and buffer_file.exists() and clock_file.exists():  # resume an interrupted run
        model = cls.load(model_file, env=make_env(algo, bins))
        model.load_replay_buffer(buffer_file)
        trained = json.loads(clock_file.read_text())["train_seconds"]
    else:
        model = cls("MlpPolicy", make_env(algo, bins), seed=seed, verbose=0)
        trained = 0.0
    t0 = time.time()

    class Checkpoint(BaseCallback):
        """Every CHECKPOINT_EVERY steps: the model, its replay buffer and the training time, each file replaced
        atomically, the clock last (a resume needs all three)."""

        def _on_step(self) -> bool:
            if self.num_timesteps % CHECKPOINT_EVERY == 0 and self.num_timesteps < steps:
                self.model.save(out / "checkpoint.tmp.zip")
                os.replace(out / "checkpoint.tmp.zip", model_file)
                self.model.save_replay_buffer(out / "replay.tmp.pkl")
                os.replace(out / "replay.tmp.pkl", buffer_file)
                clock = {"train_seconds": trained + time.time() - t0, "steps": self.num_timesteps}
                (out / "checkpoint.tmp.json").write_text(json.dumps(clock))
                os.replace(out / "checkpoint.tmp.json", clock_file)
            return True

    # Counting on from the checkpoint keeps the schedules (DQN's exploration) where an uninterrupted run has them.
    model.learn(steps - model.num_timesteps, reset_num_timesteps=False, callback=Checkpoint())
    seconds = trained + time.time() - t0
    result = {
        "algo": algo,
        "seed": seed,
        "steps": steps,
        "bins": bins if algo == "DQN" else None,
        "train_seconds": seconds,
        "greedy_return": greedy_return(model, make_env(algo, bins), 1000, 10_000 + seed),
    }
    result_file.write_text(json.dumps(result, indent=2))
    for f in (model_file, buffer_file, clock_file):  # the replay buffer is large; the result is what stays
        f.unlink(missing_ok=True)
    return result


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--steps", type=int, default=100_000)
    p.add_argument("--seeds", default="0,1,2")
    p.add_argument("--bins", type=int, default=9)
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--out", default="results/bench")
    a = p.parse_args()
    try:
        import stable_baselines3
    except ModuleNotFoundError:
        sys.exit("this benchmark needs Stable-Baselines3: pip install -c constraints.txt stable-baselines3")
    seeds = [int(s) for s in a.seeds.split(",")]
    jobs = [(algo, s, str(Path(a.out) / "mainstream_platform" / algo / f"seed{s}")) for algo in ALGOS for s in seeds]
    record = HERE / "mainstream_platform.md"
    finished_before = all((Path(out) / "result.json").exists() for _, _, out in jobs)
    results = []
    t0 = time.time()
    ctx = multiprocessing.get_context("spawn")
    with cf.ProcessPoolExecutor(max_workers=a.workers, mp_context=ctx) as pool:
        futures = {pool.submit(run, algo, s, a.steps, a.bins, out): (algo, s) for algo, s, out in jobs}
        for fut in cf.as_completed(futures):
            r = fut.result()
            print(f"{r['algo']} seed {r['seed']}: greedy return {r['greedy_return']:.3f}", flush=True)
            results.append(r)
    wall = time.time() - t0
    if finished_before and record.exists():  # nothing new ran: the record already says what the runs gave
        print(json.dumps({"record": str(record), "unchanged": "every run had finished before"}))
        return
    sys.path.insert(0, str(HERE))
    from _record import hand_notes, machine

    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, cwd=HERE)
    lines = [
        "# Stable-Baselines3 on Platform through pamdp's action wrappers",
        "",
        f"- command: `python {' '.join(sys.argv)}` (commit {commit.stdout.strip()})",
        f"- date: {dt.datetime.now().isoformat(timespec='minutes')}",
        f"- machine: {machine()}; stable-baselines3 {stable_baselines3.__version__}",
        f"- {len(jobs)} runs of {a.steps:,} steps, {a.workers} at a time; this invocation took {wall / 60:.1f} min",
        "",
        "| algorithm | action space | seeds | greedy return (mean +- std over seeds; 1000 episodes each) | "
        "training time per run (median) |",
        "|---|---|---|---|---|",
    ]
    for algo in ALGOS:
        rs = sorted((r for r in results if r["algo"] == algo), key=lambda r: r["seed"])
        rets = [r["greedy_return"] for r in rs]
        space = "FlattenHybridAction: Box(6)" if algo == "SAC" else f"DiscretizeHybridAction: Discrete({3 * a.bins})"
        spread = statistics.pstdev(rets) if len(rets) > 1 else 0.0
        per_seed = ", ".join(f"{x:.3f}" for x in rets)
        minutes = statistics.median(r["train_seconds"] for r in rs) / 60
        lines.append(
            f"| SB3 {algo} (defaults) | {space} | {len(rs)} | {statistics.mean(rets):.3f} +- {spread:.3f} "
            f"({per_seed}) | {minutes:.1f} min |"
        )
    lines += [
        "",
        "For comparison (same machine, pamdp's records): PATRPO tuned 0.978 +- 0.041 over 5 x 1M samples,",
        "and its paper preset 1.000 ([patrpo_platform.md](patrpo_platform.md)); P-DQN 0.985 and PAPPO 0.985 over",
        "5 x 300k ([later_platform.md](later_platform.md)); a uniformly random policy 0.154.",
    ]
    notes = hand_notes(record)  # a rerun keeps what was written about the runs by hand
    record.write_text("\n".join(lines) + "\n" + ("\n" + notes + "\n" if notes else ""))
    print(json.dumps({"record": str(HERE / "mainstream_platform.md"), "wall_minutes": wall / 60}))


if __name__ == "__main__":
    main()
