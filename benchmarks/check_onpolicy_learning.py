"""Do the on-policy algorithms still learn Platform? A short seeded run of each, well above the random policy.

PATRPO's and PAPPO's ``tuned`` presets train one seed each for ``--samples`` samples, then play ``--episodes``
greedy episodes (evaluation seed 123). The uniformly random policy scores 0.154 (spec section 8); a run that
learns ends well above it. The record also gives a digest of the final weights: two versions whose maths is the
same give the same digest, so the check tells a refactoring that changed nothing from one that changed the runs.
This was a unit test (40 000 samples of PATRPO) until learning runs moved out of the unit suite.

    taskset -c 0 python benchmarks/check_onpolicy_learning.py --out benchmarks/onpolicy_learning_short.md
"""

from __future__ import annotations

import argparse
import datetime as dt
import hashlib
import sys
import time
from pathlib import Path

import torch

from pamdp import PAPPO, PATRPO
from pamdp.evaluation import evaluate

sys.path.insert(0, str(Path(__file__).parent))
from _record import machine, write_record  # noqa: E402

RANDOM_POLICY = 0.154  # Platform's mean return under uniformly random actions (spec section 8)


def run(cls, samples: int, episodes: int, seed: int) -> dict:
    config = cls.config_class.from_dict({"seed": seed}, base=cls.config_class.preset("tuned"))
    model = cls("pamdp/Platform-v0", config)
    returns: list[float] = []
    start = time.process_time()
    model.learn(samples, progress_bar=False, callback=lambda algo, s: returns.append(s.get("charts/episodic_return")))
    cpu = time.process_time() - start
    result = evaluate(model, episodes=episodes, seed=123)
    digest = hashlib.sha256()
    for name, module in model._modules().items():
        for key, tensor in module.state_dict().items():
            digest.update(f"{name}.{key}".encode() + tensor.detach().contiguous().numpy().tobytes())
    return {
        "samples": model.num_timesteps,
        "train": returns[-1],
        "greedy": result["mean_return"],
        "cpu": cpu,
        "digest": digest.hexdigest()[:16],
    }


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=40_000, help="training samples per run")
    parser.add_argument("--episodes", type=int, default=300, help="greedy evaluation episodes")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", default=None, help="markdown record to write (default: print only)")
    args = parser.parse_args(argv)
    torch.set_num_threads(1)
    rows = []
    for cls in (PATRPO, PAPPO):
        r = run(cls, args.samples, args.episodes, args.seed)
        verdict = "learns" if r["greedy"] > RANDOM_POLICY + 0.1 else "NOT above the random policy"
        rows.append(
            f"| {cls.__name__} | tuned | {args.seed} | {r['samples']:,} | {r['train']:.3f} | {r['greedy']:.3f} "
            f"| {verdict} | {r['cpu']:.0f} | `{r['digest']}` |"
        )
        print(rows[-1], flush=True)
    args_text = " ".join(argv if argv is not None else sys.argv[1:])
    write_record(
        [
            "# On-policy learning check: PATRPO and PAPPO on Platform, short seeded runs",
            "",
            f"- command: `taskset -c 0 python benchmarks/check_onpolicy_learning.py {args_text}`",
            f"- date: {dt.datetime.now().isoformat(timespec='seconds')}",
            f"- machine: {machine()}; torch threads 1",
            f"- greedy return over {args.episodes} episodes (evaluation seed 123); the random policy scores"
            f" {RANDOM_POLICY}; 'learns' means more than 0.1 above it",
            "",
            "| algorithm | preset | seed | samples | last epoch's training return | greedy return | verdict "
            "| training CPU s | weights digest |",
            "|---|---|---|---|---|---|---|---|---|",
            *rows,
        ],
        args.out,
    )


if __name__ == "__main__":
    main()
