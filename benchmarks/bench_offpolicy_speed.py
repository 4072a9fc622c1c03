"""Training speed of the off-policy algorithms: gradient updates per second and env samples per second.

For each algorithm and preset, a model is warmed up (replay filled past ``learning_starts``), then
measured ``--repeats`` times:

- updates/s: ``_update()`` calls (one critic and one actor step on a replayed minibatch) per second;
- samples/s: environment samples per second during training, i.e. whole epochs of collecting and
  learning at the preset's update-to-data ratio (``learn()``'s own loop).

Medians over the repeats are written as a markdown record with the command, date and machine.

    python benchmarks/bench_offpolicy_speed.py --out benchmarks/offpolicy_speed.md
"""

from __future__ import annotations

import argparse
import dataclasses
import datetime as dt
import os
import platform
import statistics
import sys
import time

import torch

from pamdp.algos.paddpg import PADDPG, PADDPGConfig
from pamdp.algos.pasvg import PASVG0, PASVG0Config

CASES = [
    ("PASVG0", PASVG0, PASVG0Config, "paper"),
    ("PASVG0", PASVG0, PASVG0Config, "tuned"),
    ("PADDPG", PADDPG, PADDPGConfig, "paper"),
    ("PADDPG", PADDPG, PADDPGConfig, "hausknecht_stone"),
]


def cpu_name() -> str:
    try:
        with open("/proc/cpuinfo") as f:
            return next(line.split(":", 1)[1].strip() for line in f if line.startswith("model name"))
    except (OSError, StopIteration):
        return platform.processor() or platform.machine()


def measure(cls, config, n_updates: int, n_samples: int, repeats: int) -> dict:
    config = dataclasses.replace(config, learning_starts=n_samples, epoch_steps=n_samples, buffer_size=200_000)
    model = cls("pamdp/Platform-v0", config)
    torch.set_num_threads(config.torch_threads)
    model.learn(n_samples, progress_bar=False)  # fills the buffer past learning_starts and warms up
    updates, samples = [], []
    for _ in range(repeats):
        t = time.perf_counter()
        for _ in range(n_updates):
            model._update()
        updates.append(n_updates / (time.perf_counter() - t))
        start = model.num_timesteps
        t = time.perf_counter()
        model.learn(n_samples, progress_bar=False)
        samples.append((model.num_timesteps - start) / (time.perf_counter() - t))
    return {"updates_per_s": statistics.median(updates), "samples_per_s": statistics.median(samples)}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--updates", type=int, default=300, help="updates per repeat")
    parser.add_argument("--samples", type=int, default=1_000, help="env samples per repeat (one epoch)")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--out", default="benchmarks/offpolicy_speed.md")
    args = parser.parse_args(argv)

    lines = [
        "# Off-policy training speed (PASVG(0), PADDPG) on Platform",
        "",
        f"- command: `python {' '.join(sys.argv)}`",
        f"- date: {dt.datetime.now().isoformat(timespec='seconds')}",
        f"- machine: {cpu_name()}, {os.cpu_count()} CPUs (shared with other jobs), "
        f"load average at start {os.getloadavg()[0]:.1f}; Python {platform.python_version()}, "
        f"torch {torch.__version__}",
        f"- medians of {args.repeats} repeats; {args.updates} updates and {args.samples} samples per repeat; "
        "torch threads 1; samples/s is whole training epochs (collect + learn at the preset's update-to-data ratio)",
        "",
        "| algorithm | preset | hidden layers | batch | num_envs | updates/sample | updates/s "
        "| samples/s during training |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for name, cls, config_class, preset in CASES:
        cfg = config_class.preset(preset)
        r = measure(cls, cfg, args.updates, args.samples, args.repeats)
        lines.append(
            f"| {name} | {preset} | {'-'.join(map(str, cfg.hidden_sizes))} | {cfg.batch_size} | {cfg.num_envs} | "
            f"{cfg.updates_per_step:g} | {r['updates_per_s']:.0f} | {r['samples_per_s']:.0f} |"
        )
        print(lines[-1], flush=True)
    os.makedirs(os.path.dirname(args.out) or ".", exist_ok=True)
    with open(args.out, "w") as f:
        f.write("\n".join(lines) + "\n")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
