"""The HFO domain's boundary: the action space, the action mask, the checks of batched actions, settings and reset
options, and the top-down drawing for ``render_mode="rgb_array"``."""

from __future__ import annotations

import functools
import math

import numpy as np
from gymnasium import spaces

import pamdp.envs.hfo.dynamics as dyn
from pamdp.envs.hfo import defense
from pamdp.envs.rendering import Canvas
from pamdp.envs.vector import shown

ACTION_NAMES = ("DASH", "TURN", "KICK")
PARAM_SIZES = (2, 1, 2)
PARAM_LOW = (np.array([0.0, -180.0]), np.array([-180.0]), np.array([0.0, -180.0]))
PARAM_HIGH = (np.array([100.0, 180.0]), np.array([180.0]), np.array([100.0, 180.0]))
ACTION_FORM = "(a, (dash[power, direction], turn[direction], kick[power, direction])) with a in {0, 1, 2}"
#: Order of the reset options in the vector the compiled reset reads (NaN where not given); ``goalie_body``
#: only with the goalie (``defense_npcs=1``).
OPTION_SLOTS = {"ball": slice(0, 2), "player": slice(2, 4), "body": slice(4, 5), "goalie_body": slice(5, 6)}


def hfo_action_space() -> spaces.Tuple:
    """``Tuple(Discrete(3), Tuple(Box(2), Box(1), Box(2)))`` in HFO's units (powers 0-100, degrees)."""
    boxes = tuple(
        spaces.Box(lo.astype(np.float32), hi.astype(np.float32), dtype=np.float32)
        for lo, hi in zip(PARAM_LOW, PARAM_HIGH)
    )
    return spaces.Tuple((spaces.Discrete(3), spaces.Tuple(boxes)))


_LANDMARKS = (
    "goal_centre", "goal_post_top", "goal_post_bottom", "penalty_centre", "penalty_corner_top",
    "penalty_corner_bottom", "field_centre", "corner_top_left", "corner_top_right", "corner_bottom_right",
    "corner_bottom_left",
)  # fmt: skip
_BASIC_FEATURES = (
    ("self_pos_valid", "self_vel_valid", "self_vel_dir_sin", "self_vel_dir_cos", "self_speed", "body_sin", "body_cos",
     "stamina", "frozen", "colliding_ball", "colliding_player", "colliding_post", "kickable")
    + tuple(f"{name}_{part}" for name in _LANDMARKS for part in ("sin", "cos", "proximity"))
    + ("oob_left", "oob_right", "oob_top", "oob_bottom", "ball_pos_valid", "ball_sin", "ball_cos", "ball_proximity",
       "ball_vel_valid", "ball_speed", "ball_vel_dir_sin", "ball_vel_dir_cos")
)  # fmt: skip
_OPPONENT_FEATURES = ("sin", "cos", "proximity", "body_sin", "body_cos", "speed", "vel_dir_sin", "vel_dir_cos")


def feature_names(n_basic_plus_flag: int, goalie: bool) -> tuple[str, ...]:
    """The name of every observation feature, in order (HFO's low-level feature set): the 58 basic ones, the
    goalie's block (``opponent0_*``, its uniform number with ``n_basic_plus_flag`` = 59) and the last-action flag
    where the profile has it. The same feature has the same name in 1v0 and 1v1, so a policy's input weights can be
    carried from one to the other by name (``pamdp train --init-from``)."""
    flag = n_basic_plus_flag == 59
    names = _BASIC_FEATURES + tuple(f"opponent0_{f}" for f in _OPPONENT_FEATURES) * goalie
    return names + ("opponent0_unum",) * (goalie and flag) + ("last_action_ok",) * flag


def kick_mask(states: np.ndarray) -> np.ndarray:
    """The actions with an effect in one state vector ``(STATE_SIZE,)`` or a batch ``(N, STATE_SIZE)``: DASH and
    TURN always, KICK where the agent's kickable test passes (``dynamics.simulate`` drops it otherwise)."""
    mask = np.ones(states.shape[:-1] + (3,), dtype=bool)
    mask[..., dyn.KICK] = states[..., dyn.KICKABLE_NOW] != 0.0
    return mask


def check_settings(profile: str, body_reset: str, defense_npcs: int = 0) -> None:
    """Raise ``ValueError`` for an unknown feature profile, body-reset rule or number of defense NPCs (the shell
    checks the render mode)."""
    if isinstance(defense_npcs, bool) or defense_npcs not in (0, 1):
        raise ValueError(f"defense_npcs={defense_npcs!r}; expected 0 (empty goal) or 1 (HFO's goalie)")
    if profile not in dyn.PROFILES:
        raise ValueError(f"profile={profile!r} is not one of {sorted(dyn.PROFILES)}")
    if body_reset not in ("carry", "uniform"):
        raise ValueError(f"body_reset={body_reset!r}; expected 'carry' (HFO's behaviour) or 'uniform'")


