"""Half Field Offense: environment steps per second and the scripted scorer's goal rate.

Run ``.venv/bin/python benchmarks/bench_hfo.py`` (a few minutes); it rewrites ``benchmarks/hfo_speed.md``,
keeping the record's section ``## Notes (written by hand)`` as it is. Actions are sampled before timing,
so the figures are the env's own cost. Each figure is the median over repeats of steps per CPU-second of
this process (``time.process_time``): another process may be using the machine's cores, and CPU time does
not count the time spent waiting for one. The load average is recorded too.

``--baseline COMMIT`` also times the HFO envs of that git commit (its ``src/pamdp/envs`` exported to a
temporary directory and imported as a package of its own), interleaved repeat by repeat with the working
tree's, so that both see the same load. ``--cpu 0`` pins the process to one core (as ``taskset -c 0``).
"""

from __future__ import annotations

import argparse
import datetime
import importlib
import io
import os
import pathlib
import platform
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time

import gymnasium
import numba
import numpy as np

import pamdp  # noqa: F401  (registers the envs)
from pamdp.envs import hfo
from pamdp.envs.hfo import scripted_scorer_batch

#: Batched steps before timing: the games, all placed at once, first time out together near step 100.
BATCHED_WARMUP = 200
#: Fewest env steps (batched steps times games) per timed repeat of a batched env.
BATCHED_ENV_STEPS = 20_000
NOTES = "## Notes (written by hand)"


def import_baseline(commit: str):
    """The ``hfo`` module (or package) of ``commit``: its ``src/pamdp/envs`` exported to a temporary directory
    as package ``envs_at_baseline``, every ``pamdp.envs`` import pointed there."""
    repo = pathlib.Path(__file__).resolve().parents[1]
    archive = subprocess.run(
        ["git", "archive", commit, "src/pamdp/envs"], cwd=repo, capture_output=True, check=True
    ).stdout
    root = pathlib.Path(tempfile.mkdtemp())
    with tarfile.open(fileobj=io.BytesIO(archive)) as tar:
        tar.extractall(root, filter="data")
    package = root / "envs_at_baseline"
    (root / "src" / "pamdp" / "envs").rename(package)
    for path in package.rglob("*.py"):
        path.write_text(path.read_text().replace("pamdp.envs", "envs_at_baseline"))
    sys.path.insert(0, str(root))
    return importlib.import_module("envs_at_baseline.hfo")


def scalar_rate(env, actions, steps: int) -> float:
    """Steps per CPU-second of one env over ``steps`` steps of ``actions`` (resets included)."""
    start = time.process_time()
    for k in range(steps):
        _, _, terminated, truncated, _ = env.step(actions[k % len(actions)])
        if terminated or truncated:
            env.reset()
    return steps / (time.process_time() - start)


def batched_rate(env, actions, steps: int) -> float:
    """Env-steps per CPU-second of a batched env over ``steps`` batched steps (autoresets included)."""
    start = time.process_time()
    for k in range(steps):
        env.step(actions[k % len(actions)])
    return steps * env.num_envs / (time.process_time() - start)


