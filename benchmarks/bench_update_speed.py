"""CPU time a training sample costs, and where an update's time goes: P-DQN, MP-DQN and PADDPG on Platform, and
PADDPG's soccer update (Half Field Offense, the ``paper_hfo`` preset that ``pamdp reproduce soccer`` runs).

For each case a model is warmed up (replay filled, Adam's state made), then measured ``--repeats`` times, each
repeat ``--updates`` calls of ``_update()`` (ms an update) and one training epoch of ``--samples`` samples
(``learn()``'s own loop: collecting and learning at the preset's update-to-data ratio, ms a sample). Times are the
worker process's CPU time (``time.process_time``) with one torch thread, so other jobs on a shared machine slow the
figures less than they would a wall clock.

With ``--baseline REF`` every case also runs on the package as it was at git commit ``REF`` (exported to a
temporary directory), one worker process per version, the repeats alternating between them so that both see the
same load. ``--split`` adds each update's time split on the current code (:func:`split`): matrix products, Adam,
gradient clipping, target (Polyak) updates, and the rest.

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
# the matrix products an update makes, with how many tensor arguments each takes (addmm: bias, a, b)
PRODUCTS = {"aten::addmm": 3, "aten::mm": 2, "aten::bmm": 2, "aten::baddbmm": 3}


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
    from pamdp.nn.subnormals import subnormals_flushed

    with subnormals_flushed(model.config.flush_denormal):
        for _ in range(n):
            model._update()


def cpu_ms(fn, n: int) -> float:
    """CPU ms a call of ``fn``, over ``n`` calls after a few to warm up."""
    for _ in range(3):
        fn()
    t = time.process_time()
    for _ in range(n):
        fn()
    return (time.process_time() - t) / n * 1e3


def split(model, n_updates: int) -> dict[str, float]:
    """CPU ms of an update and of its parts, each part timed alone on this core: the update's matrix products
    (their shapes recorded by ``torch.profiler`` in one update, then replayed on random tensors of those shapes),
    the Adam steps and the gradient clipping on gradients of the networks' shapes, and the Polyak target updates;
    "other" is the rest (element-wise kernels, copies and indexing, Python and dispatch). Parts timed alone run
    with warm caches, so they are lower bounds of their share inside an update."""
    import torch
    from torch.profiler import profile

    from pamdp.nn.optim import clip_grads, optimizer_step

    total = cpu_ms(lambda: updates(model, 1), n_updates)
    with profile(record_shapes=True) as prof:
        updates(model, 1)
    calls = [(e.name, e.input_shapes[: PRODUCTS[e.name]]) for e in prof.events() if e.name in PRODUCTS]
    args = [(getattr(torch.ops.aten, name[6:]), [torch.randn(shape) for shape in shapes]) for name, shapes in calls]
    products = cpu_ms(lambda: [op(*tensors) for op, tensors in args], n_updates)
    optimizers = list(model._optimizers().values())
    grads = [[torch.randn_like(p) * 1e-3 for p in opt.param_groups[0]["params"]] for opt in optimizers]
    clip = getattr(model.config, "grad_clip", 0.0)
    clipping = cpu_ms(lambda: [clip_grads(g, clip) for g in grads], n_updates) if clip > 0 else 0.0
    adam = cpu_ms(lambda: [optimizer_step(opt, g) for opt, g in zip(optimizers, grads)], n_updates)
    modules = model._modules()
    sources = {name.removesuffix("_net"): module for name, module in modules.items()}  # PDQN's q_net: q_target
    pairs = [(module, sources[name.removesuffix("_target")]) for name, module in modules.items() if "_target" in name]
    targets = [p for target, _ in pairs for p in target.parameters()]
    sources = [p for _, source in pairs for p in source.parameters()]
    with torch.no_grad():
        polyak = cpu_ms(lambda: torch._foreach_lerp_(targets, sources, 1e-3), n_updates)
    parts = {"products": products, "Adam": adam, "clipping": clipping, "target updates": polyak}
    return {"update": total, **parts, "other": total - sum(parts.values())}


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
    path = os.pathsep.join(p for p in (src, os.environ.get("PYTHONPATH")) if p)  # src first: the version measured
    cmd = [sys.executable, __file__, "--worker", label, "--updates", str(args.updates), "--samples", str(args.samples)]
    cmd += ["--split"] * (args.split and src is None)
    env = {**os.environ, "PYTHONPATH": path}
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
    parser.add_argument("--cases", default=",".join(CASES), help=f"comma-separated, some of {list(CASES)}")
    parser.add_argument("--baseline", metavar="REF", help="also measure the package at this git commit")
    parser.add_argument("--split", action="store_true", help="add each update's time split (current code)")
    parser.add_argument("--repeats", type=int, default=5, help="measurements a case and version (median)")
    parser.add_argument("--updates", type=int, default=300, help="_update() calls timed in a repeat")
    parser.add_argument("--samples", type=int, default=1_000, help="samples of the training epoch timed in a repeat")
    parser.add_argument("--out", default="benchmarks/update_speed.md", help="the markdown record")
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
        parts = list(next(iter(splits.values())))[1:]
        lines += [
            "",
            "Each update's time split, now: CPU ms of the update, then of each part timed alone (see "
            "`split` in the script), with its share of the update:",
            "",
            "| case | update | " + " | ".join(parts) + " |",
            "|---|---|" + "---|" * len(parts),
        ]
        for label, ms in splits.items():
            cells = [f"{ms[p]:.2f} ({100 * ms[p] / ms['update']:.0f} %)" for p in parts]
            lines.append(f"| {label} | {ms['update']:.2f} | " + " | ".join(cells) + " |")
    from _record import write_record  # the workers may import an older pamdp: not at the top

    write_record(lines, args.out)  # with the record's hand-written notes kept
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
