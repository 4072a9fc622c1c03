"""One copy of Half Field Offense 1v1 against HFO's goalie (``--defense-npcs 1``), compiled by Numba.

The 1v0 copy of ``dynamics`` (its state rows, physics, referee, features and reward) with a second player: the
defense NPC goalie of LARG/HFO, agent2d's goalie (Akiyama) deciding each cycle (:func:`goalie.decide`) on the
exact state printed to 6 digits (HFO's ``--fullstate``), and the server rules only it triggers (rcssserver's
catch, tackle and three-body collisions, :mod:`two_player`). A cycle in server order:

1. both players decide on the state after the previous cycle;
2. their commands act on arrival: the agent's as in 1v0; the goalie's turn, dash, catch (with its own
   collision pass) or tackle;
3. the goalie's tackle freeze counts down; ball and players move; collisions; the HFO referee, which also
   ends the episode with ``CAPTURED_BY_DEFENSE`` as soon as the goalie's centre is closer than 1.085 m to the
   ball's; stamina; the catch ban counts down.

Around an episode boundary the goalie keeps acting while the agent does not: in the cycle after the end (the
"dead cycle", decided on the terminal state; of it only the body angle, the catch ban, the tackle freeze and
the goalie's memory survive the reset) and in the two cycles between the placement and the agent's first
observation. Its body angle is never reset (180 degrees at a new server run). The goalie's random numbers
(turn noise, tackle outcomes) come from the copy's own stream, after the agent's.

The state row extends the 1v0 one (indices of ``dynamics`` first, then the goalie's below).

Numba's on-disk cache is keyed by each module's own file, and these functions inline ``dynamics``, ``goalie``
and ``two_player``: ``import pamdp.envs`` deletes the envs' caches whenever any of their sources changed
(``envs/_numba_cache.py``), so an edit of those modules alone is compiled in, not replayed from the old cache.
"""

from __future__ import annotations

import math

import numpy as np

import pamdp.envs.hfo.dynamics as dyn
from pamdp.envs.hfo import goalie as gk
from pamdp.envs.hfo import two_player as tp
from pamdp.envs.hfo.dynamics import jit

# --- The goalie's rows in a copy's state, after the 1v0 ones -----------------------------------------
GX, GY, GVX, GVY, GBODY = range(dyn.STATE_SIZE, dyn.STATE_SIZE + 5)
GSTAMINA, GEFFORT, GRECOVERY, GCAPACITY = range(dyn.STATE_SIZE + 5, dyn.STATE_SIZE + 9)
#: Server counters of the goalie (catch ban, tackle freeze); the server clock the goalie's memory reads; the
#: agent touched the goalie this cycle (feature 10).
CATCH_BAN, FREEZE, CLOCK, COLLIDED_PLAYER = range(dyn.STATE_SIZE + 9, dyn.STATE_SIZE + 13)
#: The goalie client's memory (``goalie.M_*`` from here on).
MEMORY = dyn.STATE_SIZE + 13
STATE_SIZE = MEMORY + gk.MEMORY_SIZE
#: The goalie's body at a new server run: the recordings' start-up state (HFO's own is a timing race, 0 or 180).
START_BODY = 180.0
GOALIE_X = dyn.PITCH_HALF_LENGTH
#: Feature indices of the goalie block (after the 58 basic features), its uniform number and the flag.
OPPONENT = 58
UNUM_FEATURE, FLAG_FEATURE = 66, 67
N_FEATURES = 68
GOALIE_SPEED_NORMALISER = 0.75
#: Column of the goalie's body in the reset options (after ball x, y, player x, y, body).
OPTION_GOALIE_BODY = 5


@jit
def new_goalie(s):
    """A new server run: a fresh goalie program facing its own start-up direction, counters expired."""
    s[GBODY] = START_BODY
    s[CATCH_BAN] = s[FREEZE] = s[CLOCK] = 0.0
    fresh_memory(s)


@jit
def fresh_memory(s):
    """The goalie client's memory with nothing in it: no catch for ages, last kicker neutral, no ball record."""
    for k in range(gk.MEMORY_SIZE):
        s[MEMORY + k] = 0.0
    s[MEMORY + gk.M_LAST_CATCH] = -1000.0


