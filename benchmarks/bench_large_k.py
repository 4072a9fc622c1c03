"""CPU cost of a training sample for every algorithm on Hard Move at large K (n actuators, K = 2^n actions).

For each algorithm and n, one worker process builds a model with the env's preset (``pamdp train ALGO --env
pamdp/HardMove-v0 --env-kwargs '{"n": N}'`` without ``--preset``; ``--cases ALGO:N:PRESET`` names another), with
only the schedule shortened so that the updates start at once:
``epoch_steps`` the measured sample count (:data:`SAMPLES`), ``learning_starts`` (HyAR: ``warmup_steps``) one
epoch, HyAR's ``warmup_updates`` 50, ``buffer_size`` 50 000. It trains one warm-up epoch, then ``--repeats``
measured ones; a repeat's figure is the worker's CPU time (``time.process_time``, torch threads 1) over the
samples it collected and learnt from (on-policy: one whole epoch of the preset's ``batch_size``). The record
gives the median.

With ``--baseline REF`` every case also runs on the package as it was at git commit ``REF`` (exported to a
temporary directory; a preset that ``REF`` lacks is left out there); the figures are cached in ``--cache`` by
commit and case (``ALGO:PRESET:N``), so a rerun measures only the current code, and the record shows every cached
case of the algorithms and n asked for. Pin the whole script to one core (``taskset -c 1``) on a shared machine.

    taskset -c 1 python benchmarks/bench_large_k.py --baseline 0c2c6ee --out benchmarks/large_k_cost.md
"""

from __future__ import annotations

import argparse
import dataclasses
import datetime as dt
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
sys.path.insert(0, str(HERE))
ALGOS = ("patrpo", "pappo", "pasvg0", "paddpg", "pdqn", "hyar", "hsac")
ENV = "pamdp/HardMove-v0"
SAMPLES = {4: 1024, 6: 512, 8: 256, 10: 128}
"""Samples of one off-policy repeat, by n (the cost grows with K)."""


def env_preset(algo: str, n: int) -> str:
    """The preset ``pamdp train ALGO --env pamdp/HardMove-v0`` gets at ``n``."""
    from pamdp.algos import algorithm_class

    return algorithm_class(algo).config_class.for_env(ENV, {"n": n})[0]


def worker(algo: str, n: int, preset: str, repeats: int) -> int:
    import torch

    from pamdp.algos import algorithm_class
    from pamdp.presets import preset_names

    cls = algorithm_class(algo)
    config_class = cls.config_class
    if preset not in preset_names(config_class):  # a preset newer than this version of the package
        print(json.dumps({"ms_per_sample": [], "preset": preset}), flush=True)
        return 0
    config = config_class.preset(preset, ENV, {"n": n})
    fields = {f.name for f in dataclasses.fields(config)}
    samples = SAMPLES[n]
    shorter = {"epoch_steps": samples, "buffer_size": 50_000}  # updates from the warm-up epoch's end on
    if "warmup_steps" in fields:
        shorter.update(warmup_steps=samples, warmup_updates=50)
    elif "learning_starts" in fields:
        shorter["learning_starts"] = samples
    config = dataclasses.replace(config, **{k: v for k, v in shorter.items() if k in fields})
    torch.set_num_threads(1)
    model = cls(ENV, config, env_kwargs={"n": n})
    # learn(n) trains at least n more samples (once "learn(1)" was one epoch; it is now one batch of the vector
    # env's steps, which measured sampling alone: no update before the replay held `samples`)
    model.learn(samples, progress_bar=False)  # the warm-up: fills replay past learning_starts, compiles, allocates
    figures = []
    for _ in range(repeats):
        start, t = model.num_timesteps, time.process_time()
        model.learn(samples, progress_bar=False)
        figures.append((time.process_time() - t) / (model.num_timesteps - start))
    print(json.dumps({"ms_per_sample": [1e3 * f for f in figures], "preset": preset}), flush=True)
    return 0


def measure(algo: str, n: int, preset: str, repeats: int, src: str | None) -> dict:
    env = dict(os.environ)
    if src is not None:
        env["PYTHONPATH"] = src + os.pathsep + env.get("PYTHONPATH", "")
    cmd = [sys.executable, __file__, "--worker", algo, str(n), preset, "--repeats", str(repeats)]
    t = time.time()
    out = subprocess.run(cmd, env=env, capture_output=True, text=True)
    if out.returncode != 0:
        raise SystemExit(f"{algo} n={n} failed:\n{out.stderr[-3000:]}")
    result = json.loads(out.stdout.strip().splitlines()[-1])
    result["wall_s"] = time.time() - t
    if src is None:  # the current code: which commit, and whether the package had uncommitted changes
        result["commit"] = git("rev-parse", "--short", "HEAD") + ("+" if git("status", "--porcelain", "src") else "")
    return result


def _by_n(key: str) -> int:
    return int(key.rsplit(":", 1)[1])


