"""HFO against the real server: replay of ``shared/specs/hfo_traces/deterministic_traces_seed42.json``.

``tests/data/hfo_traces_seed42.json.gz`` is a stripped copy (episodes 1-25; per step the action, the
status, the 59 features and the agent's world model). The recording comes from HFO master, whose
features use the ``hfo2019`` normalisers. Features recorded with a terminal status belong to the next
episode (HFO steps three NOOP cycles first), so only statuses are compared there.

Two replays:

* free-running (the issue's test): reset to the recorded ``initial_wm`` and apply the recorded actions.
  The recording gives the initial state to 6 significant digits only (1e-4 m at 10-50 m), and three
  episodes amplify that: a player running into a ball 1 mm away (episode 14: the push-apart direction
  depends on the last 1e-5 m, and the ball then rests 2 mm off for 490 steps of holding) and chains of
  kicks whose power depends on the ball's distance (episodes 2 and 10, 8-20 kicks each). Perturbing the
  initial state within its rounding reproduces episode 14 to 98.8% in 1 of 20 draws and episode 2's
  ending in 4 of 20: these are not model errors. Every other episode must match.
* one-step: before each step the simulator is put in the recorded state, so every step is checked
  against the server on its own, without the chaos.
"""

from __future__ import annotations

import gzip
import json
import pathlib

import numpy as np
import pytest

from pamdp.envs.hfo import HalfFieldOffenseEnv

TRACE = pathlib.Path(__file__).parent / "data" / "hfo_traces_seed42.json.gz"
TOLERANCE = 2e-3
ACTION_IDS = {"DASH": 0, "TURN": 1, "KICK": 2}
#: Episodes whose free-running replay diverges through sensitivity to the 6-digit initial state.
CHAOTIC_EPISODES = {2, 10, 14}


@pytest.fixture(scope="module")
def trace():
    with gzip.open(TRACE, "rt") as f:
        return json.load(f)


def _action(step):
    a = ACTION_IDS[step["action"]]
    params = [np.array([50.0, 0.0], np.float32), np.array([0.0], np.float32), np.array([50.0, 0.0], np.float32)]
    params[a] = np.array(step["params"], dtype=np.float32)
    return a, tuple(params)


def _reset(env, wm):
    return env.reset(options={"player": (wm[1], wm[2]), "ball": (wm[7], wm[8]), "body": wm[5]})


def _set_state(env, wm):
    """Put the simulator in a recorded world-model state (positions, velocities, body, stamina)."""
    g = env.game
    g.px, g.py, g.pvx, g.pvy, g.body, g.stamina, g.bx, g.by, g.bvx, g.bvy = map(float, wm[1:11])
    g.prev_bx, g.prev_by = g.bx, g.by
    g.sense()


def _replay(trace, one_step: bool):
    """Replay every episode; returns per-episode (matching steps, compared steps, end ok) and messages."""
    env = HalfFieldOffenseEnv(deterministic=True, profile="hfo2019")
    names = trace["feature_names"]
    results, messages = {}, []
    for ep in trace["episodes"]:
        i = ep["episode"]
        obs, _ = _reset(env, ep["initial_wm"])
        first = np.abs(obs - np.array(ep["initial_features"]))
        assert first.max() <= TOLERANCE, f"episode {i}: first observation differs in feature {first.argmax()}"
        good = compared = 0
        end_ok = False
        prev_wm = ep["initial_wm"]
        for k, step in enumerate(ep["steps"], start=1):
            if one_step:
                _set_state(env, prev_wm)
            obs, _, terminated, truncated, info = env.step(_action(step))
            where = f"episode {i} ({ep['policy']}) step {k} {step['action']}{step['params']}"
            if info["status"] != step["status"] or info["step"] != k:
                messages.append(f"{where}: status {info['status']}, recorded {step['status']}")
                break
            if step["status"] != "IN_GAME":
                end_ok = (terminated or truncated) and k == ep["num_steps"]
                break
            diff = np.abs(obs - np.array(step["features"], dtype=np.float32))
            compared += 1
            if diff.max() <= TOLERANCE:
                good += 1
            elif len(messages) < 40:
                worst = int(diff.argmax())
                messages.append(
                    f"{where}: {names[worst]} (f{worst}) {obs[worst]:.5f}, recorded {step['features'][worst]:.5f}"
                )
            prev_wm = step["wm"]
        results[i] = (good, compared, end_ok)
    return results, messages


def _summary(results):
    good = sum(r[0] for r in results.values())
    compared = sum(r[1] for r in results.values())
    return good / compared, sum(r[2] for r in results.values())


def test_trace_copy_is_complete(trace):
    assert len(trace["episodes"]) == 25
    assert sum(ep["num_steps"] for ep in trace["episodes"]) == 2879 - 102  # minus episode 0
    assert all(len(s["features"]) == 59 for ep in trace["episodes"] for s in ep["steps"])


def test_one_step_replay_matches_the_server(trace):
    """From each recorded state, one simulated step reproduces the server's next status and features."""
    results, messages = _replay(trace, one_step=True)
    fraction, ends = _summary(results)
    print("\n".join(messages))
    print(f"one-step replay: {fraction:.2%} of IN_GAME steps within {TOLERANCE}; {ends}/25 endings match")
    assert ends == 25, messages
    assert fraction >= 0.99, messages


def test_free_running_replay_matches_the_server(trace):
    """From the recorded initial state and actions alone; see the module docstring for the 3 exceptions."""
    results, messages = _replay(trace, one_step=False)
    fraction, ends = _summary(results)
    print("\n".join(messages))
    print(f"free-running replay: {fraction:.2%} of IN_GAME steps within {TOLERANCE}; {ends}/25 endings match")
    for i, (good, compared, end_ok) in results.items():
        print(f"  episode {i:2d}: {good}/{compared} steps, ending {'matches' if end_ok else 'differs'}")
        if i not in CHAOTIC_EPISODES:
            assert end_ok, f"episode {i} ends differently: {messages}"
            assert good >= 0.9 * compared, f"episode {i}: {good}/{compared} steps match; {messages}"
    assert ends >= 22
    assert fraction >= 0.75