def parse_actions(actions, n: int):
    """A batch of actions as ``(a, dash, turn, kick)``: int64 (N,) and float64 (N, 2), (N, 1), (N, 2);
    ``ValueError`` if malformed, or if any parameter of a copy is not finite (the unused ones too)."""
    expected = f"{ACTION_FORM}, batched: (a[{n}], (dash[{n}, 2], turn[{n}, 1], kick[{n}, 2]))"
    try:
        a_raw, params = actions
        a = np.asarray(a_raw)
        boxes = [np.ascontiguousarray(p, dtype=np.float64) for p in params]
    except (TypeError, ValueError):
        raise ValueError(f"actions are malformed; expected {expected}") from None
    if a.shape != (n,) or len(boxes) != 3 or any(b.shape != (n, m) for b, m in zip(boxes, PARAM_SIZES)):
        shapes = (a.shape, tuple(b.shape for b in boxes)) if len(boxes) == 3 else a.shape
        raise ValueError(f"malformed actions of shapes {shapes}; expected {expected}")
    dash, turn, kick = boxes
    i, what = dyn.first_bad_action(a, dash, turn, kick)  # one compiled pass: NumPy's were most of a scalar step
    if what == 0 and i >= 0:
        raise ValueError(f"discrete actions {a.tolist()}; expected integers 0 (DASH), 1 (TURN) or 2 (KICK)")
    a = a.astype(np.int64, copy=False)
    if i >= 0:
        shown = f"dash {dash[i].tolist()}, turn {turn[i].tolist()}, kick {kick[i].tolist()}"
        raise ValueError(
            f"copy {i}: action {a[i]} ({ACTION_NAMES[a[i]]}) with non-finite parameters ({shown}); expected every "
            "parameter finite, used or not"
        )
    return a, dash, turn, kick


def reset_options(options, n: int, shell_keys: tuple[str, ...] = (), goalie: bool = False) -> np.ndarray:
    """``reset(options=...)`` as an ``(n, 6)`` array (ball x, y, player x, y, body, goalie body; NaN where not
    given).

    Any of ``ball`` (x, y), ``player`` (x, y), ``body`` (degrees) and, with the goalie (``goalie``),
    ``goalie_body`` (degrees), each once for every copy or one per copy (a leading axis of size n). The ball
    must lie in HFO's play area (0 <= x <= 52.5, |y| <= 34), the player on the pitch (|x| <= 52.5, |y| <= 34).
    ``shell_keys`` (the batched env's ``reset_mask``) are let through for the caller.
    """
    out = np.full((n, OPTION_SLOTS["goalie_body"].stop), np.nan)
    if options is None:
        return out
    if not isinstance(options, dict):
        raise ValueError(f"reset options must be a dict, got {type(options).__name__}")
    keys = [k for k in OPTION_SLOTS if goalie or k != "goalie_body"]
    unknown = set(options) - {*keys, *shell_keys}
    if unknown:
        expected = ", ".join(repr(k) for k in keys)
        raise ValueError(f"unknown reset option(s) {sorted(unknown)}; expected any of {expected}")
    for key in keys:
        slots = OPTION_SLOTS[key]
        if key in options:
            out[:, slots] = _option(key, options[key], n).reshape(-1, slots.stop - slots.start)
    return out


def _option(key: str, value, n: int) -> np.ndarray:
    """One reset option, checked, as an array of shape (2,) or () or, given per copy, (n, 2) or (n,)."""
    point = key in ("ball", "player")
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        arr = None
    shapes = ((2,), (n, 2)) if point else ((), (n,))
    if arr is None or arr.shape not in shapes or not np.all(np.isfinite(arr)):
        if point:
            raise ValueError(f"reset option {key}={shown(value)}; expected a pair of finite numbers (x, y) in metres")
        raise ValueError(f"reset option {key}={shown(value)}; expected one finite angle in degrees")
    if point:
        x_lo = 0.0 if key == "ball" else -dyn.PITCH_HALF_LENGTH
        for x, y in arr.reshape(-1, 2):
            if not (x_lo <= x <= dyn.PITCH_HALF_LENGTH and abs(y) <= dyn.PITCH_HALF_WIDTH):
                raise ValueError(
                    f"reset option {key}={(float(x), float(y))} is outside the allowed area "
                    f"{x_lo} <= x <= {dyn.PITCH_HALF_LENGTH}, |y| <= {dyn.PITCH_HALF_WIDTH}"
                )
    return arr


