"""PATRPO's policy update with the two Fisher-vector products: Gauss-Newton vs double back-propagation.

For each case (the Platform and soccer experiments' PATRPO settings), one epoch of real samples is
collected, then the policy update (``_update_policy``: the surrogate's gradient, the Fisher-vector product's
set-up, ``cg_iters`` conjugate-gradient products, the line search) runs ``--repeats`` times per method from
the same parameters, the methods alternating so that both see the same load. Also timed: one product alone.
Both methods must end at the same parameters (they are the same matrix); the script reports the gap.
Times are CPU seconds of this process (``time.process_time``), which a shared machine's other processes do not
inflate as they do the wall clock; pin it to one core for steadier figures:

    taskset -c 0 python benchmarks/bench_fvp_speed.py --repeats 5 --out benchmarks/fvp_speed.md
"""

from __future__ import annotations

import argparse
import dataclasses
import datetime as dt
import statistics
import sys
import time
from pathlib import Path

import torch

from pamdp.algos.onpolicy import advantage_batch, update_tensors
from pamdp.algos.patrpo import PATRPO, PATRPOConfig

sys.path.insert(0, str(Path(__file__).parent))
from _record import machine, write_record  # noqa: E402

# (label, env id, settings on top of the paper preset): the platform and soccer experiments' PATRPO arms
CASES = [
    ("Platform (platform experiment)", "pamdp/Platform-v0", {}),
    (
        "Half Field Offense (soccer experiment)",
        "pamdp/HalfFieldOffense-v0",
        {"hidden_sizes": (400, 300, 200), "batch_size": 50_000},
    ),
]
METHODS = ("double_backprop", "gauss_newton")


def measure(env_id: str, settings: dict, repeats: int, batch_scale: float) -> dict:
    cfg = dataclasses.replace(PATRPOConfig(), **settings)
    cfg = dataclasses.replace(cfg, batch_size=max(1000, int(cfg.batch_size * batch_scale)))
    model = PATRPO(env_id, cfg)
    batch = model.rollout.collect(
        model.vec_env, model.policy, model.hybrid, cfg.batch_size, model.np_rng, model.torch_gen
    )
    tensors = update_tensors(advantage_batch(batch, model._values, cfg.gamma, cfg.gae_lambda, True)[0])
    obs, a, x, *_ = tensors
    start = {k: v.clone() for k, v in model.policy.state_dict().items()}
    update, product, end = {m: [] for m in METHODS}, {m: [] for m in METHODS}, {}
    for _ in range(repeats):
        for method in METHODS:
            model.policy.load_state_dict(start)
            model.config = dataclasses.replace(cfg, fvp=method)
            t = time.process_time()
            model._update_policy(*tensors)
            update[method].append(time.process_time() - t)
            end[method] = torch.cat([p.detach().flatten() for p in model.policy.parameters()])
            model.policy.load_state_dict(start)
            with torch.no_grad():
                old = model.policy(obs).detach()
            fvp = model._fisher_vector_product(obs, a, x, old)
            v = torch.randn(end[method].numel())
            t = time.process_time()
            fvp(v)
            product[method].append(time.process_time() - t)
    model.policy.load_state_dict(start)
    theta = torch.cat([p.detach().flatten() for p in model.policy.parameters()])
    step = end["double_backprop"] - theta
    gap = float((end["gauss_newton"] - end["double_backprop"]).abs().max() / step.abs().max())
    return {
        "hidden": "-".join(map(str, cfg.hidden_sizes)),
        "batch": cfg.batch_size,
        "update": {m: statistics.median(v) for m, v in update.items()},
        "product": {m: statistics.median(v) for m, v in product.items()},
        "gap": gap,
    }


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5, help="timed policy updates per method and case")
    parser.add_argument("--batch-scale", type=float, default=1.0, help="shrink the batches, for a quick look")
    parser.add_argument("--out", default=None, help="markdown record to write (default: print only)")
    args = parser.parse_args(argv)
    torch.set_num_threads(1)
    rows = []
    for label, env_id, settings in CASES:
        r = measure(env_id, settings, args.repeats, args.batch_scale)
        u, p = r["update"], r["product"]
        rows.append(
            f"| {label} | {r['hidden']} | {r['batch']:,} | {u['double_backprop']:.2f} | {u['gauss_newton']:.2f} "
            f"| {u['double_backprop'] / u['gauss_newton']:.2f}x | {p['double_backprop']:.3f} | {p['gauss_newton']:.3f} "
            f"| {p['double_backprop'] / p['gauss_newton']:.2f}x | {r['gap']:.1e} |"
        )
        print(rows[-1], flush=True)
    args_text = " ".join(argv if argv is not None else sys.argv[1:])
    command = f"taskset -c 0 python benchmarks/bench_fvp_speed.py {args_text}"
    write_record(
        [
            "# PATRPO's Fisher-vector products: Gauss-Newton vs double back-propagation",
            "",
            f"- command: `{command.strip()}`",
            f"- date: {dt.datetime.now().isoformat(timespec='seconds')}",
            f"- machine: {machine()}; torch threads 1, pinned to one core, CPU seconds of the process",
            f"- medians of {args.repeats} repeats per method, alternating; the paper preset with the experiment's"
            " settings, KL estimator chain_analytic, 10 conjugate-gradient iterations, one epoch of real samples",
            "",
            "| case | hidden layers | batch | update CPU s (double backprop) | update CPU s (Gauss-Newton) | speed-up "
            "| product CPU s (double backprop) | product CPU s (Gauss-Newton) | speed-up | parameter gap |",
            "|---|---|---|---|---|---|---|---|---|---|",
            *rows,
            "",
            "An update is `_update_policy`: the surrogate's gradient, the product's set-up, the conjugate-gradient"
            " products, the line search and the statistics. The parameter gap is the largest difference between"
            " the two methods' updated parameters, over the largest step component (float32 rounding).",
        ],
        args.out,
    )


if __name__ == "__main__":
    main()
