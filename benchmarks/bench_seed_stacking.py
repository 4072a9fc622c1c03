"""How much faster does ``pamdp reproduce --stack`` train off-policy seeds? The library's seed stacks, end to end.

``benchmarks/seed_batching.md`` measured a model of the stacked update before it was built; this measures the
library's :class:`~pamdp.algos.stacking.SeedStack` as ``pamdp reproduce --stack`` runs it: whole training runs
(env steps, acting, replay, updates, logging, threads) of PADDPG and PASVG(0), paper presets on Platform (the
platform experiment's off-policy arms), one torch thread a process,
each process pinned to its own core and all of a case started together. The figure is seed-samples trained per
second summed over the processes (median over ``--repeats``), against two processes of one seed each (the
layout of ``pamdp reproduce --workers 2``).

    python benchmarks/bench_seed_stacking.py --out benchmarks/seed_stacking.md

Other training on the machine should be paused (``kill -STOP``) while it runs; the record says the load average.
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import os
import statistics
import sys
import time
from pathlib import Path

HERE = Path(__file__).parent
# (label, seeds per process, one entry per process)
CASES = [
    ("two processes, 1 seed each (`--workers 2`)", [1, 1]),
    ("two processes, 2 seeds stacked each (`--workers 2 --stack 2`)", [2, 2]),
    ("two processes, 3 seeds stacked each (`--workers 2 --stack 3`)", [3, 3]),
]


ALGOS = {"paddpg": "PADDPG", "pasvg0": "PASVG(0)"}


def worker(core: int, seeds: int, samples: int, algo: str) -> None:
    """Pinned to the ``core``-th allowed CPU: build ``seeds`` runs, say so, then train them once told to."""
    import dataclasses

    import torch

    from pamdp.algos.stacking import SeedStack
    from pamdp.experiments.runner import algorithm_class

    os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[core]})
    torch.set_num_threads(1)
    cls = algorithm_class(algo)
    # The paper preset with updates from the first batch on, so every measured sample carries its update.
    base = cls.config_class.preset("paper")
    config = dataclasses.replace(base, learning_starts=base.batch_size, epoch_steps=1000)
    models = [cls("pamdp/Platform-v0", dataclasses.replace(config, seed=100 * core + s)) for s in range(seeds)]
    print("ready", flush=True)
    sys.stdin.readline()
    start, cpu = time.perf_counter(), time.process_time()
    if seeds == 1:
        models[0].learn(samples, progress_bar=False)
    else:
        SeedStack(models).run([lambda leave, m=m: m.learn(samples, progress_bar=False) for m in models])
    wall, cpu = time.perf_counter() - start, time.process_time() - cpu
    trained = sum(m.num_timesteps for m in models)
    print(json.dumps({"seeds": seeds, "samples": trained, "wall": wall, "cpu": cpu}), flush=True)


def run_case(counts: list[int], samples: int, algo: str) -> list[dict]:
    from _record import run_together

    return run_together(
        [[sys.executable, __file__, "--worker", str(core), str(n), str(samples), algo] for core, n in enumerate(counts)]
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=3000, help="samples per seed (default: %(default)s)")
    parser.add_argument("--repeats", type=int, default=3, help="repeats per case (default: %(default)s)")
    parser.add_argument("--out", default=None, help="markdown record to write (default: print only)")
    parser.add_argument(
        "--algos", default="paddpg,pasvg0", help="comma-separated: paddpg, pasvg0 (default: %(default)s)"
    )
    parser.add_argument("--worker", nargs=4, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        core, seeds, samples, algo = args.worker
        worker(int(core), int(seeds), int(samples), algo)
        return
    algos = args.algos.split(",")
    if unknown := [a for a in algos if a not in ALGOS]:
        raise SystemExit(f"--algos {args.algos}: unknown {', '.join(unknown)}; expected some of {', '.join(ALGOS)}")
    if len(os.sched_getaffinity(0)) < 2:
        raise SystemExit("needs two cores (each case pins one process to each)")
    load = os.getloadavg()[0]
    keys = [(algo, label) for algo in algos for label, _ in CASES]
    rates: dict[tuple[str, str], list[float]] = {k: [] for k in keys}
    per_process: dict[tuple[str, str], list[list[float]]] = {k: [] for k in keys}
    for rep in range(args.repeats):  # cases interleaved, so a drift of the machine's speed hits them alike
        for algo in algos:
            for label, counts in CASES:
                results = run_case(counts, args.samples, algo)
                rates[algo, label].append(sum(r["samples"] / r["wall"] for r in results))
                per_process[algo, label].append([r["samples"] / r["cpu"] for r in results])
                print(f"repeat {rep}: {algo}: {label}: {rates[algo, label][-1]:.0f} seed-samples/s", file=sys.stderr)
    sys.path.insert(0, str(HERE))
    from _record import machine, write_record

    command = (
        f"python benchmarks/bench_seed_stacking.py --samples {args.samples} --repeats {args.repeats} "
        f"--algos {args.algos}"
    )
    lines = [
        "# Seed stacking, end to end: `pamdp reproduce --stack` against one seed per process (Platform)",
        "",
        f"- command: `{command}" + (f" --out {args.out}`" if args.out else "`"),
        f"- date: {dt.datetime.now().isoformat(timespec='seconds')}",
        f"- load average at the start: {load:.1f}; machine: {machine()}",
        "- the paper presets ({400, 300}; one update per sample; batch 32 for PADDPG, 64 for PASVG(0)) with "
        f"`learning_starts` = one batch, {args.samples:,} samples per seed from a fresh start; one torch thread "
        f"per process, each pinned to its own core; medians of {args.repeats} repeats, the cases interleaved",
        "",
        "| algorithm | layout | seed-samples/s in all (median) | each repeat | per process, samples per "
        "CPU-second | vs. one seed per process |",
        "|---|---|---|---|---|---|",
    ]
    for algo in algos:
        base = statistics.median(rates[algo, CASES[0][0]])
        for label, _ in CASES:
            med = statistics.median(rates[algo, label])
            each = ", ".join(f"{r:.0f}" for r in rates[algo, label])
            cpu = ", ".join(f"{statistics.median(col):.0f}" for col in zip(*per_process[algo, label]))
            lines.append(f"| {ALGOS[algo]} | {label} | {med:.0f} | {each} | {cpu} | {med / base:.2f}x |")
    write_record(lines, args.out)


if __name__ == "__main__":
    main()
