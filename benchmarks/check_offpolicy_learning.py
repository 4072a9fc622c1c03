"""Does a change leave the off-policy algorithms' learning as it was? Short seeded runs, compared across versions.

Each case trains one seed of an algorithm's preset on Platform for ``--samples`` samples (updates from
``--starts`` samples on, small epochs), then reports the mean training return of its last epoch, the greedy
return over ``--episodes`` evaluation episodes, and a digest of its final weights. With ``--baseline REF`` the
same cases run on the package at git commit ``REF`` too (exported to a temporary directory, as
``bench_offpolicy_speed.py`` does): where the maths did not change the digests are equal, so the runs are the
same to the last bit; where it did, the returns say whether learning still looks the same.

    python benchmarks/check_offpolicy_learning.py --baseline f56f96a --out benchmarks/offpolicy_learning_check.md
"""

from __future__ import annotations

import argparse
import dataclasses
import datetime as dt
import hashlib
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).parent
REPO = HERE.parent
# (algorithm, preset, settings on top of the preset, label)
CASES = [
    ("PASVG0", "paper", {}, "paper (hand-written update)"),
    ("PASVG0", "tuned", {}, "tuned (autograd update)"),
    ("PADDPG", "paper", {}, "paper"),
    ("PDQN", "tuned", {"multi_pass": False}, "tuned (P-DQN)"),
    ("PDQN", "tuned", {"multi_pass": True}, "tuned (MP-DQN)"),
    ("HyAR", "cpu", {"warmup_updates": 300, "vae_interval": 500}, "cpu"),
]


def worker(algo: str, preset: str, overrides: dict, samples: int, starts: int, episodes: int) -> dict:
    import torch

    import pamdp
    from pamdp.evaluation import evaluate

    cls = getattr(pamdp, algo)
    config = dataclasses.replace(cls.config_class.preset(preset), **overrides, epoch_steps=samples // 3)
    start = "warmup_steps" if algo == "HyAR" else "learning_starts"
    config = dataclasses.replace(config, **{start: starts})
    torch.set_num_threads(1)
    model = cls("pamdp/Platform-v0", config)
    epochs = []
    model.learn(samples, progress_bar=False, callback=lambda m, s: epochs.append(s))
    digest = hashlib.sha256()
    for _, module in sorted(model._modules().items()):
        for p in module.state_dict().values():
            digest.update(p.detach().numpy().tobytes())
    greedy = evaluate(model, episodes, seed=1)["mean_return"]
    last = epochs[-1]
    return {
        "train_return": float(last.get("charts/episodic_return", float("nan"))),
        "greedy_return": greedy,
        "updates": int(sum(e.get("train/updates", 0) for e in epochs)),
        "digest": digest.hexdigest()[:12],
    }


def export_source(ref: str, dest: str) -> str:
    sys.path.insert(0, str(HERE))
    from bench_offpolicy_speed import export_source as export

    return export(ref, dest)


def run(case: tuple, args, src: str | None) -> dict:
    env = dict(os.environ)
    if src is not None:
        env["PYTHONPATH"] = src + os.pathsep + env.get("PYTHONPATH", "")
    algo, preset, overrides, _ = case
    cmd = [sys.executable, __file__, "--worker", json.dumps([algo, preset, overrides])]
    cmd += ["--samples", str(args.samples), "--starts", str(args.starts), "--episodes", str(args.episodes)]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True, env=env).stdout
    return json.loads(out.strip().splitlines()[-1])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=3_000, help="samples per run (default: %(default)s)")
    parser.add_argument("--starts", type=int, default=500, help="samples before the first update")
    parser.add_argument("--episodes", type=int, default=50, help="greedy evaluation episodes")
    parser.add_argument("--baseline", metavar="REF", help="git commit to compare with")
    parser.add_argument("--out", default=None, help="markdown record to write (default: print only)")
    parser.add_argument("--worker", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        algo, preset, overrides = json.loads(args.worker)
        print(json.dumps(worker(algo, preset, overrides, args.samples, args.starts, args.episodes)))
        return 0
    head = "| algorithm | preset | updates | training return (last epoch) | greedy return | weights digest |"
    rule = "|---|---|---|---|---|---|"
    if args.baseline:
        head = (
            f"| algorithm | preset | updates | training return at {args.baseline} / now | greedy return at "
            f"{args.baseline} / now | weights digest at {args.baseline} / now | same bits |"
        )
        rule = "|---|---|---|---|---|---|---|"
    lines = [
        "# Off-policy learning, short seeded runs: one seed (0) of each case on Platform",
        "",
        f"- command: `python benchmarks/{Path(__file__).name} {' '.join(argv or sys.argv[1:])}`",
        f"- date: {dt.datetime.now().isoformat(timespec='seconds')}",
        f"- {args.samples:,} samples per run, updates from {args.starts:,} on, epochs of {args.samples // 3:,}; "
        f"greedy return over {args.episodes} episodes (`pamdp.evaluation.evaluate`, seed 1); torch threads 1",
        "",
        head,
        rule,
    ]
    with tempfile.TemporaryDirectory() as tmp:
        base_src = export_source(args.baseline, tmp) if args.baseline else None
        for case in CASES:
            now = run(case, args, None)
            cells = [case[0], case[3], now["updates"]]
            if args.baseline:
                base = run(case, args, base_src)
                cells += [f"{base['train_return']:.3f} / {now['train_return']:.3f}"]
                cells += [f"{base['greedy_return']:.3f} / {now['greedy_return']:.3f}"]
                cells += [f"{base['digest']} / {now['digest']}", "yes" if base["digest"] == now["digest"] else "no"]
            else:
                cells += [f"{now['train_return']:.3f}", f"{now['greedy_return']:.3f}", now["digest"]]
            lines.append("| " + " | ".join(map(str, cells)) + " |")
            print(lines[-1], flush=True)
    from _record import write_record

    write_record(lines, args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
