"""Training speed on the CPU against CUDA (issue 31): samples per second of every algorithm on Platform and HFO with
the paper's networks, and the time of one PATRPO policy update at 50 000 samples.

The same code runs on each device (the algorithms' ``device`` setting); only the networks, optimisers and updates
move, the envs step on the CPU. For each algorithm, env and device a model with the paper's preset (HFO's own where
the algorithm has one) is warmed up, then trained ``--repeats`` times for ``--samples`` samples; the record gives
the median samples per wall-clock second (CUDA's queue is drained before each clock reading; CPU time would miss
the GPU's share) and the CPU seconds per 1000 samples. Off-policy models learn from ``--warmup`` samples on
(``learning_starts``), in epochs of ``--samples``; on-policy ones take one epoch of ``--samples`` (their
``batch_size``). PATRPO's update is timed on one batch of 50 000 Platform samples (``--update-samples``), the same
batch on each device, the policy restored between repeats.

    python benchmarks/bench_gpu_speed.py --out benchmarks/gpu_speed.md

takes some minutes where there is a GPU, most of them in the off-policy algorithms' CPU column (about 100 samples a
second each with the paper's networks); ``--envs Platform`` and ``--envs HFO`` split it in two. ``--devices cpu
--samples 300 --warmup 100 --repeats 1 --update-samples 2000`` is a quick check of the script without a GPU.
"""

from __future__ import annotations

import argparse
import datetime as dt
import os
import platform
import statistics
import sys
import time
from pathlib import Path

import torch

from pamdp.algos import ALGORITHMS, algorithm_class
from pamdp.algos.onpolicy import advantage_batch, update_tensors

ENVS = {"Platform": "pamdp/Platform-v0", "HFO": "pamdp/HalfFieldOffense-v0"}
HFO_PRESETS = {"paddpg": "paper_hfo"}


def preset_of(name: str, env: str) -> str:
    presets = algorithm_class(name).config_class.presets()
    if env == "HFO" and name in HFO_PRESETS:
        return HFO_PRESETS[name]
    return "paper" if "paper" in presets else next(iter(presets))


def clock(device: str) -> tuple[float, float]:
    if device.startswith("cuda"):
        torch.cuda.synchronize()
    return time.perf_counter(), time.process_time()


def build(name: str, env: str, device: str, samples: int, warmup: int):
    cls = algorithm_class(name)
    config = cls.config_class.preset(preset_of(name, env))
    names = set(config.to_dict())
    settings = {"device": device}
    if "epoch_steps" in names:  # off-policy
        settings.update(epoch_steps=samples, learning_starts=warmup)
        if "warmup_steps" in names:  # HyAR: learning_starts is its warm-up of random actions
            settings.update(warmup_steps=warmup, warmup_updates=min(config.warmup_updates, 100))
            settings.pop("learning_starts")
    else:
        settings.update(batch_size=samples)
        if "minibatch_size" in names:
            settings["minibatch_size"] = min(config.minibatch_size, samples)
    return cls(ENVS[env], cls.config_class.from_dict(settings, base=config))


def samples_per_second(name, env, device, samples, warmup, repeats) -> tuple[float, float]:
    """Median samples per wall second and CPU seconds per 1000 samples, after one warm-up epoch."""
    algo = build(name, env, device, samples, warmup)
    algo.learn(max(samples, warmup + 1), progress_bar=False)
    rates, cpu = [], []
    for _ in range(repeats):
        start, n = clock(device), algo.num_timesteps
        algo.learn(samples, progress_bar=False)
        end = clock(device)
        rates.append((algo.num_timesteps - n) / (end[0] - start[0]))
        cpu.append(1000 * (end[1] - start[1]) / (algo.num_timesteps - n))
    return statistics.median(rates), statistics.median(cpu)


def patrpo_update_seconds(device: str, n_samples: int, repeats: int, data: dict) -> float:
    """Median wall seconds of one PATRPO (paper preset) policy update on ``data``."""
    algo = build("patrpo", "Platform", device, n_samples, 0)
    tensors = update_tensors(data, algo.device)
    saved = {k: v.clone() for k, v in algo.policy.state_dict().items()}
    times = []
    for _ in range(repeats + 1):  # the first one warms up (CUDA's kernels, the allocator)
        algo.policy.load_state_dict(saved)
        start = clock(device)
        algo._update_policy(*tensors)
        times.append(clock(device)[0] - start[0])
    return statistics.median(times[1:])


