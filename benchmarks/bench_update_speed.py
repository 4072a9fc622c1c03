"""CPU time a training sample costs, and where an update's time goes: P-DQN, MP-DQN and PADDPG on Platform, and
PADDPG's soccer update (Half Field Offense, the ``paper_hfo`` preset that ``pamdp reproduce soccer`` runs).

For each case a model is warmed up (replay filled, Adam's state made), then measured ``--repeats`` times, each
repeat ``--updates`` calls of ``_update()`` (ms an update) and one training epoch of ``--samples`` samples
(``learn()``'s own loop: collecting and learning at the preset's update-to-data ratio, ms a sample). Times are the
worker process's CPU time (``time.process_time``) with one torch thread, so other jobs on a shared machine slow the
figures less than they would a wall clock.

With ``--baseline REF`` every case also runs on the package as it was at git commit ``REF`` (exported to a
temporary directory), one worker process per version, the repeats alternating between them so that both see the
same load. ``--split`` adds each update's time split, measured on the current code with ``torch.profiler``:
matrix products, Adam, gradient clipping, target (Polyak) updates, copies and indexing, other element-wise
kernels, and the rest (Python, dispatch and the profiler's own overhead: the update's time less its kernels').

    python benchmarks/bench_update_speed.py --baseline 30eadb4 --split --out benchmarks/update_speed.md
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
import tempfile
import time
from pathlib import Path

from bench_offpolicy_speed import cpu_name, export_source

# label: (algorithm, env id, preset, settings over the preset)
CASES = {
    "P-DQN": ("pdqn", "pamdp/Platform-v0", "paper", {"multi_pass": False}),
    "MP-DQN": ("pdqn", "pamdp/Platform-v0", "paper", {"multi_pass": True}),
    "PADDPG": ("paddpg", "pamdp/Platform-v0", "paper", {}),
    "PADDPG soccer": ("paddpg", "pamdp/HalfFieldOffense-v0", "paper_hfo", {}),
}
REPO = Path(__file__).resolve().parents[1]
# torch.profiler op names -> the split's parts (anything else is "element-wise")
PARTS = {
    "products": ("aten::addmm", "aten::mm", "aten::bmm", "aten::baddbmm", "aten::matmul", "aten::linear"),
    "Adam": ("aten::_fused_adam_", "aten::_foreach_add_"),
    "clipping": ("aten::_foreach_norm", "aten::linalg_vector_norm", "aten::_foreach_mul_", "aten::stack"),
    "target updates": ("aten::lerp_", "aten::_foreach_lerp_"),
    "copies": (
        "aten::copy_", "aten::_to_copy", "aten::cat", "aten::index", "aten::index_select", "aten::gather",
        "aten::scatter_", "aten::clone", "aten::empty", "aten::empty_strided", "aten::empty_like", "aten::zeros",
        "aten::zeros_like", "aten::ones_like", "aten::fill_", "aten::zero_", "aten::contiguous",
    ),
}  # fmt: skip


def build(label: str):
    """The case's model, warmed up."""
    import torch

    from pamdp.algos import algorithm_class

    algo, env_id, preset, settings = CASES[label]
    cls = algorithm_class(algo)
    config = cls.config_class.preset(preset, env_id)
    config = dataclasses.replace(
        config, **settings, torch_threads=1, learning_starts=2_000, epoch_steps=2_000, buffer_size=200_000
    )
    torch.set_num_threads(1)
    model = cls(env_id, config)
    model.learn(4_000, progress_bar=False)  # 2 000 samples of updates: Adam's state exists, targets have moved
    return model


def updates(model, n: int) -> None:
    """``n`` updates as the training loop makes them (subnormals flushed with the ``flush_denormal`` setting)."""
    from pamdp.algos.subnormals import subnormals_flushed

    with subnormals_flushed(model.config.flush_denormal):
        for _ in range(n):
            model._update()


def split(model, n_updates: int) -> dict[str, float]:
    """Fractions of an update's time by part, under ``torch.profiler`` (which times kernels by the wall clock, so
    the fractions are of the wall time)."""
    from torch.profiler import profile

    t = time.perf_counter()
    with profile() as prof:
        updates(model, n_updates)
    total = (time.perf_counter() - t) * 1e6  # us, as the profiler's
    parts = dict.fromkeys([*PARTS, "element-wise"], 0.0)
    for event in prof.key_averages():
        if not event.key.startswith("aten::"):
            continue
        part = next((p for p, names in PARTS.items() if event.key in names), "element-wise")
        parts[part] += event.self_cpu_time_total
    parts["Python, dispatch, profiler"] = total - sum(parts.values())
    return {p: v / total for p, v in parts.items()}


def worker(label: str, n_updates: int, n_samples: int, with_split: bool) -> int:
    """Build and warm up one model, then measure one repeat per ``go`` line on stdin (JSON on stdout)."""
    model = build(label)
    print(json.dumps({"ready": True}), flush=True)
    for line in sys.stdin:
        if line.strip() == "split":
            print(json.dumps(split(model, n_updates) if with_split else {}), flush=True)
            continue
        t = time.process_time()
        updates(model, n_updates)
        update_ms = (time.process_time() - t) / n_updates * 1e3
        start = model.num_timesteps
        t = time.process_time()
        model.learn(n_samples, progress_bar=False)
        sample_ms = (time.process_time() - t) / (model.num_timesteps - start) * 1e3
        print(json.dumps({"update_ms": update_ms, "sample_ms": sample_ms}), flush=True)
    return 0


