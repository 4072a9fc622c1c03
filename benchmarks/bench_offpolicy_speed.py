"""Training speed of the off-policy algorithms: gradient updates per second and env samples per second.

For each algorithm and preset, a model is warmed up (replay filled past ``learning_starts``), then
measured ``--repeats`` times:

- updates/s: ``_update()`` calls (one critic and one actor step on a replayed minibatch) per CPU-second;
- samples/s: environment samples per CPU-second during training, i.e. whole epochs of collecting and
  learning at the preset's update-to-data ratio (``learn()``'s own loop).

Times are the worker process's CPU time (``time.process_time``, one torch thread), so other jobs on a shared
machine slow the figures less than they would a wall clock. The row "paper (autograd update)" runs PASVG(0)'s
paper preset on its autograd update instead of the hand-written one (``_dense = None``), which says whether
the hand-written update still pays.

With ``--baseline REF`` the same cases also run on the package as it was at git commit ``REF`` (exported
to a temporary directory), with the settings of the current presets. Each case runs in one worker process
per version, and the repeats alternate between them, so both versions see the same load on a shared
machine. Medians over the repeats are written as a markdown record with the command, date and machine.

    python benchmarks/bench_offpolicy_speed.py --baseline 3eb7877 --out benchmarks/offpolicy_speed.md
"""

from __future__ import annotations

import argparse
import dataclasses
import datetime as dt
import json
import os
import platform
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

# (algorithm, preset, settings on top of the preset, label)
CASES = [
    ("PASVG0", "paper", {}, "paper"),
    ("PASVG0", "paper", {"autograd": True}, "paper (autograd update)"),
    ("PASVG0", "tuned", {}, "tuned"),
    ("PADDPG", "paper", {}, "paper"),
    ("PADDPG", "hausknecht_stone", {}, "hausknecht_stone"),
    ("PDQN", "tuned", {"multi_pass": False}, "tuned (P-DQN)"),
    ("PDQN", "tuned", {"multi_pass": True}, "tuned (MP-DQN)"),
]
REPO = Path(__file__).resolve().parents[1]


def cpu_name() -> str:
    try:
        with open("/proc/cpuinfo") as f:
            return next(line.split(":", 1)[1].strip() for line in f if line.startswith("model name"))
    except (OSError, StopIteration):
        return platform.processor() or platform.machine()


def config_classes():
    from pamdp.algos.paddpg import PADDPG, PADDPGConfig
    from pamdp.algos.pasvg import PASVG0, PASVG0Config
    from pamdp.algos.pdqn import PDQN, PDQNConfig

    return {"PASVG0": (PASVG0, PASVG0Config), "PADDPG": (PADDPG, PADDPGConfig), "PDQN": (PDQN, PDQNConfig)}


def worker(algo: str, config_json: str, n_updates: int, n_samples: int) -> int:
    """Build and warm up one model, then measure one repeat per ``go`` line on stdin (JSON on stdout)."""
    import torch

    cls, config_class = config_classes()[algo]
    values = json.loads(config_json)
    autograd = values.pop("autograd", False)
    known = {f.name for f in dataclasses.fields(config_class)}
    if set(values) - known:  # a setting newer than the baseline's code: measure without it
        print(f"{algo}: ignoring settings unknown to this version: {sorted(set(values) - known)}", file=sys.stderr)
    config = config_class.from_dict({k: v for k, v in values.items() if k in known})
    config = dataclasses.replace(config, learning_starts=n_samples, epoch_steps=n_samples, buffer_size=200_000)
    model = cls("pamdp/Platform-v0", config)
    torch.set_num_threads(config.torch_threads)
    if autograd:
        model._dense = None
    model.learn(n_samples, progress_bar=False)  # fills the buffer past learning_starts and warms up
    print(json.dumps({"ready": True}), flush=True)
    for _ in sys.stdin:
        t = time.process_time()
        for _ in range(n_updates):
            model._update()
        updates = n_updates / (time.process_time() - t)
        start = model.num_timesteps
        t = time.process_time()
        model.learn(n_samples, progress_bar=False)
        samples = (model.num_timesteps - start) / (time.process_time() - t)
        print(json.dumps({"updates_per_s": updates, "samples_per_s": samples}), flush=True)
    return 0


def export_source(ref: str, dest: str) -> str:
    """The package's ``src`` tree at git commit ``ref``, unpacked under ``dest``; returns the ``src`` path."""
    archive = subprocess.run(["git", "-C", str(REPO), "archive", ref, "src"], check=True, capture_output=True).stdout
    path = Path(dest) / "archive.tar"
    path.write_bytes(archive)
    with tarfile.open(path) as tar:
        tar.extractall(dest, filter="data")
    return str(Path(dest) / "src")


def start_worker(algo: str, config: dict, args, src: str | None) -> subprocess.Popen:
    env = dict(os.environ)
    if src is not None:
        env["PYTHONPATH"] = src + os.pathsep + env.get("PYTHONPATH", "")
    cmd = [sys.executable, __file__, "--worker", algo, json.dumps(config)]
    cmd += ["--updates", str(args.updates), "--samples", str(args.samples)]
    proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=env)
    if json.loads(proc.stdout.readline()) != {"ready": True}:
        raise RuntimeError(f"worker for {algo} did not start")
    return proc


