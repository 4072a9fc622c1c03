"""What the scalar and the batched HFO env share at their boundary: the action space, the validation of
settings and reset options, and the top-down drawing for ``render_mode="rgb_array"``."""

from __future__ import annotations

import functools

import numpy as np
from gymnasium import spaces

from pamdp.envs import hfo_physics as phys
from pamdp.envs.hfo_features import PROFILES
from pamdp.envs.rendering import Canvas

ACTION_NAMES = ("DASH", "TURN", "KICK")
PARAM_SIZES = (2, 1, 2)
PARAM_LOW = (np.array([0.0, -180.0]), np.array([-180.0]), np.array([0.0, -180.0]))
PARAM_HIGH = (np.array([100.0, 180.0]), np.array([180.0]), np.array([100.0, 180.0]))
ACTION_FORM = "(a, (dash[power, direction], turn[direction], kick[power, direction])) with a in {0, 1, 2}"


def hfo_action_space() -> spaces.Tuple:
    """``Tuple(Discrete(3), Tuple(Box(2), Box(1), Box(2)))`` in HFO's units (powers 0-100, degrees)."""
    boxes = tuple(
        spaces.Box(lo.astype(np.float32), hi.astype(np.float32), dtype=np.float32)
        for lo, hi in zip(PARAM_LOW, PARAM_HIGH)
    )
    return spaces.Tuple((spaces.Discrete(3), spaces.Tuple(boxes)))


def check_options(
    profile: str, body_reset: str
) -> None:  # shared with the batched env so both reject the same settings
    """Raise ``ValueError`` for an unknown feature profile or body-reset rule."""
    if profile not in PROFILES:
        raise ValueError(f"profile={profile!r} is not one of {sorted(PROFILES)}")
    if body_reset not in ("carry", "uniform"):
        raise ValueError(f"body_reset={body_reset!r}; expected 'carry' (HFO's behaviour) or 'uniform'")


def parse_reset_options(options: dict | None) -> dict[str, np.ndarray]:
    """Validate ``reset(options=...)``: any of ``ball`` (x, y), ``player`` (x, y), ``body`` (degrees).

    The ball must lie in HFO's play area (0 <= x <= 52.5, |y| <= 34), the player on the pitch
    (|x| <= 52.5, |y| <= 34). Returns the given entries as float arrays of shape (2,) or ().
    """
    if options is None:
        return {}
    if not isinstance(options, dict):
        raise ValueError(f"reset options must be a dict, got {type(options).__name__}")
    unknown = set(options) - {"ball", "player", "body"}
    if unknown:
        raise ValueError(f"unknown reset option(s) {sorted(unknown)}; expected any of 'ball', 'player', 'body'")
    parsed = {}
    limits = {"ball": (0.0, phys.PITCH_HALF_LENGTH), "player": (-phys.PITCH_HALF_LENGTH, phys.PITCH_HALF_LENGTH)}
    for key, (x_lo, x_hi) in limits.items():
        if key not in options:
            continue
        value = options[key]
        try:
            xy = np.asarray(value, dtype=np.float64)
        except (TypeError, ValueError):
            xy = None
        if xy is None or xy.shape != (2,) or not np.all(np.isfinite(xy)):
            raise ValueError(f"reset option {key}={value!r}; expected a pair of finite numbers (x, y) in metres")
        if not (x_lo <= xy[0] <= x_hi and abs(xy[1]) <= phys.PITCH_HALF_WIDTH):
            raise ValueError(
                f"reset option {key}={tuple(xy.tolist())} is outside the allowed area "
                f"{x_lo} <= x <= {x_hi}, |y| <= {phys.PITCH_HALF_WIDTH}"
            )
        parsed[key] = xy
    if "body" in options:
        value = options["body"]
        try:
            body = np.asarray(value, dtype=np.float64)
        except (TypeError, ValueError):
            body = None
        if body is None or body.shape != () or not np.isfinite(body):
            raise ValueError(f"reset option body={value!r}; expected one finite angle in degrees")
        parsed["body"] = body
    return parsed


# --- drawing -----------------------------------------------------------------------------------
_PX_PER_M = 6.0
_X_MIN, _X_MAX, _Y_MAX = -3.0, 56.0, 37.0
_GRASS, _LINE, _GOAL, _BALL, _PLAYER = (60, 140, 60), (240, 240, 240), (200, 200, 200), (250, 250, 250), (30, 80, 220)


def _to_px(x: float, y: float) -> tuple[float, float]:
    return (x - _X_MIN) * _PX_PER_M, (y + _Y_MAX) * _PX_PER_M


@functools.lru_cache(maxsize=1)
def _field_image() -> np.ndarray:
    """The static part of every frame: grass, touch and goal lines, penalty box, goal and posts."""
    canvas = Canvas(int((_X_MAX - _X_MIN) * _PX_PER_M), int(2 * _Y_MAX * _PX_PER_M), _GRASS)

    def hline(x0, x1, y, width=1.6):
        (a, b), (c, _) = _to_px(x0, y), _to_px(x1, y)
        canvas.rect(a, b - width / 2, c, b + width / 2, _LINE)

    def vline(x, y0, y1, width=1.6):
        (a, b), (_, d) = _to_px(x, y0), _to_px(x, y1)
        canvas.rect(a - width / 2, b, a + width / 2, d, _LINE)

    L, W = phys.PITCH_HALF_LENGTH, phys.PITCH_HALF_WIDTH
    gw = phys.GOAL_HALF_WIDTH
    canvas.rect(*_to_px(L, -gw), *_to_px(L + 2.44, gw), _GOAL)
    hline(0, L, -W, 2.0)
    hline(0, L, W, 2.0)
    vline(0, -W, W, 2.0)
    vline(L, -W, W, 2.0)
    pa_x, pa_w = phys.PENALTY_AREA_X, phys.PENALTY_AREA_HALF_WIDTH
    vline(pa_x, -pa_w, pa_w)
    hline(pa_x, L, -pa_w)
    hline(pa_x, L, pa_w)
    for sy in (-1.0, 1.0):
        canvas.circle(*_to_px(phys.POST_X, sy * phys.POST_Y), 2.0, (20, 20, 20))
    canvas.image.flags.writeable = False
    return canvas.image


def draw_half_field(px: float, py: float, body: float, bx: float, by: float) -> np.ndarray:
    """An ``(H, W, 3)`` uint8 top view of the attacked half: lines, goal, posts, penalty box, ball, player.

    The player is a blue disc with a white line along its body direction; y grows downwards as in the
    server's frame.
    """
    field = _field_image()
    canvas = Canvas(field.shape[1], field.shape[0])
    canvas.image[:] = field
    radius = max(phys.BALL_SIZE * _PX_PER_M, 2.5)
    canvas.circle(*_to_px(bx, by), radius, _BALL)
    canvas.circle(*_to_px(bx, by), radius, (0, 0, 0), outline=1.0)
    canvas.circle(*_to_px(px, py), max(phys.PLAYER_SIZE * _PX_PER_M, 4.0), _PLAYER)
    theta = np.radians(body)
    canvas.line(*_to_px(px, py), *_to_px(px + 1.2 * np.cos(theta), py + 1.2 * np.sin(theta)), _LINE, 2.0)
    return canvas.image
