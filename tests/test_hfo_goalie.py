"""HFO's goalie (``pamdp.envs.hfo.goalie``): hand-worked examples and a command replay of the real server.

The examples are those worked by hand in section 5 of the goalie specification (positions in the goalie's
frame G there; :func:`world` converts to the server frame the decision takes). The replay feeds every
recorded cycle of the seed-42 recording into the decision and compares with the command the real goalie
sent (``tests/hfo_goalie_replay.py``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hfo_goalie_replay import load, rates, recorded_command, replay

import pamdp.envs.hfo.goalie as gl
import pamdp.envs.hfo.two_player as tp


def world(ball=(-40.0, 0.0), u=(0.0, 0.0), agent=(-20.0, 0.0), agent_body=180.0, agent_v=(0.0, 0.0),
          goalie=(-50.0, 0.0), theta=0.0, v=(0.0, 0.0), stamina=8000.0, cycle=100):  # fmt: skip
    """A ``world`` vector from goalie-frame (G) quantities: positions and velocities negated, angles + 180."""
    return gl.world_from_fields(
        ball=(-ball[0], -ball[1], -u[0], -u[1]),
        agent=(-agent[0], -agent[1], -agent_v[0], -agent_v[1]),
        agent_body=agent_body + 180.0,
        goalie=(-goalie[0], -goalie[1], -v[0], -v[1]),
        goalie_body=theta + 180.0,
        stamina=stamina,
        effort=1.0,
        recovery=1.0,
        cycle=cycle,
    )


def model(w, memory=None):
    """The goalie's per-cycle world model with both reach cycles filled in, and its interception list."""
    memory = gl.new_memory() if memory is None else memory
    g = gl._world_model(w, memory)
    gl._update_last_kicker(g, w, memory)
    cache = np.empty((gl.MAX_CACHE, 2))
    length = gl.ball_cache(g, cache)
    g[gl.G_N_OPP] = gl.opponent_reach(g, cache, length)
    infos = np.empty((gl.MAX_INFOS, gl.INFO_SIZE))
    count = gl.self_intercept(g, min(30, length), infos)
    g[gl.G_N_SELF] = infos[0, gl.I_TURNS] + infos[0, gl.I_DASHES]
    return g, infos[:count]


# --- 5.1 Tables ---------------------------------------------------------------------------------------
def test_dash_distance_table():
    expected = [0.6, 1.44, 2.376, 3.3504, 4.3402, 5.3361, 6.3344, 7.3338, 8.3335, 9.3334]
    np.testing.assert_allclose(gl.DASH_DISTANCE[1:11], expected, atol=1e-4)


@pytest.mark.parametrize(
    "d, n", [(0.5, 1), (0.601, 1), (1.44, 2), (2.0, 3), (7.415, 9), (8.85, 10), (20.0, 21), (60.0, 61)]
)
def test_dash_cycles(d, n):
    assert gl.dash_cycles(d) == n


@pytest.mark.parametrize("x, p", [(1.1, 0.9723), (1.3, 0.9246), (1.5, 0.8220), (1.53, 0.7996)])
def test_tackle_probability_straight_ahead(x, p):
    g = gl._world_model(world(ball=(-50.0 + x, 0.0)), gl.new_memory())
    assert gl.tackle_probability(g, gl.TACKLE_EXPONENT) == pytest.approx(p, abs=1e-4)


def test_tackle_thresholds():
    """Probability 0.8 at x = 2 * 0.2**(1/6) for a tackle, at 1.7027 for a foul."""
    g = gl._world_model(world(ball=(-50.0 + 2.0 * 0.2 ** (1 / 6), 0.0)), gl.new_memory())
    assert gl.tackle_probability(g, gl.TACKLE_EXPONENT) == pytest.approx(0.8)
    g = gl._world_model(world(ball=(-50.0 + 1.7027, 0.0)), gl.new_memory())
    assert gl.tackle_probability(g, gl.FOUL_EXPONENT) == pytest.approx(0.8, abs=1e-4)


@pytest.mark.parametrize("db, dq, r", [(5.0, 5.0, 1.285), (8.0, 9.0, 1.425), (12.5, 13.0, 1.585)])
def test_opponent_kickable_radius(db, dq, r):
    assert gl.opponent_kickable_radius(db, dq) == pytest.approx(r)


