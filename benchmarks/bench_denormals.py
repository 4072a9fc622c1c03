"""What flushing subnormal floats to zero (the ``flush_denormal`` setting, on by default) buys in training speed.

For each algorithm's paper preset (or ``--presets``) on Platform (or ``--env``) a model is trained for
``--warm`` samples with IEEE subnormals (the behaviour before the setting existed), so that its Adam moments
and weights are those of such a run in progress, and saved. Then the same model, loaded
afresh each time, trains ``--samples`` more with ``flush_denormal`` off and on, alternating, ``--repeats``
times, in this one process pinned to one core. Medians are written as a markdown record with the command,
date and machine. Stop other work on the machine while it runs: the two settings alternate so a steady load
hits both alike, but a changing one does not.

    python benchmarks/bench_denormals.py --out benchmarks/denormals.md
"""

from __future__ import annotations

import argparse
import dataclasses
import datetime as dt
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

import torch
from _record import machine, write_record

# (algorithm, the epoch length for timing; None keeps the preset's)
CASES = [("PASVG0", 1_000), ("PADDPG", 1_000), ("PATRPO", None)]


def subnormal_share(model) -> float:
    """The fraction of the optimisers' state and the networks' weights that is subnormal (nonzero, below the
    smallest normal float32)."""
    tiny = torch.finfo(torch.float32).tiny
    tensors = [p.detach() for m in model._modules().values() for p in m.parameters()]
    for opt in model._optimizers().values():
        tensors += [v for state in opt.state.values() for v in state.values() if torch.is_tensor(v) and v.dim() > 0]
    total = sum(t.numel() for t in tensors)
    sub = sum(int(((t != 0) & (t.abs() < tiny)).sum()) for t in tensors)
    return sub / total


def time_case(name: str, preset: str, env: str, epoch: int | None, warm: int, samples: int, repeats: int, folder: Path):
    import pamdp

    cls = getattr(pamdp, name)
    config = cls.config_class.preset(preset)
    if epoch is not None:
        config = dataclasses.replace(config, epoch_steps=epoch)
    samples = max(samples, getattr(config, "epoch_steps", None) or config.batch_size)  # whole epochs
    path = folder / f"{name}.pt"
    model = cls(env, dataclasses.replace(config, flush_denormal=False)).learn(warm, progress_bar=False)
    model.save(path, replay=True)
    share = subnormal_share(model)
    times = {False: [], True: []}
    for _ in range(repeats):
        for flush in (False, True):
            model = cls.load(path)
            model.config = dataclasses.replace(model.config, flush_denormal=flush)
            start = time.perf_counter()
            model.learn(samples, progress_bar=False)
            times[flush].append((time.perf_counter() - start) / samples * 1e3)
            print(f"{name} flush={flush}: {times[flush][-1]:.3f} ms/sample", flush=True)
    off, on = statistics.median(times[False]), statistics.median(times[True])
    return {
        "algo": name,
        "preset": preset,
        "samples": samples,
        "subnormal": share,
        "off": off,
        "on": on,
        "times": times,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--warm", type=int, default=20_000, help="samples trained before timing (default: 20000)")
    parser.add_argument("--samples", type=int, default=2_000, help="samples per timing (default: 2000)")
    parser.add_argument("--repeats", type=int, default=3, help="timings per setting (default: 3)")
    parser.add_argument("--algos", default="PASVG0,PADDPG,PATRPO", help="comma-separated (default: all three)")
    parser.add_argument("--env", default="pamdp/Platform-v0", help="env id (default: pamdp/Platform-v0)")
    parser.add_argument(
        "--presets", default="", help="ALGO=PRESET,... instead of the paper presets, e.g. PADDPG=paper_hfo"
    )
    parser.add_argument("--out", help="markdown record to write (default: print only)")
    args = parser.parse_args()
    os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})
    torch.set_num_threads(1)
    wanted = args.algos.split(",")
    presets = dict(item.split("=", 1) for item in args.presets.split(",") if item)
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for name, epoch in CASES:
            if name in wanted:
                rows.append(
                    time_case(
                        name,
                        presets.get(name, "paper"),
                        args.env,
                        epoch,
                        args.warm,
                        args.samples,
                        args.repeats,
                        Path(folder),
                    )
                )
    lines = [
        "# Flushing subnormal floats to zero: training speed",
        "",
        f"Command: `python benchmarks/{Path(__file__).name} {' '.join(sys.argv[1:])}`  ",
        f"Date: {dt.datetime.now().strftime('%Y-%m-%d %H:%M')}  ",
        f"Machine: {machine()}",
        "",
        f"Each preset on `{args.env}`, trained {args.warm:,} samples with IEEE subnormals first, then timed on one "
        f"core over the samples below, medians of {args.repeats} alternating repeats. Subnormal share: of the weights "
        "and Adam's state "
        "after the warm-up.",
        "",
        "| algorithm | preset | samples timed | subnormal share | ms/sample, IEEE subnormals | ms/sample, flushed "
        "| speed-up |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['algo']} | {r['preset']} | {r['samples']:,} | {r['subnormal']:.1%} | {r['off']:.3f} | "
            f"{r['on']:.3f} | {r['off'] / r['on']:.2f}x |"
        )
    write_record(lines, args.out)


if __name__ == "__main__":
    main()
