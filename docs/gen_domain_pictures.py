"""Draw one frame of each registered domain for the documentation's domain pages (``docs/domains/img/*.png``).

Each env is made with ``render_mode="rgb_array"`` and stepped with seeded random actions, so that the picture
shows the domain in play rather than its start: the first seed whose episode lasts the domain's number of steps
gives the frame (``render()``) after them; random actions end many episodes at once (a fall, a shot). Run from
the repository root after changing an env's drawing: ``python docs/gen_domain_pictures.py``.
"""

from pathlib import Path

import gymnasium
import matplotlib

matplotlib.use("Agg")
import matplotlib.image  # noqa: E402

import pamdp  # noqa: E402, F401  (registers the envs)

OUT = Path(__file__).parent / "domains" / "img"
SEEDS = 100

# page name -> (env id, env kwargs, steps before the picture: enough for the agent to have moved visibly)
DOMAINS = {
    "platform": ("pamdp/Platform-v0", {}, 2),
    "half-field-offense": ("pamdp/HalfFieldOffense-v0", {}, 20),
    "half-field-offense-goalie": ("pamdp/HalfFieldOffenseGoalie-v0", {}, 20),
    "goal": ("pamdp/Goal-v0", {}, 2),
    "hard-goal": ("pamdp/HardGoal-v0", {}, 2),
    "catch-point": ("pamdp/CatchPoint-v0", {}, 5),
    "hard-move": ("pamdp/HardMove-v0", {}, 5),
    "moving": ("pamdp/Moving-v0", {}, 60),
    "sliding": ("pamdp/Sliding-v0", {}, 60),
}


def picture(env_id: str, kwargs: dict, steps: int):
    """The frame after ``steps`` random actions of the first seed whose episode lasts that long, else the last
    frame of the longest episode."""
    env = gymnasium.make(env_id, render_mode="rgb_array", **kwargs)
    best, best_len = None, -1
    for seed in range(SEEDS):
        env.reset(seed=seed)
        env.action_space.seed(seed)
        frame, length = env.render(), 0
        while length < steps:
            _, _, terminated, truncated, _ = env.step(env.action_space.sample())
            if terminated or truncated:
                break
            frame, length = env.render(), length + 1
        if length > best_len:
            best, best_len = frame, length
        if length == steps:
            break
    env.close()
    return best


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    for name, (env_id, kwargs, steps) in DOMAINS.items():
        path = OUT / f"{name}.png"
        matplotlib.image.imsave(path, picture(env_id, kwargs, steps))
        print(f"{path}: {path.stat().st_size // 1024} KB")


if __name__ == "__main__":
    main()