@jit
def world(s, cfg, w):
    """The goalie's input ``w`` (``goalie.W_*``): the state as the server prints it to it (6 digits)."""
    fs = dyn.fullstate_value
    w[gk.W_BX], w[gk.W_BY], w[gk.W_BVX], w[gk.W_BVY] = fs(s[dyn.BX]), fs(s[dyn.BY]), fs(s[dyn.BVX]), fs(s[dyn.BVY])
    w[gk.W_AX], w[gk.W_AY], w[gk.W_AVX], w[gk.W_AVY] = fs(s[dyn.PX]), fs(s[dyn.PY]), fs(s[dyn.PVX]), fs(s[dyn.PVY])
    w[gk.W_ABODY] = fs(s[dyn.BODY])
    w[gk.W_GX], w[gk.W_GY], w[gk.W_GVX], w[gk.W_GVY] = fs(s[GX]), fs(s[GY]), fs(s[GVX]), fs(s[GVY])
    w[gk.W_GBODY], w[gk.W_GSTAMINA] = fs(s[GBODY]), fs(s[GSTAMINA])
    w[gk.W_GEFFORT], w[gk.W_GRECOVERY] = fs(s[GEFFORT]), fs(s[GRECOVERY])
    w[gk.W_AGENT_KICKED] = s[dyn.KICKED]
    w[gk.W_AGENT_TACKLING] = 0.0  # the agent has no tackle action
    w[gk.W_GOALIE_FREEZE] = s[FREEZE]
    w[gk.W_CYCLE] = s[CLOCK]
    w[gk.W_PLAYER_RAND], w[gk.W_BALL_RAND] = cfg[dyn._PLAYER_RAND], cfg[dyn._BALL_RAND]


@jit
def collisions(s, pos, vel, hit):
    """rcssserver's collision resolution of ball, agent and goalie (``two_player.collide``), skipped when
    nothing overlaps (almost every cycle). Returns whether the agent touched the ball and the goalie."""
    bx, by, px, py, gx, gy = s[dyn.BX], s[dyn.BY], s[dyn.PX], s[dyn.PY], s[GX], s[GY]
    ball_agent = (bx - px) ** 2 + (by - py) ** 2 < tp.BALL_PLAYER_CONTACT**2
    ball_goalie = (bx - gx) ** 2 + (by - gy) ** 2 < tp.BALL_PLAYER_CONTACT**2
    players = (gx - px) ** 2 + (gy - py) ** 2 < tp.PLAYER_PLAYER_CONTACT**2
    if not (ball_agent or ball_goalie or players):
        return False, False
    for k, o in enumerate((dyn.BX, dyn.PX, GX)):
        pos[k, 0], pos[k, 1], vel[k, 0], vel[k, 1] = s[o], s[o + 1], s[o + 2], s[o + 3]
        hit[k] = False
    tp.collide(pos, vel, hit)
    for k, o in enumerate((dyn.BX, dyn.PX, GX)):
        s[o], s[o + 1], s[o + 2], s[o + 3] = pos[k, 0], pos[k, 1], vel[k, 0], vel[k, 1]
    return ball_agent, players


