"""Pictures of Platform: a side view of the course (``render_mode="rgb_array"``) and episode GIFs."""

from __future__ import annotations

import os
from collections.abc import Callable

import gymnasium
import numpy as np

from pamdp.envs.platform.physics import PLATFORM_HEIGHT, PLATFORMS, PLAYER_H, PLAYER_W, X_GOAL
from pamdp.envs.rendering import Canvas, record_episode

__all__ = ["draw_platform", "save_platform_gif", "RENDER_FPS"]

RENDER_SCALE = 0.6
RENDER_WIDTH, RENDER_HEIGHT = int((X_GOAL + PLAYER_W) * RENDER_SCALE), int(200 * RENDER_SCALE)
RENDER_FPS = 20
"""One frame per physics sub-step (dt = 0.05 s) plays the episode in real time."""


def draw_platform(player_x: float, player_y: float, enemy1_x: float, enemy2_x: float) -> np.ndarray:
    """A ``(120, 633, 3)`` uint8 side view: grey platforms, red enemies, blue player, green goal line."""
    canvas = Canvas(RENDER_WIDTH, RENDER_HEIGHT, background=(235, 242, 250))
    s, h = RENDER_SCALE, RENDER_HEIGHT

    def box(x, y, w, hgt, color):  # world (y up) to image (y down)
        canvas.rect(x * s, h - (y + hgt) * s, (x + w) * s, h - y * s, color)

    for px, w in PLATFORMS:
        box(px, 0.0, w, PLATFORM_HEIGHT, (110, 110, 110))
    canvas.line(X_GOAL * s, 0, X_GOAL * s, h, (40, 170, 60), width=2)
    for ex in (enemy1_x, enemy2_x):
        box(ex, PLATFORM_HEIGHT, PLAYER_W, PLAYER_H, (210, 50, 50))
    box(player_x, player_y, PLAYER_W, PLAYER_H, (40, 80, 220))
    return canvas.image


def save_platform_gif(
    path: str | os.PathLike = "platform.gif",
    policy: Callable[[np.ndarray], object] | None = None,
    seed: int | None = None,
) -> tuple[str, float]:
    """Play one ``pamdp/Platform-v0`` episode (random actions if ``policy`` is None) into a GIF with one
    frame per physics sub-step. Returns the GIF's path and the episode's return."""
    env = gymnasium.make("pamdp/Platform-v0", render_mode="rgb_array")
    try:
        return record_episode(env, policy, path, seed=seed, fps=RENDER_FPS)
    finally:
        env.close()
