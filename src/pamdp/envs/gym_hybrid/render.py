"""Pictures of Moving and Sliding: the field from above (``render_mode="rgb_array"``)."""

from __future__ import annotations

import numpy as np

import pamdp.envs.gym_hybrid.dynamics as dyn
from pamdp.envs.rendering import Canvas

__all__ = ["draw_gym_hybrid", "RENDER_FPS", "RENDER_SIZE"]

VIEW = 1.1
"""Half-size of the picture in field units: a margin around the field shows an agent that left it."""
SCALE = 200.0
"""Pixels per field unit."""
RENDER_SIZE = int(2 * VIEW * SCALE)
RENDER_FPS = 20
AGENT_RADIUS = 0.05
"""The original's drawing radius of the agent (the agent itself is a point)."""


def draw_gym_hybrid(state: np.ndarray, sliding: bool) -> np.ndarray:
    """A square uint8 top view of one copy's ``state`` row: the field (light) in its margin (grey), the
    target circle (red), the agent (blue) with its heading (black) and its velocity (orange, its length
    proportional to the speed; along the heading for Moving, along the velocity direction for Sliding)."""
    canvas = Canvas(RENDER_SIZE, RENDER_SIZE, background=(150, 150, 150))

    def px(x, y):  # field (y up) to image (y down)
        return (x + VIEW) * SCALE, (VIEW - y) * SCALE

    canvas.rect(*px(-dyn.FIELD, dyn.FIELD), *px(dyn.FIELD, -dyn.FIELD), (240, 240, 235))
    tx, ty = px(state[dyn.TX], state[dyn.TY])
    canvas.circle(tx, ty, dyn.TARGET_RADIUS * SCALE, (250, 170, 170))
    canvas.circle(tx, ty, dyn.TARGET_RADIUS * SCALE, (200, 40, 40), outline=2.0)
    x, y = state[dyn.X], state[dyn.Y]
    ax, ay = px(x, y)
    canvas.circle(ax, ay, AGENT_RADIUS * SCALE, (40, 80, 220))
    theta = state[dyn.THETA]
    canvas.line(ax, ay, *px(x + 2 * AGENT_RADIUS * np.cos(theta), y + 2 * AGENT_RADIUS * np.sin(theta)), (0, 0, 0), 3.0)
    speed = state[dyn.SPEED]
    if speed > 0:
        motion = state[dyn.PHI] if sliding else theta
        length = min(0.2 * speed, 1.0)
        end = px(x + length * np.cos(motion), y + length * np.sin(motion))
        canvas.line(ax, ay, *end, (240, 140, 20), 3.0)
    return canvas.image