# --- 5.2 Target points --------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "ball, u, agent, target",
    [
        ((-5.0, 20.0), (0.0, 0.0), (0.0, 0.0), (-49.8, 3.5596)),
        ((-45.0, 20.0), (0.0, 0.0), (0.0, 0.0), (-51.5, 7.011)),
        ((-45.0, -10.5), (0.0, 0.0), (0.0, 0.0), (-49.8, -6.91)),
        ((-48.0, 9.5), (0.0, 0.0), (0.0, 0.0), (-49.8, 6.91)),
        ((-20.0, 0.0), (0.0, 0.0), (-19.5, 0.0), (-49.8, 0.0)),  # the agent has the ball
    ],
)
def test_target_point(ball, u, agent, target):
    g, _ = model(world(ball=ball, u=u, agent=agent))
    np.testing.assert_allclose(gl.target_point(g), target, atol=1e-4)


@pytest.mark.parametrize("n_opp, target_y", [(3, -1.5249), (12, -1.0442)])
def test_target_point_moving_ball(n_opp, target_y):
    """The ball is extrapolated to the agent's reach cycle, then again by up to 5 cycles of its current velocity."""
    g, _ = model(world(ball=(-30.0, -5.0), u=(-1.5, 0.3)))
    g[gl.G_N_OPP] = n_opp
    np.testing.assert_allclose(gl.target_point(g), (-49.8, target_y), atol=1e-4)


# --- 5.3 Catch ----------------------------------------------------------------------------------------
def test_catch():
    w = world(ball=(-49.0, 0.7), goalie=(-50.0, 0.0))
    memory = gl.new_memory()
    kind, direction, _ = gl.decide(w, memory)
    assert kind == gl.CATCH
    assert direction == pytest.approx(57.6119, abs=1e-4)
    assert memory[gl.M_LAST_CATCH] == w[gl.W_CYCLE] + 1
    assert memory[gl.M_CATCH_MODE] == 1.0


def test_no_catch_from_1_28_m():
    """A ball 1.2807 m away is not tried (the goalie keeps 0.05 inside the 1.3 m the server would accept)."""
    assert gl.decide(world(ball=(-49.0, 0.8), goalie=(-50.0, 0.0)), gl.new_memory())[0] != gl.CATCH


def test_catch_waits_after_a_catch():
    """After a catch decided at t, the next one is possible at t + 7 (the client stamps it at t + 1)."""
    memory = gl.new_memory()
    assert gl.decide(world(ball=(-49.0, 0.7), cycle=100), memory)[0] == gl.CATCH
    gl.start_episode(memory)
    assert gl.decide(world(ball=(-49.0, 0.7), cycle=106), memory)[0] != gl.CATCH
    assert gl.decide(world(ball=(-49.0, 0.7), cycle=107), memory)[0] == gl.CATCH


# --- 5.4 First commands after a reset -------------------------------------------------------------------
def test_first_commands_after_reset():
    w = world(ball=(-5.0, 20.0), agent=(0.0, 0.0), goalie=(-52.5, 0.0), theta=0.0)
    assert gl.decide(w, gl.new_memory()) == (gl.TURN, 52.819, 0.0)
    w = world(ball=(-5.0, 20.0), agent=(0.0, 0.0), goalie=(-52.5, 0.0), theta=52.819)
    assert gl.decide(w, gl.new_memory()) == (gl.DASH, 45.0, 0.0)
    w = world(
        ball=(-5.0, 20.0), agent=(0.0, 0.0), goalie=(-52.33683, 0.21512), v=(0.065268, 0.086047), theta=52.819,
        stamina=8000.0 - 45.0 + 45.0,
    )  # fmt: skip
    assert gl.decide(w, gl.new_memory()) == (gl.DASH, 45.0, 0.0)


def test_first_commands_recorded():
    """The recording's own counterpart: goalie at S(52.5, 0) with body 180, ball S(3.9327, 16.1319) at rest."""
    w = world(ball=(-3.9327, -16.1319), agent=(10.0, 20.0), goalie=(-52.5, 0.0), theta=0.0)
    assert gl.decide(w, gl.new_memory()) == (gl.TURN, -46.205, 0.0)


# --- 5.5 Opponent reach -----------------------------------------------------------------------------------
@pytest.mark.parametrize("ball, agent, n_opp", [((-10.0, 0.0), (0.0, 0.0), 9), ((-40.0, 0.0), (-20.0, 0.0), 19)])
def test_opponent_reach_resting_ball(ball, agent, n_opp):
    g, _ = model(world(ball=ball, agent=agent, agent_body=180.0, goalie=(-50.0, 0.0)))
    assert g[gl.G_N_OPP] == n_opp


