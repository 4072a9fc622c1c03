"""Hard Move's step in CPU-microseconds (``time.process_time``), median of 9 timings of 400 steps, at n = 4 and 10:
the batched env at 16 copies with its boxes as a tuple (``batch_space``'s format), stacked in one array, and as the
algorithms hand them (``HybridActionSpace.to_env_batch``), and the scalar env. Run it on two commits with
``PYTHONPATH=<checkout>/src python benchmarks/bench_hard_move_check.py`` in turns (benchmarks/env_speed.md)."""

import statistics
import time

import gymnasium
import numpy as np

import pamdp  # noqa: F401  (registers the envs)
from pamdp.spaces import HybridActionSpace


def med(f, reps=9, inner=400):
    times = []
    for _ in range(reps):
        start = time.process_time()
        for _ in range(inner):
            f()
        times.append((time.process_time() - start) / inner * 1e6)
    return statistics.median(times)


def timings(n: int) -> dict[str, float]:
    venv = gymnasium.make_vec(
        "pamdp/HardMove-v0", num_envs=16, vectorization_mode="vector_entry_point", n=n, max_episode_steps=None
    )
    venv.reset(seed=0)
    venv.action_space.seed(0)
    space, rng = HybridActionSpace.from_gym(venv.single_action_space), np.random.default_rng(0)
    tuples = [venv.action_space.sample() for _ in range(8)]
    batches = {
        "tuple": tuples,
        "stacked": [(a, np.stack(p)) for a, p in tuples],
        "to_env_batch": [space.to_env_batch(rng.integers(0, 2**n, 16), rng.uniform(-1, 1, (16, 1))) for _ in range(8)],
    }
    env = gymnasium.make("pamdp/HardMove-v0", n=n).unwrapped
    env.reset(seed=0)
    env.action_space.seed(0)
    scalar = [env.action_space.sample() for _ in range(8)]
    turn = iter(range(10**9))

    def scalar_step():
        if any(env.step(scalar[next(turn) % 8])[2:4]):
            env.reset()

    def batched_step(actions):
        return lambda: venv.step(actions[next(turn) % 8])

    return {**{name: med(batched_step(actions)) for name, actions in batches.items()}, "scalar": med(scalar_step)}


def main() -> None:
    for n in (4, 10):
        print(f"n = {n}: " + ", ".join(f"{k} {v:.1f} us" for k, v in timings(n).items()), flush=True)


if __name__ == "__main__":
    main()