def start_worker(label: str, args, src: str | None) -> subprocess.Popen:
    env = dict(os.environ)
    if src is not None:
        env["PYTHONPATH"] = src + os.pathsep + env.get("PYTHONPATH", "")
    cmd = [sys.executable, __file__, "--worker", label, "--updates", str(args.updates), "--samples", str(args.samples)]
    cmd += ["--split"] * (args.split and src is None)
    proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=env)
    if json.loads(proc.stdout.readline()) != {"ready": True}:
        raise RuntimeError(f"worker for {label} did not start")
    return proc


def ask(proc: subprocess.Popen, line: str) -> dict:
    proc.stdin.write(line + "\n")
    proc.stdin.flush()
    return json.loads(proc.stdout.readline())


def measure(label: str, args, sources: list[str | None]) -> tuple[list[dict], dict]:
    """Medians per source (current package: ``None``), the repeats alternating, and the current code's split."""
    procs = [start_worker(label, args, src) for src in sources]
    runs: list[list[dict]] = [[] for _ in sources]
    try:
        for r in range(args.repeats):
            for i in range(len(procs)) if r % 2 == 0 else reversed(range(len(procs))):
                runs[i].append(ask(procs[i], "go"))
        parts = ask(procs[0], "split")
    finally:
        for proc in procs:
            proc.stdin.close()
            proc.wait()
    return [{k: statistics.median(run[k] for run in rs) for k in rs[0]} for rs in runs], parts


def git_short(ref: str) -> str:
    cmd = ["git", "-C", str(REPO), "rev-parse", "--short", ref]
    return subprocess.run(cmd, check=True, capture_output=True, text=True).stdout.strip()


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--updates", type=int, default=300, help="updates per repeat")
    parser.add_argument("--samples", type=int, default=1_000, help="env samples per repeat (one epoch)")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--baseline", metavar="REF", help="git commit to compare with (same settings)")
    parser.add_argument("--split", action="store_true", help="also profile each update's time split")
    parser.add_argument("--cases", default=",".join(CASES), help=f"comma-separated, some of {list(CASES)}")
    parser.add_argument("--out", default="benchmarks/update_speed.md")
    parser.add_argument("--worker", metavar="LABEL", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        return worker(args.worker, args.updates, args.samples, args.split)
    labels = [c for c in args.cases.split(",") if c]
    if set(labels) - set(CASES):
        parser.error(f"--cases {sorted(set(labels) - set(CASES))}: expected some of {list(CASES)}")

    import torch

    ref = git_short(args.baseline) if args.baseline else None
    lines = [
        "# Training speed per sample and each update's time split (P-DQN, MP-DQN, PADDPG)",
        "",
        f"- command: `python {' '.join(sys.argv)}`",
        f"- date: {dt.datetime.now().isoformat(timespec='seconds')}; code: HEAD {git_short('HEAD')} "
        + "(with any uncommitted changes)"
        + (f" against {ref}" if ref else ""),
        f"- machine: {cpu_name()}, {os.cpu_count()} CPUs (shared with other jobs), load average at start "
        f"{os.getloadavg()[0]:.1f}; Python {platform.python_version()}, torch {torch.__version__}",
        f"- medians of {args.repeats} repeats; {args.updates} updates and one epoch of {args.samples} samples per "
        "repeat; CPU ms, torch threads 1; ms/sample is whole training epochs (collect + learn at the preset's "
        "update-to-data ratio)"
        + ("; the two versions alternate repeat by repeat, each in its own process" if ref else ""),
        "",
    ]
    if ref:
        lines += [
            f"| case | env, preset | hidden layers | batch | ms/update at {ref} | ms/update now | speed-up "
            f"| ms/sample at {ref} | ms/sample now | speed-up |",
            "|---|---|---|---|---|---|---|---|---|---|",
        ]
    else:
        lines += ["| case | env, preset | hidden layers | batch | ms/update | ms/sample |", "|---|---|---|---|---|---|"]
    splits = {}
    from pamdp.algos import algorithm_class

    with tempfile.TemporaryDirectory() as tmp:
        sources = [None] + ([export_source(args.baseline, tmp)] if ref else [])
        for label in labels:
            algo, env_id, preset, settings = CASES[label]
            cfg = dataclasses.replace(algorithm_class(algo).config_class.preset(preset, env_id), **settings)
            results, splits[label] = measure(label, args, sources)
            now = results[0]
            cells = [label, f"{env_id.split('/')[1]}, {preset}", "-".join(map(str, cfg.hidden_sizes)), cfg.batch_size]
            if ref:
                old = results[1]
                cells += [
                    f"{old['update_ms']:.2f}",
                    f"{now['update_ms']:.2f}",
                    f"{old['update_ms'] / now['update_ms']:.2f}x",
                ]
                cells += [
                    f"{old['sample_ms']:.2f}",
                    f"{now['sample_ms']:.2f}",
                    f"{old['sample_ms'] / now['sample_ms']:.2f}x",
                ]
            else:
                cells += [f"{now['update_ms']:.2f}", f"{now['sample_ms']:.2f}"]
            lines.append("| " + " | ".join(map(str, cells)) + " |")
            print(lines[-1], flush=True)
    if args.split:
        parts = list(next(iter(splits.values())))
        lines += [
            "",
            f"Each update's time split, now (fractions of its CPU time under torch.profiler, {args.updates} updates):",
            "",
            "| case | " + " | ".join(parts) + " |",
            "|---|" + "---|" * len(parts),
        ]
        for label, fractions in splits.items():
            lines.append(f"| {label} | " + " | ".join(f"{100 * fractions[p]:.0f} %" for p in parts) + " |")
    os.makedirs(os.path.dirname(args.out) or ".", exist_ok=True)
    from _record import write_record  # here, not at the top: the workers may import an older pamdp

    write_record(lines, args.out)  # keeps the record's hand-written notes
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