def update_batch(n_samples: int) -> dict:
    """One batch of ``n_samples`` Platform samples of PATRPO's initial policy, with their advantages."""
    algo = build("patrpo", "Platform", "cpu", n_samples, 0)
    cfg = algo.config
    batch = algo.rollout.collect(algo.vec_env, algo.policy, algo.hybrid, n_samples, algo.np_rng, algo.torch_gen)
    return advantage_batch(batch, algo._values, cfg.gamma, cfg.gae_lambda, cfg.normalize_advantages)[0]


def machine(devices) -> str:
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next(line.split(":", 1)[1].strip() for line in f if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    gpu = torch.cuda.get_device_name(0) if torch.cuda.is_available() else "none"
    return (
        f"{cpu}, {os.cpu_count()} cores; GPU: {gpu}; torch {torch.__version__}, Python {platform.python_version()}; "
        f"load average at the end {os.getloadavg()[0]:.1f}"
    )


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--devices", default="cpu,cuda", help="comma-separated devices (default: %(default)s)")
    parser.add_argument("--algos", default=",".join(ALGORITHMS), help="comma-separated algorithms")
    parser.add_argument("--envs", default=",".join(ENVS), help="comma-separated envs: Platform, HFO")
    parser.add_argument("--samples", type=int, default=1000, help="samples per measurement (default: %(default)s)")
    parser.add_argument("--warmup", type=int, default=500, help="off-policy learning_starts (default: %(default)s)")
    parser.add_argument("--repeats", type=int, default=2, help="measurements per case (default: %(default)s)")
    parser.add_argument("--update-samples", type=int, default=50_000, help="PATRPO update batch (%(default)s)")
    parser.add_argument("--out", type=Path, default=None, help="markdown record to write")
    args = parser.parse_args(argv)
    devices = args.devices.split(",")
    missing = [d for d in devices if d.startswith("cuda") and not torch.cuda.is_available()]
    if missing:
        print(f"skipping {', '.join(missing)}: CUDA is not available on this machine", file=sys.stderr)
        devices = [d for d in devices if d not in missing]

    rows = []
    for env in args.envs.split(","):
        for name in args.algos.split(","):
            cells = {}
            for device in devices:
                cells[device] = samples_per_second(name, env, device, args.samples, args.warmup, args.repeats)
                print(f"{name} {env} {device}: {cells[device][0]:.0f} samples/s", file=sys.stderr, flush=True)
            rows.append((name, preset_of(name, env), env, cells))
    data = update_batch(args.update_samples)
    update = {d: patrpo_update_seconds(d, args.update_samples, args.repeats, data) for d in devices}

    header = "| algorithm | preset | env | " + " | ".join(f"{d} samples/s (CPU s per 1000)" for d in devices)
    lines = [header + (" | cuda / cpu |" if len(devices) > 1 else " |")]
    lines.append("|" + "---|" * (3 + len(devices) + (len(devices) > 1)))
    for name, preset, env, cells in rows:
        figures = " | ".join(f"{cells[d][0]:.0f} ({cells[d][1]:.2f})" for d in devices)
        ratio = f" | x{cells[devices[1]][0] / cells[devices[0]][0]:.2f}" if len(devices) > 1 else ""
        lines.append(f"| {name} | {preset} | {env} | {figures}{ratio} |")
    update_line = ", ".join(f"{d} {update[d]:.3f} s" for d in devices)
    text = "\n".join(
        [
            "# Training speed, CPU against CUDA",
            "",
            f"Command: `python benchmarks/bench_gpu_speed.py {' '.join(argv if argv is not None else sys.argv[1:])}`",
            f"Date: {dt.datetime.now(dt.timezone.utc):%Y-%m-%d %H:%M UTC}",
            f"Machine: {machine(devices)}",
            "",
            f"Samples per wall-clock second, medians of {args.repeats} measurements of {args.samples} samples each "
            f"(off-policy models past a warm-up of {args.warmup} samples).",
            "",
            *lines,
            "",
            f"PATRPO's policy update (paper preset) on {args.update_samples} Platform samples: {update_line}.",
            "",
        ]
    )
    print(text)
    if args.out is not None:
        args.out.write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
