"""HFO 1v1 against the goalie (``defense_npcs=1``): the observation replay of the real server's recording, the
worked examples of the episode boundary, and what ``defense_npcs`` leaves unchanged."""

from __future__ import annotations

import gymnasium as gym
import hfo_goalie_obs_replay as replay
import numpy as np
import pytest

import pamdp  # noqa: F401
from pamdp.envs.hfo import defense, goalie, scripted_scorer, scripted_scorer_batch
from pamdp.envs.hfo import dynamics as dyn

#: Episodes whose ending turns on the post-catch collision, decided by the last bits of the positions (the server
#: moves the goalie to exactly touching distance; whether the squared distance lands below contact is
#: arithmetic noise). The goalie's recorded body angle is rounded to 1e-3 degrees, and inside that rounding the
#: outcome flips back and forth; these offsets (well inside +-5e-4) pick a value that gives the recorded ending.
GOALIE_BODY_WITHIN_ROUNDING = {13: 5e-5, 26: 1e-4}


@pytest.fixture(scope="module")
def trace():
    return replay.load()


def test_the_recording_replays_observation_by_observation(trace):
    figures = replay.replay(trace)
    assert figures.compared > 1800
    assert figures.matching / figures.compared >= 0.98
    assert (figures.feature_matching / figures.compared).min() >= 0.98
    # With the goalie's body as logged, only the two post-catch collisions can differ (see above).
    assert figures.endings_matching >= figures.episodes - len(GOALIE_BODY_WITHIN_ROUNDING)


def test_within_the_logged_rounding_every_ending_is_the_recorded_one(trace):
    episodes = [dict(e) for e in trace["episodes"]]
    for e in episodes:
        e["goalie_body_deg"] = (e["goalie_body_deg"] or 0.0) + GOALIE_BODY_WITHIN_ROUNDING.get(e["episode"], 0.0)
    figures = replay.replay({**trace, "episodes": episodes})
    assert figures.endings_matching / figures.episodes >= 0.95
    assert figures.matching / figures.compared >= 0.98


def make(**kwargs):
    return gym.make("pamdp/HalfFieldOffense-v0", defense_npcs=1, deterministic=True, profile="hfo2019", **kwargs)


def test_first_commands_after_a_reset_and_the_first_observation():
    """Spec example (recorded cycles 1-3): goalie at S(52.5, 0) facing 180, ball S(3.9327, 16.1319) at rest:
    (turn -46.205), then (dash 45) twice; the agent first sees it after the first two."""
    env = make()
    env.reset(options={"ball": (3.9327, 16.1319), "player": (0.0, 0.0), "body": 0.0, "goalie_body": 180.0})
    s = env.unwrapped.state
    assert s[defense.GBODY] == pytest.approx(180.0 - 46.205, abs=1e-9)
    # One dash of 45 from rest: acceleration 0.27 along the body, speed 0.27 * 0.4 after the decay.
    assert np.hypot(s[defense.GVX], s[defense.GVY]) == pytest.approx(0.27 * 0.4, abs=1e-9)
    assert s[defense.GX] < 52.5 and s[dyn.UNTOUCHED] == 2 and s[dyn.CYCLES] == 2


def test_a_capture_ends_the_episode_and_the_dead_cycle_catch_sets_the_next_body():
    """Spec 5.10: the goalie's centre within 1.085 of the ball ends the episode with CAPTURED_BY_DEFENSE at
    once; its decision on the terminal state is a catch, which turns its body towards the ball, and that body
    survives the reset."""
    env = make()
    obs, info = env.reset(options={"ball": (50.0, 3.0), "player": (40.0, 10.0), "body": 0.0, "goalie_body": 180.0})
    for _ in range(60):
        obs, reward, terminated, truncated, info = env.step(scripted_scorer(obs))
        if terminated or truncated:
            break
    assert info["status"] == "CAPTURED_BY_DEFENSE" and terminated and not truncated
    assert reward == 0.0 and not info["is_success"]
    s = env.unwrapped.state
    memory = s[defense.MEMORY : defense.MEMORY + goalie.MEMORY_SIZE]
    assert memory[goalie.M_CATCH_MODE] == 1.0 and s[defense.CATCH_BAN] > 0  # caught at the end or in the dead cycle
    body, ban = s[defense.GBODY], s[defense.CATCH_BAN]
    obs, info = env.reset()
    s = env.unwrapped.state
    assert s[defense.GBODY] != 180.0 and s[defense.CATCH_BAN] == max(ban - 2, 0)  # ban counts through the reset
    # The goalie's first two commands after the placement turned or dashed from the carried body only.
    assert abs(dyn.normalize_angle(s[defense.GBODY] - body)) <= 180.0
    assert s[defense.MEMORY + goalie.M_CATCH_MODE] == 0.0


