"""Replay recordings of the real HFO server through the simulation, step by step.

A recording (``shared/specs/hfo_traces/``, format in its README) holds, per episode, the initial world
model (``initial_wm``: cycle, player x, y, vx, vy, body angle, stamina, ball x, y, vx, vy, flags), the
actions sent and, after each step, the status, the 59 low-level features and the world model. The
simulation is reset to the recorded placement, the recorded actions are applied and every step is
compared: the status, and on IN_GAME steps all features (the features recorded with a terminal status
already belong to the next episode, so only the status is compared there).

The recorder printed the world model with 6 significant digits, so a recorded placement is only known
to within half a unit of its last digit (:func:`rounding_box`). A few episodes amplify that: a player
running into a ball one millimetre away pushes it off in a direction set by the last 1e-5 m, and a chain
of kicks, whose power depends on the ball's distance, multiplies a small error at every kick.
:func:`replay_episode` therefore accepts an ``initial`` placement inside that box; see
``tests/test_hfo_traces.py`` for how the test uses it; ``tests/data/refine_hfo_trace_placements.py`` is its
other user.
"""

from __future__ import annotations

import gzip
import json
import math
import pathlib
from dataclasses import dataclass, field

import numpy as np

from pamdp.envs.hfo.dynamics import BODY, BVX, BVY, BX, BY, PREV_BX, PREV_BY, PVX, PVY, PX, PY, STAMINA, sense

ACTION_IDS = {"DASH": 0, "TURN": 1, "KICK": 2}
#: ``initial_wm`` indices of the placement a reset takes: player x, y, body angle, ball x, y.
PLACEMENT_INDICES = (1, 2, 5, 7, 8)
PLACEMENT_NAMES = ("player_x", "player_y", "body", "ball_x", "ball_y")


@dataclass
class EpisodeReplay:
    """Outcome of replaying one recorded episode."""

    episode: int
    matching: int = 0
    """IN_GAME steps whose 59 features all lie within the tolerance of the recorded ones."""
    compared: int = 0
    """IN_GAME steps compared (the replay stops at the first status that differs)."""
    ending_matches: bool = False
    """The episode ended with the recorded status on the recorded step."""
    first_error: float = 0.0
    """Largest feature difference of the first observation (after the reset, before any action)."""
    messages: list[str] = field(default_factory=list)
    """One line per mismatch: episode, step, action, worst feature, simulated and recorded value."""

    @property
    def perfect(self) -> bool:
        return self.ending_matches and self.matching == self.compared


def load_trace(path: str | pathlib.Path) -> dict:
    """Read a recording (``.json`` or ``.json.gz``)."""
    path = pathlib.Path(path)
    opener = gzip.open if path.suffix == ".gz" else open
    with opener(path, "rt") as f:
        return json.load(f)


def action(step: dict) -> tuple[int, tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """The env action for a recorded step (the other actions' parameters are placeholders)."""
    a = ACTION_IDS[step["action"]]
    params = [np.array([50.0, 0.0], np.float32), np.array([0.0], np.float32), np.array([50.0, 0.0], np.float32)]
    params[a] = np.asarray(step["params"], dtype=np.float32)
    return a, tuple(params)


def placement(initial_wm: list[float]) -> np.ndarray:
    """The recorded placement (player x, y, body angle, ball x, y) from an ``initial_wm``."""
    return np.array([initial_wm[i] for i in PLACEMENT_INDICES], dtype=np.float64)


def rounding_box(values: np.ndarray, digits: int = 6) -> np.ndarray:
    """Half a unit of the last of ``digits`` significant digits of each value (0 for exact zeros)."""
    values = np.asarray(values, dtype=np.float64)
    out = np.zeros_like(values)
    for i, v in enumerate(values.flat):
        if v != 0.0:
            out.flat[i] = 0.5 * 10.0 ** (math.floor(math.log10(abs(v))) - (digits - 1))
    return out


def set_state(env, wm: list[float]) -> None:
    """Put the simulator in a recorded world-model state (positions, velocities, body, stamina)."""
    s = env.unwrapped.state
    for k, value in zip((PX, PY, PVX, PVY, BODY, STAMINA, BX, BY, BVX, BVY), wm[1:11]):
        s[k] = float(value)
    s[PREV_BX], s[PREV_BY] = s[BX], s[BY]
    sense(s)


def replay_episode(
    env,
    ep: dict,
    feature_names: list[str],
    initial: np.ndarray | None = None,
    one_step: bool = False,
    tolerance: float = 2e-3,
    max_messages: int = 20,
) -> EpisodeReplay:
    """Replay one recorded episode; ``env`` is a ``HalfFieldOffenseEnv(deterministic=True)``.

    Args:
        initial: placement (player x, y, body, ball x, y) to reset to; the recorded one by default.
        one_step: before each step, put the simulator in the recorded state of the previous step, so
            that every step is checked on its own.
    """
    px, py, body, bx, by = placement(ep["initial_wm"]) if initial is None else initial
    obs, _ = env.reset(options={"player": (px, py), "ball": (bx, by), "body": body})
    first_error = float(np.abs(obs - np.asarray(ep["initial_features"], dtype=np.float32)).max())
    result = EpisodeReplay(episode=ep["episode"], first_error=first_error)
    prev_wm = ep["initial_wm"]
    for k, step in enumerate(ep["steps"], start=1):
        if one_step:
            set_state(env, prev_wm)
        obs, _, terminated, truncated, info = env.step(action(step))
        where = f"episode {ep['episode']} ({ep['policy']}) step {k} {step['action']}{step['params']}"
        if info["status"] != step["status"] or info["step"] != k:
            result.messages.append(f"{where}: status {info['status']}, recorded {step['status']}")
            break
        if step["status"] != "IN_GAME":
            result.ending_matches = bool(terminated or truncated) and k == ep["num_steps"]
            break
        diff = np.abs(obs - np.asarray(step["features"], dtype=np.float32))
        result.compared += 1
        if diff.max() <= tolerance:
            result.matching += 1
        elif len(result.messages) < max_messages:
            worst = int(diff.argmax())
            result.messages.append(
                f"{where}: {feature_names[worst]} (f{worst}) {obs[worst]:.5f}, recorded {step['features'][worst]:.5f}"
            )
        prev_wm = step["wm"]
    return result
