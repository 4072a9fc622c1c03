"""Pictures of Robot Soccer Goal: the half pitch from above (``render_mode="rgb_array"``) and episode GIFs."""

from __future__ import annotations

import functools
import math
import os
from collections.abc import Callable

import gymnasium
import numpy as np

from pamdp.envs.goal.dynamics import (
    BALL_CONFIG,
    GOAL_AREA_HALF,
    GOAL_AREA_X,
    HALF_GOAL,
    HALF_LENGTH,
    HALF_WIDTH,
    KEEPER_CONFIG,
    NET_BACK,
    PLAYER_CONFIG,
)
from pamdp.envs.rendering import Canvas, record_episode

__all__ = ["draw_goal", "save_goal_gif", "RENDER_FPS"]

RENDER_SCALE = 16
"""Pixels per metre."""
MARGIN = 1.0
"""Metres of grass drawn around the field (and behind the net)."""
X0, X1 = -MARGIN, NET_BACK + MARGIN
Y0, Y1 = -HALF_WIDTH - MARGIN, HALF_WIDTH + MARGIN
RENDER_WIDTH, RENDER_HEIGHT = round((X1 - X0) * RENDER_SCALE), round((Y1 - Y0) * RENDER_SCALE)
RENDER_FPS = 30
"""Frames (sub-steps) per second of the GIFs."""
GRASS, LINE, NET = (60, 140, 60), (235, 235, 235), (200, 200, 200)
PLAYER_COLOR, KEEPER_COLOR, BALL_COLOR = (40, 80, 220), (210, 50, 50), (255, 255, 255)


def _px(x: float, y: float) -> tuple[float, float]:
    """World (x towards the goal, to the right; y up) to image pixels (y down)."""
    return (x - X0) * RENDER_SCALE, (Y1 - y) * RENDER_SCALE


def draw_goal(
    player_x: float, player_y: float, player_phi: float,
    keeper_x: float, keeper_y: float, keeper_psi: float,
    ball_x: float, ball_y: float,
) -> np.ndarray:  # fmt: skip
    """A ``(RENDER_HEIGHT, RENDER_WIDTH, 3)`` uint8 top view: the field's lines, the goal and its net on
    the right, the keeper (red), the player (blue), each with a tick in the direction it faces, and the
    ball (white)."""
    canvas = Canvas(RENDER_WIDTH, RENDER_HEIGHT)
    canvas.image[:] = _field()
    for x, y, angle, size, color in (
        (keeper_x, keeper_y, keeper_psi, KEEPER_CONFIG[0], KEEPER_COLOR),
        (player_x, player_y, player_phi, PLAYER_CONFIG[0], PLAYER_COLOR),
    ):
        canvas.circle(*_px(x, y), size * RENDER_SCALE, color)
        tip = _px(x + size * math.cos(angle), y + size * math.sin(angle))
        canvas.line(*_px(x, y), *tip, (255, 230, 80), width=3.0)
    cx, cy = _px(ball_x, ball_y)
    canvas.circle(cx, cy, BALL_CONFIG[0] * RENDER_SCALE, BALL_COLOR)
    canvas.circle(cx, cy, BALL_CONFIG[0] * RENDER_SCALE, (20, 20, 20), outline=1.5)
    return canvas.image


@functools.cache
def _field() -> np.ndarray:
    """The frame without players and ball (drawn once: the lines are most of the drawing's cost)."""
    canvas = Canvas(RENDER_WIDTH, RENDER_HEIGHT, background=GRASS)

    def segment(xa, ya, xb, yb, color=LINE):
        canvas.line(*_px(xa, ya), *_px(xb, yb), color, width=2.0)

    canvas.rect(*_px(HALF_LENGTH, HALF_GOAL), *_px(NET_BACK, -HALF_GOAL), NET)
    for xa, ya, xb, yb in (
        (0.0, -HALF_WIDTH, HALF_LENGTH, -HALF_WIDTH),
        (0.0, HALF_WIDTH, HALF_LENGTH, HALF_WIDTH),
        (0.0, -HALF_WIDTH, 0.0, HALF_WIDTH),
        (HALF_LENGTH, -HALF_WIDTH, HALF_LENGTH, HALF_WIDTH),
        (GOAL_AREA_X, -GOAL_AREA_HALF, GOAL_AREA_X, GOAL_AREA_HALF),
        (GOAL_AREA_X, -GOAL_AREA_HALF, HALF_LENGTH, -GOAL_AREA_HALF),
        (GOAL_AREA_X, GOAL_AREA_HALF, HALF_LENGTH, GOAL_AREA_HALF),
    ):
        segment(xa, ya, xb, yb)
    for y in (-HALF_GOAL, HALF_GOAL):  # the posts and the net's sides
        segment(HALF_LENGTH, y, NET_BACK, y, (90, 90, 90))
        canvas.circle(*_px(HALF_LENGTH, y), 3, (40, 40, 40))
    segment(NET_BACK, -HALF_GOAL, NET_BACK, HALF_GOAL, (90, 90, 90))
    canvas.image.flags.writeable = False
    return canvas.image


def save_goal_gif(
    path: str | os.PathLike = "goal.gif",
    policy: Callable[[np.ndarray], object] | None = None,
    seed: int | None = None,
    env_id: str = "pamdp/Goal-v0",
) -> tuple[str, float]:
    """Play one episode of ``env_id`` (Goal or Hard Goal; random actions if ``policy`` is None) into a GIF
    with one frame per sub-step. Returns the GIF's path and the episode's return."""
    env = gymnasium.make(env_id, render_mode="rgb_array")
    try:
        return record_episode(env, policy, path, seed=seed, fps=RENDER_FPS)
    finally:
        env.close()