def test_observation_sizes_and_the_goalie_block():
    for profile, size in (("hfo2016", 66), ("hfo2017", 68), ("hfo2019", 68)):
        env = gym.make("pamdp/HalfFieldOffense-v0", defense_npcs=1, profile=profile)
        obs, _ = env.reset(seed=3)
        assert obs.shape == (size,) and env.observation_space.contains(obs)
    obs, _ = make().reset(seed=3)
    assert obs[66] == np.float32(0.01) and obs[67] == -1.0  # uniform number 1; no action yet
    # The goalie on its line about 50 m away: proximity 1 - 2 d / 85.908.
    assert -0.5 < obs[60] < 0.2


def test_defense_npcs_zero_is_1v0_and_other_values_are_refused():
    a = gym.make("pamdp/HalfFieldOffense-v0")
    b = gym.make("pamdp/HalfFieldOffense-v0", defense_npcs=0)
    oa, _ = a.reset(seed=5)
    ob, _ = b.reset(seed=5)
    assert oa.shape == (59,) and np.array_equal(oa, ob)
    with pytest.raises(ValueError, match="defense_npcs"):
        gym.make("pamdp/HalfFieldOffense-v0", defense_npcs=2)
    with pytest.raises(ValueError, match="goalie_body"):
        a.reset(options={"goalie_body": 10.0})


def test_1v1_places_ball_and_agent_as_1v0_with_the_same_seed():
    """The goalie draws nothing at a reset: a 1v1 run reproduces the 1v0 placements (noise off: with noise the
    goalie's turns draw from the copy's one stream)."""
    a = gym.make("pamdp/HalfFieldOffense-v0", profile="hfo2019", deterministic=True)
    b = make()
    for seed in (1, None, None):
        oa, _ = a.reset(seed=seed)
        ob, _ = b.reset(seed=seed)
        sa, sb = a.unwrapped.state, b.unwrapped.state
        assert np.array_equal(sa[[dyn.PX, dyn.PY, dyn.BX, dyn.BY]], sb[[dyn.PX, dyn.PY, dyn.BX, dyn.BY]])


def test_batched_copy_i_is_the_scalar_env_seeded_seed_plus_i_through_captures_and_dead_cycles():
    """With noise on and the scorer's actions, so that episodes end by HFO's own endings (captures, goals), whose
    dead cycles and hidden cycles draw from each copy's stream."""
    n, seed = 4, 21
    venv = gym.make_vec("pamdp/HalfFieldOffenseGoalie-v0", num_envs=n, vectorization_mode="vector_entry_point")
    envs = [gym.make("pamdp/HalfFieldOffenseGoalie-v0") for _ in range(n)]
    obs, _ = venv.reset(seed=seed)
    singles = [env.reset(seed=seed + i)[0] for i, env in enumerate(envs)]
    np.testing.assert_array_equal(obs, np.stack(singles))
    ended = np.zeros(n, dtype=int)
    pending = np.zeros(n, dtype=bool)
    for _ in range(300):
        obs, reward, terminated, truncated, info = venv.step(scripted_scorer_batch(obs))
        for i, env in enumerate(envs):
            if pending[i]:
                single, r = env.reset()[0], 0.0
            else:
                single, r, te, tr, inf = env.step(scripted_scorer(singles[i]))
                assert (te, tr, inf["status"]) == (terminated[i], truncated[i], info["status"][i])
            np.testing.assert_array_equal(obs[i], single)
            assert reward[i] == r
            singles[i] = single
        pending = terminated | truncated
        ended += pending
    assert (ended >= 2).all()


def test_the_worked_catch_example_moves_the_goalie_and_the_capture_ends_the_same_step():
    """Spec example (server frame): goalie at (50, 0) facing 180, ball at rest at (49, -0.7). The goalie catches
    (catch 57.612): the server moves it to (49.31540, -0.47922), facing -145.008 degrees, at rest; the ball is not
    held, but it now lies 0.385 m from the goalie, so the referee ends the episode in that same step."""
    env = make()
    env.reset(options={"ball": (10.0, 0.0), "player": (30.0, 20.0), "body": 0.0, "goalie_body": 180.0})
    s = env.unwrapped.state
    s[[defense.GX, defense.GY, defense.GVX, defense.GVY, defense.GBODY]] = 50.0, 0.0, 0.0, 0.0, 180.0
    s[[dyn.BX, dyn.BY, dyn.PREV_BX, dyn.PREV_BY]] = 49.0, -0.7, 49.0, -0.7
    dyn.sense(s)
    _, reward, terminated, _, info = env.step((1, (np.zeros(2), np.zeros(1), np.zeros(2))))
    assert info["status"] == "CAPTURED_BY_DEFENSE" and terminated
    assert s[defense.GX] == pytest.approx(49.31540, abs=1e-5) and s[defense.GY] == pytest.approx(-0.47922, abs=1e-5)
    assert s[defense.GVX] == s[defense.GVY] == 0.0
    # The dead cycle after a catch-then-capture: the goalie, believing it holds the ball, turns to face the
    # centre spot (at rest, so in one turn); that body, not the catch's -145.008, starts the next episode.
    assert s[defense.MEMORY + goalie.M_CATCH_MODE] == 1.0
    assert s[defense.GBODY] == pytest.approx(np.degrees(np.arctan2(0.47922, -49.31540)), abs=2e-3)
