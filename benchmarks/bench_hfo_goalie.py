"""Half Field Offense 1v1 (the goalie, ``defense_npcs=1``): env steps per CPU-second, scalar and batched.

Run ``python benchmarks/bench_hfo_goalie.py`` (a few minutes); it prints the medians over ``--repeats`` of steps per
CPU-second of this process (``time.process_time``, so another process on the cores does not count), for the
scalar env and the batched env at each ``--num-envs``, with the 1v0 env beside them, interleaved repeat by
repeat. Actions are uniform samples of the action space drawn before timing (autoresets included), as in
``bench_hfo.py``, whose timing loops this reuses. The figures go by hand into ``hfo_goalie_speed.md``.
"""

from __future__ import annotations

import argparse
import os
import pathlib
import statistics
import sys

sys.path.insert(0, str(pathlib.Path(__file__).parent))

from bench_hfo import BATCHED_ENV_STEPS, BATCHED_WARMUP, batched_rate, scalar_rate  # noqa: E402

from pamdp.envs.hfo import HalfFieldOffenseEnv, HalfFieldOffenseVectorEnv  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--scalar-steps", type=int, default=20_000)
    parser.add_argument("--batched-steps", type=int, default=100)
    parser.add_argument("--num-envs", type=int, nargs="+", default=[1024])
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
            if kind == "scalar":
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
