"""Would training several seeds in one process, with their networks stacked, make the off-policy arms cheaper?

The platform experiment's PADDPG and PASVG(0) arms cost ~65 core-hours on the project machine, almost all of
it gradient updates of {400, 300} networks on batches of 32 to 64 (benchmarks/offpolicy_speed.md). One way to
cut that would be to train S seeds in one process: each weight matrix becomes an (S, in, out) stack, a layer one
``baddbmm``, and Adam (elementwise) on the stacks is exactly S independent Adams. Per-op overhead would then be
paid once for S seeds. This measures what that buys before anyone builds it.

The stacked update is a model of PADDPG's paper-preset update (it is not the library's code): a critic step on a
TD target from target networks, an actor step through the critic with inverting gradients, per-seed gradient-norm
clipping, fused Adam and soft target updates, on random batches. Each case runs in worker processes pinned to
their own core (``os.sched_setaffinity``), all started together, with one torch thread each; the figure is member
updates per second summed over the processes (median of ``--repeats``). The library's own ``PADDPG._update`` on
one core is measured too, for scale.

    python benchmarks/bench_seed_batching.py --out benchmarks/seed_batching.md

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
# (label, members per process, one entry per process)
CASES = [
    ("one process, 1 seed", [1]),
    ("one process, 5 seeds stacked", [5]),
    ("two processes, 1 seed each (the backlog's layout)", [1, 1]),
    ("two processes, 3 seeds stacked each", [3, 3]),
]
HIDDEN, BATCH, OBS, OUT = (400, 300), 32, 9, 6  # PADDPG's paper preset on Platform: 3 scores + 3 parameters


def stacked_update(members: int):
    """A warmed-up stacked update of ``members`` PADDPG-sized learners, as a callable."""
    import torch
    import torch.nn.functional as F

    torch.set_num_threads(1)
    gen = torch.Generator().manual_seed(0)

    def init(sizes):
        params = []
        for n_in, n_out in zip(sizes[:-1], sizes[1:]):
            params.append((torch.randn(members, n_in, n_out, generator=gen) / n_in**0.5).requires_grad_())
            params.append(torch.zeros(members, 1, n_out).requires_grad_())
        return params

    def forward(params, x):
        for k in range(0, len(params), 2):
            x = torch.baddbmm(params[k + 1], x, params[k])
            if k + 2 < len(params):
                x = F.leaky_relu(x, 0.01)
        return x

    def clip(params, max_norm=10.0):  # each member's own gradient norm
        norms = torch.stack([p.grad.pow(2).flatten(1).sum(1) for p in params]).sum(0).sqrt()
        scale = (max_norm / (norms + 1e-6)).clamp(max=1.0)
        for p in params:
            p.grad.mul_(scale.view(-1, *[1] * (p.dim() - 1)))

    actor, critic = init([OBS, *HIDDEN, OUT]), init([OBS + OUT, *HIDDEN, 1])
    actor_t, critic_t = [p.detach().clone() for p in actor], [p.detach().clone() for p in critic]
    opt_a = torch.optim.Adam(actor, lr=1e-5, betas=(0.95, 0.999), fused=True)
    opt_c = torch.optim.Adam(critic, lr=1e-3, betas=(0.95, 0.999), fused=True)

    def update():
        obs, next_obs = torch.rand(members, BATCH, OBS), torch.rand(members, BATCH, OBS)
        reward, out_b = torch.rand(members, BATCH, 1), torch.rand(members, BATCH, OUT) * 2 - 1
        with torch.no_grad():
            y = reward + 0.99 * forward(critic_t, torch.cat([next_obs, forward(actor_t, next_obs).clamp(-1, 1)], -1))
        loss = (forward(critic, torch.cat([obs, out_b], -1)) - y).pow(2).mean(dim=(1, 2)).sum()
        opt_c.zero_grad(set_to_none=True)
        loss.backward()
        clip(critic)
        opt_c.step()
        opt_a.zero_grad(set_to_none=True)
        out = forward(actor, obs)
        p = out.detach().requires_grad_(True)
        (g,) = torch.autograd.grad(forward(critic, torch.cat([obs, p], -1)).sum(), p)
        g = g * torch.where(g > 0, (1 - p.detach()) / 2, (p.detach() + 1) / 2)  # inverting gradients
        out.backward(-g / BATCH)
        clip(actor)
        opt_a.step()
        with torch.no_grad():
            torch._foreach_lerp_(critic_t, [p.detach() for p in critic], 0.001)
            torch._foreach_lerp_(actor_t, [p.detach() for p in actor], 0.001)

    for _ in range(30):
        update()
    return update


def library_update():
    """The library's ``PADDPG._update`` (paper preset, Platform), warmed up, as a callable."""
    import dataclasses

    import torch

    from pamdp.algos.paddpg import PADDPG, PADDPGConfig

    torch.set_num_threads(1)
    config = dataclasses.replace(PADDPGConfig(), learning_starts=2000, epoch_steps=2000, buffer_size=100_000)
    model = PADDPG("pamdp/Platform-v0", config)
    model.learn(2000, progress_bar=False)
    for _ in range(30):
        model._update()
    return model._update