# --- 5.6 Self reach, chase and intercept ----------------------------------------------------------------
def test_self_reach_and_intercept_resting_ball():
    w = world(ball=(-40.0, 0.0), agent=(-20.0, 0.0), goalie=(-50.0, 0.0))
    g, infos = model(w)
    assert len(infos) == 1
    assert tuple(infos[0, [gl.I_EXHAUST, gl.I_TURNS, gl.I_DASHES, gl.I_POWER]]) == (0.0, 0.0, 10.0, 100.0)
    assert g[gl.G_N_SELF] == 10 and g[gl.G_N_OPP] == 19
    assert gl._is_chase_situation(g)
    assert gl.decide(w, gl.new_memory()) == (gl.DASH, 100.0, 0.0)


# --- 5.7 Stop dash ----------------------------------------------------------------------------------------
def test_stop_dash():
    g = gl._world_model(world(v=(0.4, 0.0)), gl.new_memory())
    issued, kind, power, direction = gl._stop_dash(g, True)
    assert issued and kind == gl.DASH and direction == 0.0
    assert power == pytest.approx(-66.667, abs=1e-3)


# --- 5.8 Go to catch point -------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "point, theta, kind, arg",
    [
        ((-47.0, 3.0), 35.0, gl.DASH, 100.0),
        ((-53.0, 0.5), 0.0, gl.DASH, -100.0),
        ((-48.0, -3.0), 10.0, gl.TURN, -66.31),
    ],
)
def test_go_to_catch_point(point, theta, kind, arg):
    g = gl._world_model(world(goalie=(-50.0, 0.0), theta=theta), gl.new_memory())
    issued, k, a1, _ = gl._go_to_catch_point(g, *point)
    assert issued and k == kind
    assert a1 == pytest.approx(arg, abs=5e-3)


# --- 5.9 Basic dash power ---------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "ball, stamina, n_opp, goalie_y, power",
    [
        ((-20.0, 0.0), 8000.0, 10, 0.0, 45.0),
        ((-20.0, 0.0), 7000.0, 10, 0.0, 22.5),
        ((-33.0, 5.0), 8000.0, 2, 0.0, 100.0),
        ((-33.0, 5.0), 8000.0, 8, 0.0, 60.0),
        ((-33.0, 21.0), 8000.0, 8, 0.0, 45.0),
        ((-40.0, 16.0), 8000.0, 8, 3.0, 45.0),
        ((-40.0, 16.0), 8000.0, 8, -2.0, 100.0),
        ((-40.0, 10.0), 8000.0, 8, 0.0, 100.0),
    ],
)
def test_basic_dash_power(ball, stamina, n_opp, goalie_y, power):
    g = gl._world_model(world(ball=ball, goalie=(-50.0, goalie_y), stamina=stamina), gl.new_memory())
    g[gl.G_N_OPP] = n_opp
    assert gl.basic_dash_power(g, -49.8) == pytest.approx(power)
    assert gl.basic_dash_power(g, -45.0) == 100.0  # more than 3 m off the target's x


# --- Memory ----------------------------------------------------------------------------------------------
def test_last_kicker_follows_the_agents_kick():
    """A ball whose velocity jumps within 6 m of an agent that just kicked was kicked by the agent (while the
    agent may still kick it, the goalie treats the ball as at rest and sees no jump: hence 2.5 m here)."""
    memory = gl.new_memory()
    gl.decide(world(ball=(-20.0, 0.0), agent=(-19.5, 0.5)), memory)
    assert memory[gl.M_LAST_KICKER] == gl.NEUTRAL
    w = world(ball=(-21.0, 0.0), u=(-2.0, 0.0), agent=(-18.5, 0.5))
    w[gl.W_AGENT_KICKED] = 1.0
    gl.decide(w, memory)
    assert memory[gl.M_LAST_KICKER] == gl.AGENT_SIDE


def test_frozen_goalie_sends_nothing():
    w = world()
    w[gl.W_GOALIE_FREEZE] = 3.0
    assert gl.decide(w, gl.new_memory())[0] == gl.NONE