def git(*args: str) -> str:
    return subprocess.run(["git", "-C", str(REPO), *args], check=True, capture_output=True, text=True).stdout.strip()


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--algos", default=",".join(ALGOS))
    p.add_argument("--n", default="4,6,8", help="actuator counts, from 4, 6, 8, 10")
    p.add_argument("--skip", default="", help="ALGO:N,... not to run (too slow at this K)")
    p.add_argument(
        "--cases", default="", help="ALGO:N or ALGO:N:PRESET,... to run instead of --algos x --n (default: the env's)"
    )
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--baseline", metavar="REF", help="git commit to compare with")
    p.add_argument("--cache", default=str(HERE / "results" / "large_k_baseline.json"))
    p.add_argument("--out", default="", help="record to write (markdown)")
    p.add_argument("--only-baseline", action="store_true", help="measure (and cache) the baseline only")
    p.add_argument("--only-now", action="store_true", help="measure (and cache) the current code only")
    p.add_argument("--reuse", action="store_true", help="take the current code's figures from the cache too")
    p.add_argument("--record-only", action="store_true", help="measure nothing: write the record from the cache")
    p.add_argument("--worker", nargs=3, metavar=("ALGO", "N", "PRESET"), help=argparse.SUPPRESS)
    a = p.parse_args(argv)
    if a.worker:
        return worker(a.worker[0], int(a.worker[1]), a.worker[2], a.repeats)
    from _record import machine
    from bench_offpolicy_speed import export_source

    algos, ns = a.algos.split(","), [int(n) for n in a.n.split(",")]
    skip = set(a.skip.split(",")) - {""}
    if a.cases:
        cases = [(c.split(":") + [""])[:3] for c in a.cases.split(",")]
        cases = [(algo, int(n), preset or env_preset(algo, int(n))) for algo, n, preset in cases]
    elif a.record_only:
        cases = []
    else:
        cases = [(algo, n, env_preset(algo, n)) for algo in algos for n in ns if f"{algo}:{n}" not in skip]
    ref = git("rev-parse", "--short", a.baseline) if a.baseline else None
    cache = json.loads(Path(a.cache).read_text()) if Path(a.cache).exists() else {}
    before, after = cache.setdefault(ref, {}) if ref else {}, cache.setdefault("now", {})

    def save():
        latest = json.loads(Path(a.cache).read_text()) if Path(a.cache).exists() else {}  # another invocation's
        for version, figures in cache.items():
            latest.setdefault(version, {}).update(figures)
        Path(a.cache).parent.mkdir(exist_ok=True)
        Path(a.cache).write_text(json.dumps(latest, indent=1) + "\n")

    with tempfile.TemporaryDirectory() as tmp:
        src = export_source(ref, tmp) if ref else None
        for algo, n, preset in cases:
            key = f"{algo}:{preset}:{n}"
            if ref and key not in before and not a.only_now:
                before[key] = measure(algo, n, preset, a.repeats, src)
                save()
                print(key, "baseline", before[key], flush=True)
            if a.only_baseline or (a.reuse and key in after):
                continue
            after[key] = measure(algo, n, preset, a.repeats, None)
            save()
            print(key, "now", after[key], flush=True)
    if a.only_baseline or a.only_now:
        return 0
    shown = {k: v for k, v in after.items() if k.split(":")[0] in algos and int(k.split(":")[2]) in ns}
    med = {k: statistics.median(v["ms_per_sample"]) for k, v in shown.items()}
    lines = [
        "# Training cost of a sample on Hard Move at large K, every algorithm",
        "",
        f"- command: `{' '.join(['python', *sys.argv])}`",
        f"- date: {dt.datetime.now(dt.timezone.utc).isoformat(timespec='minutes')}; current code measured at "
        + ", ".join(sorted({v.get("commit", "?") for v in shown.values()}))
        + " (+: with uncommitted changes to src)"
        + (f", against {ref}" if ref else ""),
        f"- machine: {machine()}",
        f"- CPU ms per training sample, median of {a.repeats} epochs after a warm-up epoch, one worker process per "
        "case and version, torch threads 1; the preset with a short schedule (see the script's docstring); "
        f"off-policy epochs of {', '.join(f'{SAMPLES[n]} (n = {n})' for n in ns)} samples, on-policy epochs of "
        "the preset's batch_size",
        "",
    ]
    cols = ["algorithm (preset)"] + [f"n = {n} (K = {2**n})" for n in ns]
    lines += ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    rows = dict.fromkeys(
        k.rsplit(":", 1)[0] for algo in algos for k in sorted(shown, key=_by_n) if k.startswith(algo + ":")
    )
    for row_key in rows:
        algo, preset = row_key.split(":")
        row = [f"{algo} ({preset})"]
        for n in ns:
            key = f"{row_key}:{n}"
            runs = before.get(key, {}).get("ms_per_sample") if ref else None
            if key not in med:
                row.append("not run")
            elif runs:
                few = f" ({len(runs)} epoch{'s' if len(runs) > 1 else ''})" if len(runs) < a.repeats else ""
                b = statistics.median(runs)
                row.append(f"{b:.2f}{few} -> {med[key]:.2f} (x{b / med[key]:.1f})")
            else:
                row.append(f"{med[key]:.2f}" + (f" (not in {ref})" if ref else ""))
        lines.append("| " + " | ".join(row) + " |")
    if ref:
        lines += ["", f"Each cell: ms a sample at {ref} -> now (speed-up)."]
    from _record import write_record

    write_record(lines, a.out or None)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
