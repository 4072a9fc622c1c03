"""Small NumPy drawing primitives for ``render_mode="rgb_array"``, and episode-to-GIF recording.

No display is needed: frames are ``uint8`` arrays of shape ``(H, W, 3)``; GIFs are written with Pillow
(installed with Matplotlib).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence

import numpy as np

Color = tuple[int, int, int]


class Canvas:
    """An RGB image with (x right, y down) pixel coordinates; shapes falling outside are clipped."""

    def __init__(self, width: int, height: int, background: Color = (255, 255, 255)):
        self.image = np.empty((int(height), int(width), 3), dtype=np.uint8)
        self.image[:] = background

    @property
    def height(self) -> int:
        return self.image.shape[0]

    @property
    def width(self) -> int:
        return self.image.shape[1]

    def rect(self, x0: float, y0: float, x1: float, y1: float, color: Color) -> None:
        """Fill the axis-aligned rectangle with corners ``(x0, y0)`` and ``(x1, y1)``."""
        c0, c1 = sorted((int(round(x0)), int(round(x1))))
        r0, r1 = sorted((int(round(y0)), int(round(y1))))
        c0, r0 = max(c0, 0), max(r0, 0)
        c1, r1 = min(c1, self.width), min(r1, self.height)
        if c0 < c1 and r0 < r1:
            self.image[r0:r1, c0:c1] = color

    def circle(self, cx: float, cy: float, radius: float, color: Color, outline: float = 0.0) -> None:
        """Fill a disc (or, with ``outline > 0``, a ring of that thickness)."""
        r0, r1 = max(int(cy - radius - 1), 0), min(int(cy + radius + 2), self.height)
        c0, c1 = max(int(cx - radius - 1), 0), min(int(cx + radius + 2), self.width)
        if r0 >= r1 or c0 >= c1:
            return
        yy, xx = np.mgrid[r0:r1, c0:c1]
        d2 = (xx - cx) ** 2 + (yy - cy) ** 2
        inside = d2 <= radius**2
        if outline > 0:
            inside &= d2 >= max(radius - outline, 0.0) ** 2
        self.image[r0:r1, c0:c1][inside] = color

    def line(self, x0: float, y0: float, x1: float, y1: float, color: Color, width: float = 1.0) -> None:
        """Draw a segment of the given thickness."""
        n = int(max(abs(x1 - x0), abs(y1 - y0))) + 1
        for t in np.linspace(0.0, 1.0, n):
            self.circle(x0 + t * (x1 - x0), y0 + t * (y1 - y0), width / 2.0, color)


def _check_gif_path(path: str | os.PathLike) -> None:
    if not os.fspath(path).lower().endswith(".gif"):
        raise ValueError(f"animation path {os.fspath(path)!r}; expected a file name ending in .gif")


def save_gif(frames: Sequence[np.ndarray], path: str | os.PathLike, fps: float = 20.0) -> str:
    """Write ``(H, W, 3)`` uint8 frames to an animated GIF; returns the path."""
    from PIL import Image

    _check_gif_path(path)
    if len(frames) == 0:
        raise ValueError("save_gif needs at least one frame; got an empty sequence")
    images = [Image.fromarray(np.asarray(f, dtype=np.uint8)) for f in frames]
    path = os.fspath(path)
    images[0].save(path, save_all=True, append_images=images[1:], duration=int(1000 / fps), loop=0)
    return path


def record_episode(
    env,
    policy: Callable[[np.ndarray], object] | None = None,
    path: str | os.PathLike = "episode.gif",
    seed: int | None = None,
    max_steps: int = 10_000,
    fps: float = 20.0,
    action_mask: bool = False,
) -> tuple[str, float]:
    """Play one episode in ``env`` (made with ``render_mode="rgb_array"``) and save it as a GIF.

    ``policy`` maps an observation to an env action; ``None`` samples random actions. ``action_mask``: the policy
    also takes the valid actions, ``policy(obs, action_mask=info["action_mask"])``, as a model trained with masks
    does (``model.predict``): without them it may pick an action that was masked throughout training. An env whose
    agent step spans several physics sub-steps may offer ``render_substeps()``, one frame per sub-step of
    the last step (Platform does); those frames are recorded instead of one frame per step.
    Returns the GIF's path and the episode's return.
    """
    if getattr(env, "render_mode", None) != "rgb_array":
        raise ValueError(f"record_episode needs an env made with render_mode='rgb_array', got {env.render_mode!r}")
    _check_gif_path(path)  # before the episode, not after it
    obs, info = env.reset(seed=seed)
    if seed is not None:
        env.action_space.seed(seed)
    substep_frames = getattr(env.unwrapped, "render_substeps", None)
    frames, total = [env.render()], 0.0
    for _ in range(max_steps):
        if policy is None:
            action = env.action_space.sample()
        else:
            action = policy(obs, action_mask=info["action_mask"]) if action_mask else policy(obs)
        obs, reward, terminated, truncated, info = env.step(action)
        total += float(reward)
        if substep_frames is None:
            frames.append(env.render())
        else:
            frames.extend(substep_frames())
        if terminated or truncated:
            break
    return save_gif(frames, path, fps=fps), total