@jit
def goalie_command(s, rng, cfg, kind, a1, a2, pos, vel, hit):
    """The goalie's command acting on arrival. Returns the accelerations ``(goalie x, y, ball x, y)`` of a dash
    or a tackle for the movement phase. A KICK (a clearance, possible only in the cycle after its own capture,
    whose reset wipes it) is not executed."""
    gax = gay = bax = bay = 0.0
    if kind == gk.TURN:
        rand = cfg[dyn._PLAYER_RAND]
        noise = 1.0 + dyn.uniform(rng, -rand, rand) if rand else 1.0
        moment = dyn.clip(a1, -180.0, 180.0)
        s[GBODY] = dyn.normalize_angle(
            s[GBODY] + noise * moment / (1.0 + dyn.INERTIA_MOMENT * dyn.norm(s[GVX], s[GVY]))
        )
    elif kind == gk.DASH:
        direction = dyn.DASH_ANGLE_STEP * np.rint(dyn.clip(a2, -180.0, 180.0) / dyn.DASH_ANGLE_STEP)
        rate = dyn.dash_direction_rate(direction)
        power = dyn.clip(a1, -100.0, 100.0)
        s[GSTAMINA], gax, gay = dyn.server_dash(s[GSTAMINA], s[GEFFORT], s[GBODY], power, direction, rate)
    elif kind == gk.CATCH:
        ok, ban, x, y, body = tp.catch(s[GX], s[GY], s[GBODY], a1, s[CATCH_BAN], s[dyn.BX], s[dyn.BY])
        s[CATCH_BAN] = ban
        if ok:
            s[GX], s[GY], s[GBODY], s[GVX], s[GVY] = x, y, dyn.normalize_angle(body), 0.0, 0.0
            ball_agent, players = collisions(s, pos, vel, hit)  # at once, before the cycle's movement
            s[dyn.COLLIDED_BALL] = s[dyn.COLLIDED_BALL] or ball_agent
            s[COLLIDED_PLAYER] = s[COLLIDED_PLAYER] or players
    elif kind == gk.TACKLE:
        draws = np.empty(3)
        for k in range(3):
            draws[k] = dyn.next_double(rng)  # random even under --deterministic
        agent_dist = dyn.norm(s[dyn.BX] - s[dyn.PX], s[dyn.BY] - s[dyn.PY])
        ok, freeze, bax, bay = tp.tackle(
            s[GX], s[GY], s[GBODY], a1, a2 != 0.0, s[dyn.BX], s[dyn.BY], s[dyn.BVX], s[dyn.BVY], agent_dist, draws,
            cfg[dyn._KICK_RAND],
        )  # fmt: skip
        s[FREEZE] = freeze
    return gax, gay, bax, bay


@jit
def decide(s, cfg, w):
    """The goalie's decision on the current state (updating its memory in the state row)."""
    world(s, cfg, w)
    return gk.decide(w, s[MEMORY : MEMORY + gk.MEMORY_SIZE])


@jit
def end_of_cycle(s):
    """The goalie's stamina, its catch ban counting down, and the server clock."""
    s[GSTAMINA], s[GEFFORT], s[GRECOVERY], s[GCAPACITY] = dyn.stamina_model(
        s[GSTAMINA], s[GEFFORT], s[GRECOVERY], s[GCAPACITY]
    )
    s[CATCH_BAN] = max(s[CATCH_BAN] - 1.0, 0.0)
    s[CLOCK] += 1.0


@jit
def simulate(s, rng, a, x0, x1, cfg, w, pos, vel, hit):
    """One agent action and one server cycle with the goalie (server order in the module docstring)."""
    kind, a1, a2 = decide(s, cfg, w)  # on the state the agent decided on
    s[dyn.COLLIDED_BALL] = s[COLLIDED_PLAYER] = 0.0
    pax, pay, bax, bay = dyn.agent_command(s, rng, a, x0, x1, cfg)
    gax, gay, tax, tay = goalie_command(s, rng, cfg, kind, a1, a2, pos, vel, hit)
    s[FREEZE] = max(s[FREEZE] - 1.0, 0.0)
    rand = cfg[dyn._PLAYER_RAND]
    s[dyn.COLLIDED_POST] = dyn.move(
        s, rng, dyn.PX, pax, pay, dyn.PLAYER_ACCEL_MAX, dyn.PLAYER_SPEED_MAX, rand, dyn.PLAYER_DECAY, dyn.PLAYER_SIZE
    )
    dyn.move(s, rng, dyn.BX, bax + tax, bay + tay, dyn.BALL_ACCEL_MAX, dyn.BALL_SPEED_MAX, cfg[dyn._BALL_RAND],
             dyn.BALL_DECAY, dyn.BALL_SIZE)  # fmt: skip
    dyn.move(s, rng, GX, gax, gay, dyn.PLAYER_ACCEL_MAX, dyn.PLAYER_SPEED_MAX, rand, dyn.PLAYER_DECAY, dyn.PLAYER_SIZE)
    ball_agent, players = collisions(s, pos, vel, hit)
    s[dyn.COLLIDED_BALL] = s[dyn.COLLIDED_BALL] or ball_agent
    s[COLLIDED_PLAYER] = s[COLLIDED_PLAYER] or players
    status = dyn.referee(s)
    if status == dyn.IN_GAME and dyn.norm(s[dyn.BX] - s[GX], s[dyn.BY] - s[GY]) < dyn.KICKABLE_AREA:
        status = dyn.CAPTURED_BY_DEFENSE  # the goalie's first possession ends the episode at once
    dyn.update_stamina(s)
    end_of_cycle(s)
    dyn.sense(s)
    return status