# --- Branches the recording does not reach ------------------------------------------------------------------
def test_tackle_on_a_kickable_agent_outside_the_box():
    """Outside its box the goalie cannot catch; with the ball 1.3 m ahead and the agent on it, it tackles, in a
    direction on the 9-degree grid that sends the ball away from its goal. Outside the box the foul variant
    (success 1 - 0.65**10 = 0.987 against 0.925) is chosen, as the agent may kick the ball."""
    w = world(ball=(-28.7, 0.0), agent=(-28.0, 0.6), goalie=(-30.0, 0.0), theta=0.0)
    kind, direction, foul = gl.decide(w, gl.new_memory())
    assert kind == gl.TACKLE and foul == 1.0
    assert direction % 9.0 == 0.0
    power = 100.0 * (1.0 - abs(direction) / 180.0) * gl.KICK_POWER_RATE
    assert math.cos(math.radians(direction)) * power > 0.0


def test_no_tackle_when_the_agent_is_far():
    """The same ball without the agent near it: no need to tackle (the goalie goes for it instead)."""
    w = world(ball=(-28.7, 0.0), agent=(-10.0, 0.0), goalie=(-30.0, 0.0), theta=0.0)
    assert gl.decide(w, gl.new_memory())[0] != gl.TACKLE


def test_random_states_give_legal_commands():
    """Random states over the goalie's half (moving ball, moving goalie, low stamina, either last kicker, either
    play mode, noise factors on or off): every command is legal, as the server would receive it, and the
    interceptions are sorted."""
    rng = np.random.default_rng(0)
    kinds = set()
    for _ in range(3000):
        speed, heading = rng.uniform(0, 3.0), rng.uniform(-180, 180)
        u = (speed * math.cos(math.radians(heading)), speed * math.sin(math.radians(heading)))
        gs, gh = rng.uniform(0, 0.4), rng.uniform(-180, 180)
        v = (gs * math.cos(math.radians(gh)), gs * math.sin(math.radians(gh)))
        goalie = (rng.uniform(-52.5, -30.0), rng.uniform(-20.0, 20.0))
        near = rng.random() < 0.5
        ball = (goalie[0] + rng.uniform(-3, 5), goalie[1] + rng.uniform(-4, 4)) if near else (
            rng.uniform(-52.0, 0.0), rng.uniform(-34.0, 34.0))  # fmt: skip
        agent = (ball[0] + rng.uniform(-3, 3), ball[1] + rng.uniform(-3, 3))
        w = world(ball=ball, u=u, agent=agent, agent_body=rng.uniform(-180, 180), goalie=goalie,
                  theta=rng.uniform(-180, 180), v=v, stamina=rng.uniform(1000.0, 8000.0))  # fmt: skip
        if rng.random() < 0.5:  # the noise factors of a run without --deterministic
            w[gl.W_PLAYER_RAND], w[gl.W_BALL_RAND] = 0.1, 0.05
        memory = gl.new_memory()
        memory[gl.M_LAST_KICKER] = rng.choice([gl.NEUTRAL, gl.GOALIE_SIDE, gl.AGENT_SIDE])
        memory[gl.M_CATCH_MODE] = rng.random() < 0.2
        _, infos = model(w, memory.copy())
        reach = infos[:, gl.I_TURNS] + infos[:, gl.I_DASHES]
        assert len(infos) > 0 and np.all(np.diff(reach) >= 0)
        kind, a1, a2 = gl.decide(w, memory)
        kinds.add(kind)
        if kind == gl.KICK:
            continue
        assert math.isfinite(a1) and math.isfinite(a2)
        if kind == gl.TURN:
            assert abs(a1) <= 180.0 and a1 == round(a1, 3)
        elif kind == gl.DASH:
            assert abs(a1) <= 100.0 and a2 % 45.0 == 0.0 and a1 == round(a1, 3)
        elif kind in (gl.CATCH, gl.TACKLE):
            assert -180.0 <= a1 <= 180.0
    assert {gl.TURN, gl.DASH, gl.CATCH, gl.TACKLE} <= kinds


def test_side_step_near_the_target():
    """Go to point with the target 0.8 m to the goalie's right (body along +y, at rest): within threshold + 1 it
    side-steps. Worked by hand: dashing at -90 (rate 0.0024) with powers 100, 100, 56 ends 0.045 m from the
    target in 3 steps; at -45 it drifts sideways and ends farther; so ``(dash 100 -90)``."""
    g = gl._world_model(world(goalie=(-50.0, 0.0), theta=90.0), gl.new_memory())
    assert gl._go_to_point(g, -49.2, 0.0, 0.5, 100.0, -1.0, 100, True, 15.0) == (True, gl.DASH, 100.0, -90.0)


