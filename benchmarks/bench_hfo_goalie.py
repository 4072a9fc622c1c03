"""Half Field Offense 1v1 (the goalie, ``defense_npcs=1``): env steps per CPU-second, scalar and batched.

Run ``python benchmarks/bench_hfo_goalie.py`` (a few minutes); it prints the medians over ``--repeats`` of steps per
CPU-second of this process (``time.process_time``, so another process on the cores does not count), for the
scalar env and the batched env at each ``--num-envs``, with the 1v0 env beside them, interleaved repeat by
repeat. Actions are uniform samples of the action space drawn before timing (autoresets included), as in
``bench_hfo.py``, whose timing loops this reuses. ``--scorer`` times instead the scripted scorer's play (its
own cost not counted), where the goalie chases and intercepts in most cycles, the dearest part of its
decision. The figures go by hand into ``hfo_goalie_speed.md``.
"""

from __future__ import annotations

import argparse
import os
import pathlib
import statistics
import sys
import time

sys.path.insert(0, str(pathlib.Path(__file__).parent))

from bench_hfo import BATCHED_ENV_STEPS, BATCHED_WARMUP, batched_rate, scalar_rate  # noqa: E402

from pamdp.envs.hfo import (  # noqa: E402
    HalfFieldOffenseEnv,
    HalfFieldOffenseVectorEnv,
    scripted_scorer,
    scripted_scorer_batch,
)


def scorer_rate(env, steps: int) -> float:
    """Env-steps per CPU-second of ``env.step`` (and scalar resets) under the scripted scorer, whose own time
    is left out."""
    batched = isinstance(env, HalfFieldOffenseVectorEnv)
    obs = env.reset(seed=0)[0]
    spent = 0.0
    for _ in range(steps):
        action = scripted_scorer_batch(obs) if batched else scripted_scorer(obs)
        start = time.process_time()
        obs, _, terminated, truncated, _ = env.step(action)
        if not batched and (terminated or truncated):
            obs, _ = env.reset()
        spent += time.process_time() - start
    return steps * (env.num_envs if batched else 1) / spent


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--scalar-steps", type=int, default=20_000)
    parser.add_argument("--batched-steps", type=int, default=100)
    parser.add_argument("--num-envs", type=int, nargs="+", default=[1024])
    parser.add_argument("--scorer", action="store_true", help="time the scripted scorer's play instead")
    args = parser.parse_args()
    space = HalfFieldOffenseEnv().action_space
    space.seed(0)
    scalar_actions = [space.sample() for _ in range(2000)]
    envs, actions = {}, {}
    for npcs in (1, 0):
        envs[(npcs, "scalar")] = HalfFieldOffenseEnv(defense_npcs=npcs)
        envs[(npcs, "scalar")].reset(seed=0)
        for n in args.num_envs:
            env = HalfFieldOffenseVectorEnv(num_envs=n, defense_npcs=npcs)
            env.action_space.seed(0)
            actions[n] = [env.action_space.sample() for _ in range(16)]
            env.reset(seed=0)
            batched_rate(env, actions[n], BATCHED_WARMUP)  # includes Numba's compilation
            envs[(npcs, n)] = env
    rates = {key: [] for key in envs}
    for _ in range(args.repeats):
        for (npcs, kind), env in envs.items():
            if args.scorer:
                steps = args.scalar_steps // 4 if kind == "scalar" else max(args.batched_steps // 2, 2_000 // kind)
                rates[(npcs, kind)].append(scorer_rate(env, steps))
            elif kind == "scalar":
                rates[(npcs, kind)].append(scalar_rate(env, scalar_actions, args.scalar_steps))
            else:
                steps = max(args.batched_steps, BATCHED_ENV_STEPS // kind)
                rates[(npcs, kind)].append(batched_rate(env, actions[kind], steps))
    print(f"load average {os.getloadavg()}")
    for (npcs, kind), r in rates.items():
        print(f"defense_npcs={npcs} {kind!s:>6}: median {statistics.median(r):>12,.0f} steps/CPU-s  "
              f"(repeats {', '.join(f'{x:,.0f}' for x in r)})")  # fmt: skip


if __name__ == "__main__":
    main()
