"""Draw one frame of each registered domain for the documentation's domain pages (``docs/domains/img/*.png``).

Each env is made with ``render_mode="rgb_array"``, reset with seed 0 and stepped a few times with seeded random
actions, so that the picture shows the domain in play rather than its start; ``render()`` gives the frame. Run
from the repository root after changing an env's drawing: ``python docs/gen_domain_pictures.py``.
"""

from pathlib import Path

import gymnasium
import matplotlib

matplotlib.use("Agg")
import matplotlib.image  # noqa: E402

import pamdp  # noqa: E402, F401  (registers the envs)

OUT = Path(__file__).parent / "domains" / "img"
STEPS = 5  # a few steps in: the agent has moved, the episode is not over yet on any domain

# page name -> (env id, env kwargs)
DOMAINS = {
    "platform": ("pamdp/Platform-v0", {}),
    "half-field-offense": ("pamdp/HalfFieldOffense-v0", {}),
    "goal": ("pamdp/Goal-v0", {}),
    "hard-goal": ("pamdp/HardGoal-v0", {}),
    "catch-point": ("pamdp/CatchPoint-v0", {}),
    "hard-move": ("pamdp/HardMove-v0", {}),
    "moving": ("pamdp/Moving-v0", {}),
    "sliding": ("pamdp/Sliding-v0", {}),
}


def picture(env_id: str, kwargs: dict):
    env = gymnasium.make(env_id, render_mode="rgb_array", **kwargs)
    env.reset(seed=0)
    env.action_space.seed(0)
    frame = env.render()
    for _ in range(STEPS):
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        if terminated or truncated:
            break
        frame = env.render()
    env.close()
    return frame


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    for name, (env_id, kwargs) in DOMAINS.items():
        path = OUT / f"{name}.png"
        matplotlib.image.imsave(path, picture(env_id, kwargs))
        print(f"{path}: {path.stat().st_size // 1024} KB")


if __name__ == "__main__":
    main()