def worker(core: int, members: int, updates: int, repeats: int) -> None:
    """Pinned to the ``core``-th allowed CPU: build and warm up, say so, then time once the parent says go."""
    os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[core]})
    update = library_update() if members == 0 else stacked_update(members)
    print("ready", flush=True)
    sys.stdin.readline()  # every worker of the case starts timing together
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        for _ in range(updates):
            update()
        times.append((time.perf_counter() - start) / updates)
    print(json.dumps({"members": members, "times": times}), flush=True)


def run_case(counts: list[int], updates: int, repeats: int) -> list[dict]:
    from _record import run_together

    return run_together(
        [
            [sys.executable, __file__, "--worker", str(core), str(m), str(updates), str(repeats)]
            for core, m in enumerate(counts)
        ]
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--updates", type=int, default=100, help="updates per repeat (default: %(default)s)")
    parser.add_argument("--repeats", type=int, default=5, help="repeats per worker (default: %(default)s)")
    parser.add_argument("--out", default=None, help="markdown record to write (default: print only)")
    parser.add_argument("--worker", nargs=4, type=int, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        worker(*args.worker)
        return
    if len(os.sched_getaffinity(0)) < 2:
        raise SystemExit("needs two cores (the two-process cases pin one worker to each)")
    load = os.getloadavg()[0]
    rows = []
    lib = run_case([0], args.updates, args.repeats)[0]
    lib_ms = statistics.median(lib["times"]) * 1e3
    for label, counts in CASES:
        results = run_case(counts, args.updates, args.repeats)
        per_proc = [statistics.median(r["times"]) for r in results]
        rate = sum(m / t for m, t in zip(counts, per_proc))
        rows.append((label, counts, [t * 1e3 for t in per_proc], rate))
        print(f"{label}: {rate:.0f} member-updates/s", file=sys.stderr)
    base = next(rate for label, counts, _, rate in rows if counts == [1, 1])
    sys.path.insert(0, str(HERE))
    from _record import machine, write_record

    lines = [
        "# Seed batching: several seeds' networks stacked in one process (PADDPG-sized updates)",
        "",
        f"- command: `python benchmarks/bench_seed_batching.py --updates {args.updates} --repeats {args.repeats}"
        + (f" --out {args.out}`" if args.out else "`"),
        f"- date: {dt.datetime.now().isoformat(timespec='seconds')}",
        f"- load average at the start: {load:.1f}; machine: {machine()}",
        f"- networks {HIDDEN[0]}-{HIDDEN[1]} (actor {OBS} -> {OUT}, critic {OBS + OUT} -> 1), batch {BATCH} per "
        f"seed, one torch thread per process, each process pinned to its own core; medians of {args.repeats} "
        f"repeats of {args.updates} updates",
        f"- for scale, the library's `PADDPG._update` (paper preset, Platform, replay sampling and logging "
        f"included) on one core: {lib_ms:.2f} ms",
        "",
        "| layout | seeds per process | ms per update (per process) | seed-updates/s in all | vs. backlog layout |",
        "|---|---|---|---|---|",
    ]
    for label, counts, ms, rate in rows:
        lines.append(
            f"| {label} | {', '.join(map(str, counts))} | {', '.join(f'{m:.2f}' for m in ms)} | {rate:.0f} "
            f"| {rate / base:.2f}x |"
        )
    write_record(lines, args.out)


if __name__ == "__main__":
    main()