def measure(algo: str, config: dict, args, sources: list[str | None]) -> list[dict]:
    """Medians per source (current package: ``None``), the repeats alternating between sources."""
    procs = [start_worker(algo, config, args, src) for src in sources]
    runs: list[list[dict]] = [[] for _ in sources]
    try:
        for r in range(args.repeats):
            order = range(len(procs)) if r % 2 == 0 else reversed(range(len(procs)))
            for i in order:
                procs[i].stdin.write("go\n")
                procs[i].stdin.flush()
                runs[i].append(json.loads(procs[i].stdout.readline()))
    finally:
        for proc in procs:
            proc.stdin.close()
            proc.wait()
    return [{k: statistics.median(run[k] for run in rs) for k in rs[0]} for rs in runs]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--updates", type=int, default=300, help="updates per repeat")
    parser.add_argument("--samples", type=int, default=1_000, help="env samples per repeat (one epoch)")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--baseline", metavar="REF", help="git commit to compare with (same settings)")
    parser.add_argument("--out", default="benchmarks/offpolicy_speed.md")
    parser.add_argument(
        "--cases", default="", help="ALGO:LABEL,... to run only these rows (e.g. PADDPG:paper); default: all"
    )
    parser.add_argument("--worker", nargs=2, metavar=("ALGO", "CONFIG"), help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        return worker(*args.worker, args.updates, args.samples)
    wanted = {tuple(case.split(":", 1)) for case in args.cases.split(",") if case}
    unknown = wanted - {(name, label) for name, _, _, label in CASES}
    if unknown:
        parser.error(
            f"--cases {sorted(':'.join(c) for c in unknown)}: expected some of "
            f"{[f'{name}:{label}' for name, _, _, label in CASES]}"
        )

    import torch

    classes = config_classes()
    head = "# Off-policy training speed (PASVG(0), PADDPG, P-DQN, MP-DQN) on Platform"
    cols = "| algorithm | preset | hidden layers | batch | num_envs | updates/sample | updates/s | samples/s |"
    rule = "|---|---|---|---|---|---|---|---|"
    if args.baseline:
        ref = subprocess.run(
            ["git", "-C", str(REPO), "rev-parse", "--short", args.baseline], check=True, capture_output=True, text=True
        ).stdout.strip()
        head_ref = subprocess.run(
            ["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"], check=True, capture_output=True, text=True
        ).stdout.strip()
        cols = (
            "| algorithm | preset | hidden layers | batch | num_envs | updates/sample "
            f"| updates/s at {ref} | updates/s now | speed-up | samples/s at {ref} | samples/s now |"
        )
        rule = "|---|---|---|---|---|---|---|---|---|---|---|"
    lines = [
        head,
        "",
        f"- command: `python {' '.join(sys.argv)}`",
        f"- date: {dt.datetime.now().isoformat(timespec='seconds')}"
        + (f"; code: HEAD {head_ref} (with any uncommitted changes) against {ref}" if args.baseline else ""),
        f"- machine: {cpu_name()}, {os.cpu_count()} CPUs (shared with other jobs), "
        f"load average at start {os.getloadavg()[0]:.1f}; Python {platform.python_version()}, "
        f"torch {torch.__version__}",
        f"- medians of {args.repeats} repeats; {args.updates} updates and {args.samples} samples per repeat; "
        "CPU time, torch threads 1; samples/s is whole training epochs (collect + learn at the preset's "
        "update-to-data ratio)"
        + ("; the two versions alternate repeat by repeat, each in its own process" if args.baseline else ""),
        "",
        cols,
        rule,
    ]
    with tempfile.TemporaryDirectory() as tmp:
        sources = [None] + ([export_source(args.baseline, tmp)] if args.baseline else [])
        for name, preset, overrides, label in CASES:
            if wanted and (name, label) not in wanted:
                continue
            settings = {k: v for k, v in overrides.items() if k != "autograd"}
            cfg = dataclasses.replace(classes[name][1].preset(preset), **settings)
            results = measure(name, {**cfg.to_dict(), **overrides}, args, sources)
            cells = [name, label, "-".join(map(str, cfg.hidden_sizes)), cfg.batch_size, cfg.num_envs]
            cells.append(f"{cfg.updates_per_step:g}")
            now = results[0]
            if args.baseline:
                base = results[1]
                cells += [f"{base['updates_per_s']:.0f}", f"{now['updates_per_s']:.0f}"]
                cells += [f"{now['updates_per_s'] / base['updates_per_s']:.2f}x"]
                cells += [f"{base['samples_per_s']:.0f}", f"{now['samples_per_s']:.0f}"]
            else:
                cells += [f"{now['updates_per_s']:.0f}", f"{now['samples_per_s']:.0f}"]
            lines.append("| " + " | ".join(map(str, cells)) + " |")
            print(lines[-1], flush=True)
    os.makedirs(os.path.dirname(args.out) or ".", exist_ok=True)
    from _record import write_record  # here, not at the top: the workers may import an older pamdp

    write_record(lines, args.out)  # keeps the record's hand-written notes
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
