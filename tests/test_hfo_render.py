"""HFO frames: the goalie (defense_npcs=1) is drawn with its body line and catch rectangle; 1v0 is unchanged."""

import hashlib
import math

import gymnasium
import numpy as np
import pytest

import pamdp  # noqa: F401  (registers the envs)
from pamdp.envs.hfo import defense
from pamdp.envs.hfo.interface import _CATCH, _GOALIE, _to_px


def _pixel(frame, x, y):
    c, r = _to_px(x, y)
    return tuple(int(v) for v in frame[int(round(r)), int(round(c))])


def _near(frame, x, y, color):
    """Whether ``color`` is within one pixel of the point (a thin line's samples need not hit its nearest pixel)."""
    c, r = (int(round(v)) for v in _to_px(x, y))
    return bool(np.all(frame[r - 1 : r + 2, c - 1 : c + 2] == color, axis=-1).any())


@pytest.mark.parametrize("goalie_body", [150.0, -120.0])
def test_goalie_disc_and_catch_rectangle_in_front_of_it(goalie_body):
    env = gymnasium.make("pamdp/HalfFieldOffenseGoalie-v0", render_mode="rgb_array")
    env.reset(seed=1, options={"ball": [40.0, 10.0], "player": [35.0, -8.0], "body": 0.0, "goalie_body": goalie_body})
    s = env.unwrapped._states[0]
    gx, gy, body = float(s[defense.GX]), float(s[defense.GY]), float(s[defense.GBODY])
    # The option sets the body at placement; the goalie may turn in the two reset cycles it acts alone, so the
    # frame is checked against the state's body.
    frame = env.render()
    c, sn = math.cos(math.radians(body)), math.sin(math.radians(body))
    assert _pixel(frame, gx - 0.4 * c, gy - 0.4 * sn) == _GOALIE  # on its disc, just off the white body line
    assert _pixel(frame, gx + 0.8 * c, gy + 0.8 * sn) == (240, 240, 240)  # the body line
    # On the rectangle's far edge (1.2 m ahead, 0.35 m aside, off the body line), and its mirror behind the goalie.
    u, v = 1.2, 0.35
    assert _near(frame, gx + u * c - v * sn, gy + u * sn + v * c, _CATCH)
    assert not _near(frame, gx - u * c + v * sn, gy - u * sn - v * c, _CATCH)


def test_1v0_frame_is_unchanged():
    env = gymnasium.make("pamdp/HalfFieldOffense-v0", render_mode="rgb_array")
    env.reset(seed=3, options={"ball": [30.0, 5.0], "player": [20.0, -4.0], "body": 30.0})
    env.action_space.seed(3)
    for _ in range(5):
        env.step(env.action_space.sample())
    frame = env.render()
    assert not (np.all(frame == _GOALIE, axis=-1) | np.all(frame == _CATCH, axis=-1)).any()
    # Computed with this same script at d1fb42e, before the goalie was drawn.
    assert hashlib.sha256(frame.tobytes()).hexdigest() == (
        "1705b200bde944bc6885eaee25d4308f9dbbb52224d4375d0787aae4200db7a3"
    )
