"""Steps per CPU-second of every pamdp env, scalar and batched, under uniformly random actions.

Run ``python benchmarks/bench_envs.py --cpu 1`` (a few minutes); it rewrites ``benchmarks/env_speed.md``, keeping
its section ``## Notes (written by hand)``. For each registered env (Hard Move at each n of the benchmark suite):
the scalar env from ``gymnasium.make`` (resets included) and the batched env at ``--num-envs`` copies
(autoresets included), and again with the parameter boxes stacked in one array where they share one shape and
the batched env takes that format (Hard Move), each the median over ``--repeats`` timings of
``time.process_time`` (this process's CPU time, which another process on the core does not inflate). Actions are
sampled before timing. An env whose module is missing or fails to build is skipped, and the record says which
and why.

First it times Numba's compilation: a fresh process that imports pamdp, makes every env (scalar and batched),
resets and steps it once, run twice with ``NUMBA_CACHE_DIR`` set to an empty folder: cold (everything compiled
and written to the cache) and warm (everything loaded from it), each the child's CPU seconds.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import gymnasium
import numpy as np

import pamdp  # noqa: F401  (registers the envs)
from pamdp.envs import _REGISTRATIONS

sys.path.insert(0, str(Path(__file__).parent))
from _record import record_head, write_record  # noqa: E402

HERE = Path(__file__).parent
SUITE_KWARGS = {"pamdp/HardMove-v0": [{"n": n} for n in (4, 6, 8, 10)]}
MIN_ENV_STEPS = 20_000  # env steps per timed repeat (batched: batched steps times copies)


def cases() -> list[tuple[str, dict]]:
    return [(env_id, kw) for env_id in _REGISTRATIONS for kw in SUITE_KWARGS.get(env_id, [{}])]


def scalar_rate(env, actions, steps: int) -> float:
    start = time.process_time()
    for k in range(steps):
        _, _, terminated, truncated, _ = env.step(actions[k % len(actions)])
        if terminated or truncated:
            env.reset()
    return steps / (time.process_time() - start)


def batched_rate(env, actions, steps: int) -> float:
    start = time.process_time()
    for k in range(steps):
        env.step(actions[k % len(actions)])
    return steps * env.num_envs / (time.process_time() - start)


def stacked(action):
    """A batched action with its parameter boxes stacked in one ``(K, N, m)`` array, or ``None`` where the boxes
    differ in shape (the format Hard Move's batched env also takes)."""
    a, params = action
    return (a, np.stack(params)) if len({p.shape for p in params}) == 1 else None


def measure(env_id: str, kwargs: dict, num_envs: int, repeats: int, scalar_steps: int) -> tuple[float, ...]:
    """Median scalar, batched and batched-with-stacked-parameters env-steps per CPU-second (the last ``nan``
    where the env takes no stacked parameters)."""
    scalar = gymnasium.make(env_id, **kwargs)
    scalar.reset(seed=0)
    scalar.action_space.seed(0)
    k = scalar.action_space[0].n  # a sample draws every action's box: fewer distinct actions where K is large
    actions = [scalar.action_space.sample() for _ in range(max(20, min(1000, 20_000 // k)))]
    batched = gymnasium.make_vec(env_id, num_envs=num_envs, vectorization_mode="vector_entry_point", **kwargs)
    batched.reset(seed=0)
    batched.action_space.seed(0)
    batched_actions = [batched.action_space.sample() for _ in range(16)]
    batched_steps = max(1, MIN_ENV_STEPS // num_envs)
    scalar_rate(scalar, actions, 200)  # Numba's compilation and the first resets, untimed
    batched_rate(batched, batched_actions, 5)
    stacked_actions = [stacked(action) for action in batched_actions]
    if stacked_actions[0] is not None:
        try:
            batched_rate(batched, stacked_actions, 5)
        except ValueError:  # the env reads only a tuple of boxes
            stacked_actions = [None]
    rates = {"scalar": [], "batched": [], "stacked": []}
    for _ in range(repeats):
        rates["scalar"].append(scalar_rate(scalar, actions, scalar_steps))
        rates["batched"].append(batched_rate(batched, batched_actions, batched_steps))
        if stacked_actions[0] is not None:
            rates["stacked"].append(batched_rate(batched, stacked_actions, batched_steps))
    scalar.close()
    batched.close()
    return tuple(statistics.median(r) if r else float("nan") for r in rates.values())


FIRST_USE = """
import gymnasium, pamdp
from pamdp.envs import _REGISTRATIONS
for env_id in _REGISTRATIONS:
    for make in (gymnasium.make, lambda i: gymnasium.make_vec(i, 2, vectorization_mode="vector_entry_point")):
        env = make(env_id)
        env.action_space.seed(0)
        env.reset(seed=0)
        env.step(env.action_space.sample())
"""


def compile_seconds() -> tuple[float, float]:
    """CPU seconds of a fresh process's first use of every env with an empty Numba cache (cold), then again
    with the cache that run wrote (warm)."""
    times = []
    with tempfile.TemporaryDirectory() as cache:
        for _ in range(2):
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            env = {**os.environ, "NUMBA_CACHE_DIR": cache}
            subprocess.run([sys.executable, "-c", FIRST_USE], check=True, env=env)
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            times.append(after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime)
    return times[0], times[1]


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--num-envs", type=int, default=1024)
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--scalar-steps", type=int, default=5_000)
    p.add_argument("--cpu", type=int, default=None, help="pin this process to one core (as taskset -c N)")
    p.add_argument("--record", default=str(HERE / "env_speed.md"))
    a = p.parse_args()
    if a.cpu is not None:
        os.sched_setaffinity(0, {a.cpu})
    cold, warm = compile_seconds()
    print(f"first use of every env: {cold:.1f} CPU-s cold, {warm:.1f} CPU-s warm", flush=True)
    rows, skipped = [], []
    for env_id, kwargs in cases():
        name = env_id + (f" {kwargs}" if kwargs else "")
        try:
            scalar, batched, stack = measure(env_id, kwargs, a.num_envs, a.repeats, a.scalar_steps)
        except Exception as exc:  # a domain whose module has not landed, or does not build
            skipped.append(f"- {name}: {type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''}")
            continue
        in_stack = "-" if np.isnan(stack) else f"{stack:,.0f} ({stack / scalar:,.0f}x)"
        rows.append(f"| {name} | {scalar:,.0f} | {batched:,.0f} | {batched / scalar:,.0f}x | {in_stack} |")
        print(rows[-1], flush=True)
    title = "Environment speed: steps per CPU-second, scalar and batched"
    lines = record_head(title, f"python {' '.join(sys.argv)}") + [
        f"- uniformly random actions sampled before timing; median of {a.repeats} timings of this process's CPU "
        f"time; scalar: {a.scalar_steps:,} steps of `gymnasium.make`'s env a timing, resets included; batched: "
        f"{a.num_envs:,} copies, at least {MIN_ENV_STEPS:,} env steps a timing, autoresets included"
        + (f"; pinned to core {a.cpu}" if a.cpu is not None else ""),
        f"- Numba: a fresh process's first use of every env (import, make scalar and batched, reset, step) takes "
        f"{cold:.1f} CPU-s with an empty cache (compiling) and {warm:.1f} CPU-s with the cache it wrote",
        "",
        f"| env | scalar steps/s | batched steps/s ({a.num_envs:,} copies) | batched / scalar "
        "| batched, parameters stacked in one (K, N, m) array |",
        "|---|---|---|---|---|",
        *rows,
    ]
    if skipped:
        lines += ["", "Skipped (not importable or not built at this commit):", *skipped]
    write_record(lines, a.record)


if __name__ == "__main__":
    main()
