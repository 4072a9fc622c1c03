"""Pictures of Hard Move: the plane from above (``render_mode="rgb_array"``)."""

from __future__ import annotations

import numpy as np

import pamdp.envs.particle as particle
from pamdp.envs.hard_move.motions import action_bits, actuators

__all__ = ["draw_hard_move"]

SPOKE = 0.25
"""Length of an actuator's spoke in the picture (world units)."""


def draw_hard_move(state: np.ndarray, n: int, last_action: int | None = None, p: float = 0.0) -> np.ndarray:
    """A ``(320, 320, 3)`` uint8 top view of one copy (its state row): the target (green), the agent
    (blue, with its velocity) and round the agent its ``n`` actuators as spokes, those the last action switched on in
    orange (pointing backwards when its parameter was negative)."""
    canvas = particle.draw_plane(state)
    x, y = state[particle.AX], state[particle.AY]
    on = action_bits(n)[last_action] if last_action is not None else np.zeros(n)
    for (dx, dy), active in zip(actuators(n), on):
        sign = -1.0 if active and p < 0 else 1.0
        x0, y0 = particle.to_pixels(x, y)
        x1, y1 = particle.to_pixels(x + sign * SPOKE * dx, y + sign * SPOKE * dy)
        canvas.line(x0, y0, x1, y1, (240, 140, 20) if active else (170, 170, 190), width=3.0 if active else 1.0)
    particle.draw_agent(canvas, state)
    return canvas.image