def speeds(modules: dict, args) -> dict:
    """Median steps/s of each module's scalar env, scalar env via ``gymnasium.make`` (current only) and
    batched env at each of ``args.num_envs`` sizes, repeats interleaved across modules."""
    space = hfo.HalfFieldOffenseEnv().action_space
    space.seed(0)
    scalar_actions = [space.sample() for _ in range(2000)]
    batched_actions = {}
    for n in args.num_envs:
        batched_space = hfo.HalfFieldOffenseVectorEnv(num_envs=n).action_space
        batched_space.seed(0)
        batched_actions[n] = [batched_space.sample() for _ in range(16)]
    envs = {}
    for name, module in modules.items():
        envs[name] = {"scalar": module.HalfFieldOffenseEnv()}
        envs[name]["scalar"].reset(seed=0)
        for n in args.num_envs:
            batched = module.HalfFieldOffenseVectorEnv(num_envs=n)
            batched.reset(seed=0)
            batched_rate(batched, batched_actions[n], BATCHED_WARMUP)  # includes Numba's compilation
            envs[name][n] = batched
    envs["current"]["made"] = gymnasium.make("pamdp/HalfFieldOffense-v0")
    envs["current"]["made"].reset(seed=0)
    rates = {name: {kind: [] for kind in kinds} for name, kinds in envs.items()}
    for _ in range(args.repeats):
        for name, kinds in envs.items():
            for kind, env in kinds.items():
                if kind not in ("scalar", "made"):
                    # small batches take more steps, so that each repeat times enough env steps
                    steps = max(args.batched_steps, BATCHED_ENV_STEPS // kind)
                    rates[name][kind].append(batched_rate(env, batched_actions[kind], steps))
                else:
                    rates[name][kind].append(scalar_rate(env, scalar_actions, args.scalar_steps))
    return {name: {kind: statistics.median(r) for kind, r in kinds.items()} for name, kinds in rates.items()}


def scorer_results(episodes: int, num_envs: int = 250, seed: int = 0) -> tuple[float, float, dict]:
    """Goal rate and mean steps to goal of the scripted scorer (actuator noise on), first ``episodes``."""
    env = hfo.HalfFieldOffenseVectorEnv(num_envs=num_envs)
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
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=5, help="timed repeats; the median is reported")
    parser.add_argument("--scalar-steps", type=int, default=20_000, help="steps per scalar repeat")
    parser.add_argument("--batched-steps", type=int, default=100, help="batched steps per repeat (more for small N)")
    parser.add_argument(
        "--num-envs", type=int, nargs="+", default=[1024], help="games in the batched env (several: one row each)"
    )
    parser.add_argument("--episodes", type=int, default=1000, help="scripted-scorer episodes")
    parser.add_argument("--baseline", metavar="COMMIT", help="also time this commit's HFO envs, interleaved")
    parser.add_argument("--cpu", type=int, help="pin the process to this core")
    parser.add_argument("--out", default=str(pathlib.Path(__file__).with_name("hfo_speed.md")))
    args = parser.parse_args()
    if args.cpu is not None:
        os.sched_setaffinity(0, {args.cpu})

    modules = {"current": hfo}
    if args.baseline:
        modules["baseline"] = import_baseline(args.baseline)
    load_before = os.getloadavg()[0]
    rates = speeds(modules, args)
    goal_rate, goal_steps, outcomes = scorer_results(args.episodes)
    load_after = os.getloadavg()[0]

    def result(kind) -> str:
        text = f"{rates['current'][kind]:,.0f} steps/s"
        if args.baseline:
            before = rates["baseline"][kind]
            text += f" (baseline {before:,.0f}, x{rates['current'][kind] / before:.2f})"
        return text

    command = "python benchmarks/bench_hfo.py " + " ".join(sys.argv[1:])
    rows = [
        ("scalar `HalfFieldOffenseEnv`, random actions", result("scalar"), ">= 20 000"),
        ("scalar via `gymnasium.make` (wrappers)", f"{rates['current']['made']:,.0f} steps/s", ""),
        *(
            (f"batched `HalfFieldOffenseVectorEnv`, N = {n}", result(n), ">= 1 000 000" if n == 1024 else "")
            for n in args.num_envs
        ),
        (
            f"scripted scorer, {args.episodes} episodes (noise on)",
            f"goal rate {goal_rate:.3f}, {goal_steps:.1f} steps to goal",
            "real HFO: almost always, ~70 steps",
        ),
    ]
    baseline = ""
    if args.baseline:
        baseline = f"Baseline: commit `{args.baseline}`, timed in the same process, repeats interleaved.  "
    text = [
        "# Half Field Offense: speed and scripted-scorer results",
        "",
        f"Command: `{command.strip()}`  ",
        f"Date: {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M UTC}  ",
        f"Machine: {cpu_model()}, {os.cpu_count()} cores; Python {platform.python_version()}, "
        f"NumPy {np.__version__}, Gymnasium {gymnasium.__version__}, Numba {numba.__version__}  ",
        f"Load average (1 min) before / after: {load_before:.2f} / {load_after:.2f} (other engineers' jobs "
        "may share the cores; figures are env steps per CPU-second of the process, medians of "
        f"{args.repeats} repeats; batched after {BATCHED_WARMUP} warm-up steps, so autoresets are included)  ",
        *([baseline] if baseline else []),
        "",
        "| measurement | result | target |",
        "|---|---|---|",
        *[f"| {a} | {b} | {c} |" for a, b, c in rows],
        "",
        f"Scorer outcomes: {outcomes}.",
        "",
    ]
    out = pathlib.Path(args.out)
    old = out.read_text() if out.exists() else ""
    if NOTES in old:
        text += [old[old.index(NOTES) :].rstrip("\n"), ""]
    out.write_text("\n".join(text))
    print("\n".join(text))


if __name__ == "__main__":
    main()