# --- drawing -----------------------------------------------------------------------------------
_PX_PER_M = 6.0
_X_MIN, _X_MAX, _Y_MAX = -3.0, 56.0, 37.0
_GRASS, _LINE, _GOAL, _BALL, _PLAYER = (60, 140, 60), (240, 240, 240), (200, 200, 200), (250, 250, 250), (30, 80, 220)
_GOALIE, _CATCH = (220, 40, 40), (255, 220, 0)
#: The goalie's catch rectangle relative to its body (goalie spec 1.7, 4.1): 0 <= x <= 1.2 ahead, |y| <= 0.5.
_CATCH_L, _CATCH_HALF_W = 1.2, 0.5


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

    L, W = dyn.PITCH_HALF_LENGTH, dyn.PITCH_HALF_WIDTH
    gw = dyn.GOAL_HALF_WIDTH
    canvas.rect(*_to_px(L, -gw), *_to_px(L + 2.44, gw), _GOAL)
    hline(0, L, -W, 2.0)
    hline(0, L, W, 2.0)
    vline(0, -W, W, 2.0)
    vline(L, -W, W, 2.0)
    pa_x, pa_w = dyn.PENALTY_AREA_X, dyn.PENALTY_AREA_HALF_WIDTH
    vline(pa_x, -pa_w, pa_w)
    hline(pa_x, L, -pa_w)
    hline(pa_x, L, pa_w)
    for sy in (-1.0, 1.0):
        canvas.circle(*_to_px(dyn.POST_X, sy * dyn.POST_Y), 2.0, (20, 20, 20))
    canvas.image.flags.writeable = False
    return canvas.image


def draw_half_field(state: np.ndarray, goalie: bool = False) -> np.ndarray:
    """An ``(H, W, 3)`` uint8 top view of the attacked half of one copy's ``state``: lines, goal, posts,
    penalty box, ball, player, and with ``goalie`` (a ``defense`` state row) the goalie.

    The player is a blue disc with a white line along its body direction; y grows downwards as in the
    server's frame. The goalie is a red disc with a white body line and the yellow outline of its catch
    rectangle (1.2 m ahead along its body, 1 m wide; the catch probability is 1 inside it).
    """
    px, py, body, bx, by = (float(state[k]) for k in (dyn.PX, dyn.PY, dyn.BODY, dyn.BX, dyn.BY))
    field = _field_image()
    canvas = Canvas(field.shape[1], field.shape[0])
    canvas.image[:] = field
    radius = max(dyn.BALL_SIZE * _PX_PER_M, 2.5)
    canvas.circle(*_to_px(bx, by), radius, _BALL)
    canvas.circle(*_to_px(bx, by), radius, (0, 0, 0), outline=1.0)
    canvas.circle(*_to_px(px, py), max(dyn.PLAYER_SIZE * _PX_PER_M, 4.0), _PLAYER)
    theta = math.radians(body)
    canvas.line(*_to_px(px, py), *_to_px(px + 1.2 * math.cos(theta), py + 1.2 * math.sin(theta)), _LINE, 2.0)
    if goalie:
        _draw_goalie(canvas, state)
    return canvas.image


def _draw_goalie(canvas: Canvas, state: np.ndarray) -> None:
    gx, gy, body = (float(state[k]) for k in (defense.GX, defense.GY, defense.GBODY))
    c, s = math.cos(math.radians(body)), math.sin(math.radians(body))
    box = [(0.0, -_CATCH_HALF_W), (_CATCH_L, -_CATCH_HALF_W), (_CATCH_L, _CATCH_HALF_W), (0.0, _CATCH_HALF_W)]
    corners = [_to_px(gx + u * c - v * s, gy + u * s + v * c) for u, v in box]
    for (x0, y0), (x1, y1) in zip(corners, corners[1:] + corners[:1]):
        canvas.line(x0, y0, x1, y1, _CATCH, 1.5)
    # The disc and body line on top: the rectangle's back edge runs through the goalie's centre.
    canvas.circle(*_to_px(gx, gy), max(dyn.PLAYER_SIZE * _PX_PER_M, 4.0), _GOALIE)
    canvas.line(*_to_px(gx, gy), *_to_px(gx + 1.2 * c, gy + 1.2 * s), _LINE, 2.0)