@jit
def goalie_only_cycle(s, rng, cfg, w, pos, vel, hit, dead):
    """A cycle in which only the goalie acts: the dead cycle after an end (``dead``: the reset that follows
    overwrites all but its body, counters and memory) or one of the two after a placement."""
    kind, a1, a2 = decide(s, cfg, w)
    gax, gay, tax, tay = goalie_command(s, rng, cfg, kind, a1, a2, pos, vel, hit)
    s[FREEZE] = max(s[FREEZE] - 1.0, 0.0)
    if not dead:
        rand = cfg[dyn._PLAYER_RAND]
        dyn.move(s, rng, dyn.BX, tax, tay, dyn.BALL_ACCEL_MAX, dyn.BALL_SPEED_MAX, cfg[dyn._BALL_RAND],
                 dyn.BALL_DECAY, dyn.BALL_SIZE)  # fmt: skip
        dyn.move(s, rng, GX, gax, gay, dyn.PLAYER_ACCEL_MAX, dyn.PLAYER_SPEED_MAX, rand, dyn.PLAYER_DECAY,
                 dyn.PLAYER_SIZE)  # fmt: skip
        collisions(s, pos, vel, hit)
    end_of_cycle(s)


@jit
def features(s, cfg, f, n_features):
    """The 1v0 features of ``dynamics`` with the goalie as the one opponent (HFO's LOW_LEVEL_FEATURE_SET for one
    agent, no teammates, one opponent): its block at 58-65, then (68 features) its uniform number and the
    last-action flag, moved from 58 to 67."""
    dyn.features(s, cfg, f)
    flag = f[dyn.LAST_ACTION_OK_FEATURE]
    fs = dyn.fullstate_value
    px, py = s[dyn.SEEN + dyn.PX], s[dyn.SEEN + dyn.PY]
    gx, gy, gvx, gvy, gbody = fs(s[GX]), fs(s[GY]), fs(s[GVX]), fs(s[GVY]), fs(s[GBODY])
    dx, dy = gx - px, gy - py
    goalie_dist = math.sqrt(dx * dx + dy * dy)
    dyn.bearing(dx, dy, s[dyn.COS_BODY], s[dyn.SIN_BODY], goalie_dist, cfg[dyn._MAX_DIST], f, OPPONENT)
    theta = math.radians(gbody)
    f[OPPONENT + 3], f[OPPONENT + 4] = math.sin(theta), math.cos(theta)
    ux, uy, speed = dyn.direction_of(gvx, gvy)
    f[OPPONENT + 5] = 2.0 * min(speed, GOALIE_SPEED_NORMALISER) / GOALIE_SPEED_NORMALISER - 1.0
    f[OPPONENT + 6], f[OPPONENT + 7] = uy, ux
    f[10] = 1.0 if s[COLLIDED_PLAYER] else -1.0
    if n_features == N_FEATURES:
        f[UNUM_FEATURE], f[FLAG_FEATURE] = 0.01, flag
    # The agent's world model treats a ball the goalie may kick as at rest (librcsc's opponent-control rule).
    bx, by = s[dyn.SEEN + dyn.BX], s[dyn.SEEN + dyn.BY]
    ball_dist = dyn.norm(bx - px, by - py)
    if not s[dyn.KICKABLE_NOW] and s[FREEZE] == 0.0:
        if dyn.norm(gx - bx, gy - by) < gk.opponent_kickable_radius(ball_dist, goalie_dist):
            f[55], f[56], f[57] = -1.0, 0.0, 1.0