def test_target_behind_a_post_is_moved_beside_it():
    """From (-52, 6.5), body +90, a target behind the post (-52.44, 7.07) is replaced by the point 0.66 m from the
    post at right angles to the post's direction beta = 127.73 degrees, on the side away from the body:
    post + polar(0.66, beta - 90)."""
    g = gl._world_model(world(goalie=(-52.0, 6.5), theta=90.0), gl.new_memory())
    beta = math.degrees(math.atan2(7.07 - 6.5, -52.44 + 52.0))
    expected = (-52.44 + 0.66 * math.cos(math.radians(beta - 90)), 7.07 + 0.66 * math.sin(math.radians(beta - 90)))
    assert gl._avoid_post(g, -53.0, 7.6) == pytest.approx(expected)


# --- The server's catch (two_player) --------------------------------------------------------------------
def test_server_catch_worked_example():
    """5.3 on the server, in its frame: goalie S(50, 0) body 180, ball S(49, -0.7) at rest, ``(catch 57.6119)``:
    the goalie jumps to S(49.31540, -0.47922) facing the ball; the double-precision squared distance lands
    below 0.385**2, so the collision pass that follows pushes the pair apart."""
    ok, ban, gx, gy, body = tp.catch(50.0, 0.0, 180.0, 57.6119, 0, 49.0, -0.7)
    assert ok and ban == tp.CATCH_BAN_CYCLE
    assert (gx, gy) == pytest.approx((49.31540, -0.47922), abs=1e-5)
    assert body == pytest.approx(-145.008, abs=5e-4)
    assert (49.0 - gx) ** 2 + (-0.7 - gy) ** 2 < tp.BALL_PLAYER_CONTACT**2
    pos, vel, collided = np.array([[49.0, -0.7], [gx, gy]]), np.zeros((2, 2)), np.zeros(2, dtype=bool)
    tp.collide(pos, vel, collided)
    assert collided.all() and np.linalg.norm(pos[0] - pos[1]) > tp.BALL_PLAYER_CONTACT


def test_server_catch_rectangle_and_ban():
    """Inside the 1.2 x 1.0 rectangle (inclusive) the catch works unless banned; outside it fails but still bans."""
    assert tp.catchable(0.0, 0.0, 0.0, 0.0, 1.2, 0.5) and not tp.catchable(0.0, 0.0, 0.0, 0.0, 1.21, 0.0)
    assert not tp.catchable(0.0, 0.0, 0.0, 0.0, -0.01, 0.0)
    assert tp.catch(0.0, 0.0, 0.0, 0.0, 3, 1.0, 0.0)[:2] == (False, 3)
    assert tp.catch(0.0, 0.0, 0.0, 0.0, 0, 1.3, 0.0)[:2] == (False, tp.CATCH_BAN_CYCLE)


def test_server_catch_recorded():
    """Every recorded catch: the goalie's body after it faces the ball (to the 1e-3 degree logging, plus the
    rounding of the logged positions), and after a catch in live play the goalie stands where the jump put it,
    except once, where the ball's own movement then pushed it off by 0.18 m (an ordinary collision)."""
    trace = load()
    fields, resets = trace["rcg_states_fields"], set(trace["reset_cycles"])
    jumps = []
    for c in sorted(int(k) for k in trace["rcl_commands"]):
        cmd = recorded_command(trace["rcl_commands"][str(c)][1])
        if cmd is None or cmd[0] != gl.CATCH:
            continue
        now = dict(zip(fields, trace["rcg_states"][str(c)]))
        after = dict(zip(fields, trace["rcg_states"][str(c + 1)]))
        result = tp.catch(
            now["goalie_x"], now["goalie_y"], now["goalie_body_deg"], cmd[1], 0, now["ball_x"], now["ball_y"]
        )
        assert result[0]
        assert abs(gl.nrm(result[4] - after["goalie_body_deg"])) < 0.011
        if c + 1 not in resets:
            jumps.append(math.hypot(result[2] - after["goalie_x"], result[3] - after["goalie_y"]))
    assert len(jumps) == 6 and sum(j < 2e-4 for j in jumps) == 5


