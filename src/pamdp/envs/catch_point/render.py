"""Pictures of Catch Point: the plane from above (``render_mode="rgb_array"``)."""

from __future__ import annotations

import numpy as np

import pamdp.envs.particle as particle

__all__ = ["draw_catch_point"]


def draw_catch_point(state: np.ndarray, last_action: int | None = None) -> np.ndarray:
    """A ``(320, 320, 3)`` uint8 top view of one copy (its state row): the target (green) and the
    agent (blue, with its velocity), an orange ring of the catch radius round the agent after a catch
    attempt, and along the top the 11 failed catches allowed (red: spent, grey: left)."""
    canvas = particle.draw_plane(state)
    if last_action == particle.CATCH:
        x, y = particle.to_pixels(state[particle.AX], state[particle.AY])
        canvas.circle(x, y, particle.CATCH_RADIUS * particle.PIXELS_PER_UNIT, (240, 140, 20), outline=2.0)
    particle.draw_agent(canvas, state)
    spent = int(state[particle.FAILS])
    for k in range(particle.MAX_FAILED_CATCHES):
        canvas.circle(12.0 + 14.0 * k, 12.0, 5.0, (210, 50, 50) if k < spent else (190, 190, 190))
    return canvas.image