@jit
def start_episode(s, rng, cfg, options, f, n_features, w, pos, vel, hit):
    """A new episode: the 1v0 placement of ball and agent (same draws), the goalie on its goal line with its
    body carried over (or ``options[5]``), then the two cycles in which only the goalie acts. Any given option
    starts the goalie's counters and memory expired or neutral, so that a placed episode replays on its own."""
    given = False
    for k in range(options.shape[0]):
        given = given or not math.isnan(options[k])
    if given:
        s[CATCH_BAN] = s[FREEZE] = 0.0
        fresh_memory(s)
    if not math.isnan(options[OPTION_GOALIE_BODY]):
        s[GBODY] = dyn.normalize_angle(options[OPTION_GOALIE_BODY])
    s[MEMORY + gk.M_CATCH_MODE] = 0.0  # the reset's play_on ends goalie-catch mode
    s[GX], s[GY], s[GVX], s[GVY] = GOALIE_X, 0.0, 0.0, 0.0
    s[GSTAMINA], s[GEFFORT], s[GRECOVERY], s[GCAPACITY] = dyn.STAMINA_MAX, 1.0, 1.0, dyn.STAMINA_CAPACITY
    dyn.start_episode(s, rng, cfg, options, f)
    for _ in range(dyn.COUNTERS_AT_FIRST_OBSERVATION):
        goalie_only_cycle(s, rng, cfg, w, pos, vel, hit, False)
    s[COLLIDED_PLAYER] = 0.0
    dyn.sense(s)
    features(s, cfg, f, n_features)


@jit
def step_copy(s, rng, a, x0, x1, cfg, f, n_features, w, pos, vel, hit):
    """One step of one copy: the cycle, the features, the 1v0 reward; after an end, the dead cycle."""
    status = simulate(s, rng, a, x0, x1, cfg, w, pos, vel, hit)
    s[dyn.STEPS] += 1
    features(s, cfg, f, n_features)
    reward = dyn.shaped_reward(s, cfg, f, status)
    if status != dyn.IN_GAME:
        goalie_only_cycle(s, rng, cfg, w, pos, vel, hit, True)
    return reward, status


@jit
def step_batch(states, rngs, a, dash_params, turn_params, kick_params, resetting, cfg, obs, reward, status,
               terminated, truncated):  # fmt: skip
    """``dynamics.step_batch`` with the goalie: every copy on its own row and stream, next-step autoreset."""
    f, w = np.empty(N_FEATURES), np.empty(gk.WORLD_SIZE)
    pos, vel, hit = np.empty((3, 2)), np.empty((3, 2)), np.empty(3, dtype=np.bool_)
    no_options = np.full(OPTION_GOALIE_BODY + 1, np.nan)
    n_features = obs.shape[1]
    for i in range(states.shape[0]):
        s, r = states[i], rngs[i]
        if resetting[i]:
            start_episode(s, r, cfg, no_options, f, n_features, w, pos, vel, hit)
            reward[i], status[i], terminated[i], truncated[i] = 0.0, dyn.IN_GAME, False, False
        else:
            action = a[i]
            if action == dyn.DASH:
                x0, x1 = dash_params[i, 0], dash_params[i, 1]
            elif action == dyn.TURN:
                x0 = x1 = turn_params[i, 0]
            else:
                x0, x1 = kick_params[i, 0], kick_params[i, 1]
            reward[i], status[i] = step_copy(s, r, action, x0, x1, cfg, f, n_features, w, pos, vel, hit)
            terminated[i], truncated[i] = dyn.ending(status[i], cfg)
        for k in range(n_features):
            obs[i, k] = f[k]


@jit
def reset_batch(states, rngs, mask, cfg, options, obs):
    """``dynamics.reset_batch`` with the goalie (``options`` rows: ball x, y, player x, y, body, goalie body)."""
    f, w = np.empty(N_FEATURES), np.empty(gk.WORLD_SIZE)
    pos, vel, hit = np.empty((3, 2)), np.empty((3, 2)), np.empty(3, dtype=np.bool_)
    n_features = obs.shape[1]
    for i in range(states.shape[0]):
        if mask[i]:
            start_episode(states[i], rngs[i], cfg, options[i], f, n_features, w, pos, vel, hit)
        else:
            features(states[i], cfg, f, n_features)
        for k in range(n_features):
            obs[i, k] = f[k]