def test_server_tackle():
    """Ball 1.3 m straight ahead (fail 0.65**6 = 0.0754): a draw below 0.9246 succeeds with the full tackle power
    100 * 0.027 = 2.7 along the body; a draw above fails; a ball behind always fails; every tackle freezes the
    goalie for 10 cycles except a successful foul while the agent is on the ball (exponent 10: fail 0.0135)."""
    ok, freeze, ax, ay = tp.tackle(0.0, 0.0, 90.0, 0.0, False, 0.0, 1.3, 0.0, 0.0, 5.0, np.array([0.9, 0, 0]), 0.0)
    assert ok and freeze == tp.TACKLE_CYCLES and (ax, ay) == pytest.approx((0.0, 2.7))
    assert not tp.tackle(0.0, 0.0, 90.0, 0.0, False, 0.0, 1.3, 0.0, 0.0, 5.0, np.array([0.93, 0, 0]), 0.0)[0]
    assert not tp.tackle(0.0, 0.0, 90.0, 0.0, False, 0.0, -0.5, 0.0, 0.0, 5.0, np.array([0.0, 0, 0]), 0.0)[0]
    ok, freeze, ax, ay = tp.tackle(0.0, 0.0, 90.0, 90.0, True, 0.0, 1.3, 0.0, 0.0, 1.0, np.array([0.98, 0, 0]), 0.0)
    assert ok and freeze == 0 and (ax, ay) == pytest.approx((-1.35, 0.0))


def test_collision_after_a_recorded_catch():
    """Cycle 415 of the recording: the goalie catches, the jump does not overlap the ball, the ball then moves by
    its velocity into the goalie and the collision pushes the two apart to 0.385 m, the goalie off its landing
    point by 0.18 m, the ball's velocity turned to -0.1 of its decayed value: as logged at cycle 416."""
    trace = load()
    now, after = (dict(zip(trace["rcg_states_fields"], trace["rcg_states"][str(c)])) for c in (415, 416))
    direction = recorded_command(trace["rcl_commands"]["415"][1])[1]
    ok, _, gx, gy, _ = tp.catch(
        now["goalie_x"], now["goalie_y"], now["goalie_body_deg"], direction, 0, now["ball_x"], now["ball_y"]
    )
    assert ok
    pos = np.array([
        [now["ball_x"] + now["ball_vx"], now["ball_y"] + now["ball_vy"]],
        [now["self_x"], now["self_y"]],  # the agent, 20 m away
        [gx, gy],
    ])  # fmt: skip
    vel = np.array([[now["ball_vx"] * 0.94, now["ball_vy"] * 0.94], [0.0, 0.0], [0.0, 0.0]])
    collided = np.zeros(3, dtype=bool)
    tp.collide(pos, vel, collided)
    assert collided.tolist() == [True, False, True]
    np.testing.assert_allclose(pos[0], (after["ball_x"], after["ball_y"]), atol=5e-4)
    np.testing.assert_allclose(pos[2], (after["goalie_x"], after["goalie_y"]), atol=5e-4)
    np.testing.assert_allclose(vel[0], (after["ball_vx"], after["ball_vy"]), atol=1e-4)


def test_collisions_between_three_bodies():
    """Agent and goalie overlapping each other and the ball between them: each pass averages what the pairs ask
    for, so the overlaps shrink pass by pass; after the server's 10 passes less than a millimetre is left, and
    all three, having collided, move at -0.1 of their velocity."""
    pos = np.array([[0.0, 0.0], [-0.2, 0.0], [0.25, 0.05]])
    vel = np.ones((3, 2))
    collided = np.zeros(3, dtype=bool)
    tp.collide(pos, vel, collided)
    assert collided.all() and np.allclose(vel, -0.1)
    assert np.linalg.norm(pos[1] - pos[2]) > tp.PLAYER_PLAYER_CONTACT - 1e-3
    for i in (1, 2):
        assert np.linalg.norm(pos[0] - pos[i]) > tp.BALL_PLAYER_CONTACT - 1e-3


# --- Replay of the real server ----------------------------------------------------------------------------
#: Matching recorded commands (kind equal, arguments within the recording's rounding), overall and per kind;
#: floors at the rates reached, so that a change cannot lower them unnoticed.
REPLAY_FLOOR = {"all": 2054, "turn": 1602, "turn 0": 1492, "dash": 434, "catch": 18}


def test_command_replay():
    result = rates(replay(load()))
    for name, floor in REPLAY_FLOOR.items():
        assert result[name][0] >= floor, (name, result[name])
