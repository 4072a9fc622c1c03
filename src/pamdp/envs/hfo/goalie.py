"""HFO's defense NPC goalie (agent2d's goalie, ``--defense-npcs 1``): its decision each cycle, compiled by Numba.

Half Field Offense (Hausknecht et al. 2016, the LARG/HFO repository) plays its single defense NPC with the
goalie of Akiyama's agent2d on top of librcsc. Under ``--fullstate`` that goalie decides on the exact server
state, so its decision is a deterministic function of the cycle's state and of a little memory kept across
cycles. :func:`decide` is that function, written from a description of the behaviour (not from agent2d's
GPL code): given the state of one cycle as the server reports it, it returns the body command the goalie
sends (encoded as the server receives it) and updates the memory in place.

Frames. Inputs are in the server's frame (the agent attacks x = +52.5, the goalie defends it). The goalie's
client sees everything rotated by 180 degrees (positions and velocities negated, 180 added to angles), so
inside this module every rule works in that goalie frame: its own goal centre is G0 = (-52.5, 0) and the
agent attacks towards -x. Command arguments (turn moment, dash power and direction, catch direction) are
relative to the goalie's body, hence the same in both frames.

The decision, top to bottom (the names of the functions below):

* world model (:func:`_world_model`): kickability of both players, the opponent-control rule (a ball the
  agent may kick is treated as at rest), the last kicker (:func:`_update_last_kicker`);
* intercept table: when the agent reaches the ball (:func:`opponent_reach`) and when the goalie does
  (:func:`self_intercept`, a list of candidate interceptions);
* the goalie role: catch (:func:`catch_direction`); otherwise chase (:func:`_is_chase_situation`,
  :func:`_chase`, :func:`_intercept`) or the basic positioning move (:func:`_basic_move`, its target
  :func:`target_point`);
* movement primitives (:func:`_go_to_point`, :func:`_stop_dash`, :func:`_look_ball_go_to_point`, ...);
* command encoding (:func:`_encode`): what librcsc's action effector does to a turn or dash before sending.

Layouts. ``world`` (float64, :data:`WORLD_SIZE`): the cycle's state in the server frame, indices ``W_*``.
``memory`` (float64, :data:`MEMORY_SIZE`): what the goalie carries from one cycle to the next, indices
``M_*`` (:func:`new_memory` makes a fresh one, :func:`start_episode` applies what an HFO reset changes).
The result is ``(kind, arg1, arg2)`` with ``kind`` one of ``NONE, TURN, DASH, CATCH, TACKLE, KICK``:
turn (moment), dash (power, direction), catch (direction), tackle (direction, foul flag).

The goalie's client receives the server's noise factors and widens some of its own buffers with them, so
it decides slightly differently with and without ``--deterministic``: ``world`` carries them
(``W_PLAYER_RAND``, ``W_BALL_RAND``). The recording this module is checked against has them at 0.

Using it. The full state reaches the goalie printed to 6 significant digits, so an environment passes the
server's values so rounded (``dynamics.fullstate_value``); it calls :func:`start_episode` when the referee
resets the field and :func:`decide` once per cycle, also in the terminal cycle and in the two cycles after a
reset in which only the goalie acts. A ``KICK`` (a clearance) can only come on the cycle after the goalie's
own capture, whose reset wipes its effect; its arguments are not modelled (NaN) and it is best not executed.

Fidelity (``tests/test_hfo_goalie.py``): every goalie command of the seed-42 recording of the real server
(2054 cycles: positioning, chases, catches, the cycles around resets) is reproduced within the recording's
rounding. Branches the recording never reaches (tackles, stop dashes, side steps, post avoidance, the later
steps of the chase) are checked only against examples worked by hand.
"""

from __future__ import annotations

import math

import numpy as np

from pamdp.envs.hfo.dynamics import jit

# --- Inputs: one cycle's state in the server frame ------------------------------------------------
W_BX, W_BY, W_BVX, W_BVY = range(4)
#: The agent (the goalie's opponent): position, velocity, body angle.
W_AX, W_AY, W_AVX, W_AVY, W_ABODY = range(4, 9)
#: The goalie: position, velocity, body angle, stamina, effort, recovery.
W_GX, W_GY, W_GVX, W_GVY, W_GBODY, W_GSTAMINA, W_GEFFORT, W_GRECOVERY = range(9, 17)
#: The agent's fullstate flags: ``k`` (it sent a kick in the previous cycle), ``t`` (it is tackling); the
#: goalie's own tackle freeze (cycles left); the server cycle.
W_AGENT_KICKED, W_AGENT_TACKLING, W_GOALIE_FREEZE, W_CYCLE = range(17, 21)
#: The server's player and ball noise factors, which the goalie's client also uses in its own predictions
#: (0 under ``--deterministic``; 0.1 and 0.05 otherwise).
W_PLAYER_RAND, W_BALL_RAND = range(21, 23)
WORLD_SIZE = 23

# --- Memory carried across cycles (and across episodes) -------------------------------------------
#: The cycle after the last catch decision (the client stamps the catch with its next sensory update).
M_LAST_CATCH = 0
#: Last kicker side: NEUTRAL, GOALIE_SIDE or AGENT_SIDE.
M_LAST_KICKER = 1
#: The ball (goalie frame, after the opponent-control rule) at the previous decision, and whether it exists.
M_PREV_BX, M_PREV_BY, M_PREV_UX, M_PREV_UY, M_PREV_VALID = range(2, 7)
#: The goalie's previous body command was a kick or a tackle.
M_PREV_KICKED = 7
#: The goalie believes the play mode is "goalie catch" (after its own catch, until the next reset).
M_CATCH_MODE = 8
#: The agent showed the tackle flag in the previous cycle (a new tackle counts as a kick).
M_AGENT_WAS_TACKLING = 9
MEMORY_SIZE = 10
NEUTRAL, GOALIE_SIDE, AGENT_SIDE = 0.0, 1.0, 2.0

# --- Result kinds ---------------------------------------------------------------------------------
NONE, TURN, DASH, CATCH, TACKLE, KICK = range(6)
KIND_NAMES = ("none", "turn", "dash", "catch", "tackle", "kick")

# --- Field and server constants (goalie frame) ------------------------------------------------------
GOAL_X = -52.5
GOAL_HALF_WIDTH = 7.01
PENALTY_X = -36.0
PENALTY_HALF_WIDTH = 20.16
PITCH_HALF_WIDTH = 34.0
KICKABLE_AREA = 1.085
#: The goalie's own kickable test keeps librcsc's 0.055 buffer for a ball seen this cycle.
SELF_KICKABLE = KICKABLE_AREA - 0.055
#: Diagonal of the 1.2 x 1.0 catch rectangle: the goalie's control radius where it may catch.
CATCHABLE_AREA = math.sqrt(1.2 * 1.2 + 0.5 * 0.5)
#: The goalie tries a catch only below this distance (a 0.05 margin inside the catchable area).
CATCH_DISTANCE = CATCHABLE_AREA - 0.05
#: Aim so that the ball lies on the diagonal of the catch rectangle: atan2(0.5, 1.2).
CATCH_AIM = math.degrees(math.atan2(0.5, 1.2))
CATCH_WAIT = 5
PLAYER_DECAY = 0.4
BALL_DECAY = 0.94
DASH_POWER_RATE = 0.006
PLAYER_SPEED_MAX = 1.05
INERTIA_MOMENT = 5.0
STAMINA_MAX = 8000.0
RECOVER_DEC_THR = 0.3 * STAMINA_MAX
EFFORT_INC_THR = 0.6 * STAMINA_MAX
STAMINA_INC_MAX = 45.0
EXTRA_STAMINA = 50.0
#: librcsc's "safe" stamina floor: one above the recovery-decay threshold.
SAFE_STAMINA = RECOVER_DEC_THR + 1.0
TACKLE_DIST, TACKLE_WIDTH, TACKLE_EXPONENT, FOUL_EXPONENT = 2.0, 1.25, 6.0, 10.0
KICK_POWER_RATE = 0.027
BALL_SPEED_MAX = 3.0
#: Ball prediction horizon of the intercept table.
MAX_CACHE = 31
MAX_INFOS = 64
#: The table's last two rows are the stages' scratch (the best candidate so far and the one being built), so that
#: the compiled loop allocates nothing per candidate; candidates fill the rows before them (at most 31 needed).
BEST_ROW, CAND_ROW = MAX_INFOS - 2, MAX_INFOS - 1
#: Columns of an intercept candidate ("info").
I_EXHAUST, I_TURNS, I_DASHES, I_POWER, I_DIR, I_END_X, I_END_Y, I_BALL_DIST, I_STAMINA = range(9)
INFO_SIZE = 9


def _dash_table() -> np.ndarray:
    """D(n): distance after n full-power dashes from rest for player type 0 (speeds 1 - 0.4**k)."""
    table, speed, dist = [0.0], 0.0, 0.0
    for _ in range(50):
        speed = min(speed + 100.0 * DASH_POWER_RATE, PLAYER_SPEED_MAX)
        dist += speed
        speed *= PLAYER_DECAY
        table.append(dist)
    return np.array(table)


DASH_DISTANCE = _dash_table()


# --- Geometry ---------------------------------------------------------------------------------------
@jit
def nrm(deg):
    """An angle in degrees mapped to [-180, 180)."""
    while deg >= 180.0:
        deg -= 360.0
    while deg < -180.0:
        deg += 360.0
    return deg


@jit
def th(x, y):
    """Heading of (x, y) in degrees; 0 for the zero vector."""
    if x == 0.0 and y == 0.0:
        return 0.0
    return math.degrees(math.atan2(y, x))


@jit
def rel(x, y, a):
    """(x, y) in a frame whose +x axis points along ``a`` degrees."""
    c, s = math.cos(math.radians(a)), math.sin(math.radians(a))
    return x * c + y * s, -x * s + y * c


@jit
def polar(r, a):
    return r * math.cos(math.radians(a)), r * math.sin(math.radians(a))


@jit
def asind(x):
    return math.degrees(math.asin(min(1.0, max(-1.0, x))))


@jit
def first(total, ratio, n):
    """The first term of an n-term geometric series of ratio ``ratio`` summing to ``total``."""
    return total * (1.0 - ratio) / (1.0 - ratio**n)


@jit
def inertia(x, y, vx, vy, decay, n):
    """Position after n cycles of pure inertia (no acceleration)."""
    f = (1.0 - decay**n) / (1.0 - decay)
    return x + vx * f, y + vy * f


@jit
def dash_rate(direction):
    """Dash efficiency of a direction relative to the body, rounded to the 45-degree grid."""
    d = abs(45.0 * np.rint(nrm(direction) / 45.0))
    if d <= 90.0:
        return 0.4 + 0.6 * (1.0 - d / 90.0)
    return 0.6 - 0.2 * (1.0 - (d - 90.0) / 90.0)


@jit
def turn_max(speed, player_rand=0.0):
    """The largest turn a full moment gives at ``speed`` (the smallest under turn noise ``player_rand``)."""
    return 180.0 * (1.0 - player_rand) / (1.0 + INERTIA_MOMENT * speed)


@jit
def dash_cycles(d):
    """Full-power dash cycles a player type 0 needs to cover ``d`` metres from rest."""
    if d <= 0.001:
        return 0
    for n in range(1, 51):
        if DASH_DISTANCE[n] >= d - 0.001:
            return n
    return 50 + int(math.ceil(d - DASH_DISTANCE[50]))


@jit
def line_distance(px, py, ox, oy, a):
    """Distance of point p from the line through o along ``a`` degrees."""
    return abs(rel(px - ox, py - oy, a)[1])


# --- Stamina predictions (the server's per-cycle update on a copy) ---------------------------------------
@jit
def stamina_wait(stamina, effort, recovery):
    if stamina <= RECOVER_DEC_THR:
        recovery = max(recovery - 0.002, 0.5)
        effort = max(effort - 0.005, 0.6)
    if stamina >= EFFORT_INC_THR and effort < 1.0:
        effort = min(effort + 0.01, 1.0)
    stamina += min(recovery * STAMINA_INC_MAX, STAMINA_MAX - stamina)
    return stamina, effort, recovery


@jit
def stamina_dash(stamina, effort, recovery, power):
    stamina = max(stamina - (power if power >= 0.0 else -2.0 * power), 0.0)
    return stamina_wait(stamina, effort, recovery)


@jit
def safe_power(power, stamina):
    """The dash power the stamina allows without dropping below the recovery threshold."""
    power = min(100.0, max(-100.0, power))
    need = power if power >= 0.0 else -2.0 * power
    have = max(0.0, stamina - SAFE_STAMINA)
    result = min(need, have)
    if power < 0.0:
        result *= -0.5
    return power if abs(result) > abs(power) else result


# --- The goalie's world model for one cycle ------------------------------------------------------------
#: Indices of the per-cycle model ``g`` (goalie frame): goalie, ball, agent, derived quantities.
G_PX, G_PY, G_VX, G_VY, G_TH, G_ST, G_EF, G_RC = range(8)
G_BX, G_BY, G_UX, G_UY, G_QX, G_QY, G_WX, G_WY, G_PHI = range(8, 17)
G_DB, G_AB, G_OPP_KICKABLE, G_SELF_KICKABLE, G_LAST_KICKER_ME, G_PLAY_ON = range(17, 23)
G_N_OPP, G_N_SELF, G_OPP_TACKLING, G_CYCLE, G_PLAYER_RAND, G_BALL_RAND = range(23, 29)
#: Where the long stage of the self-intercept table stands (:func:`_long_steps`): whether it has cycles left, M,
#: the next cycle n, the bound L_max, whether it found an interception.
G_LONG_OPEN, G_M, G_LONG_N, G_LONG_MAX, G_LONG_FOUND = range(29, 34)
G_SIZE = 34


@jit
def opponent_kickable_radius(ball_dist, opponent_dist):
    """The agent counts as able to kick within this distance: the kickable area plus observation allowances
    that librcsc keeps even when the state is exact."""
    return KICKABLE_AREA + min(0.25, 0.02 * ball_dist) + min(0.25, 0.02 * opponent_dist)


@jit
def _world_model(world, memory):
    g = np.zeros(G_SIZE)
    g[G_PX], g[G_PY] = -world[W_GX], -world[W_GY]
    g[G_VX], g[G_VY] = -world[W_GVX], -world[W_GVY]
    g[G_TH] = nrm(world[W_GBODY] + 180.0)
    g[G_ST], g[G_EF], g[G_RC] = world[W_GSTAMINA], world[W_GEFFORT], world[W_GRECOVERY]
    g[G_BX], g[G_BY] = -world[W_BX], -world[W_BY]
    g[G_UX], g[G_UY] = -world[W_BVX], -world[W_BVY]
    g[G_QX], g[G_QY] = -world[W_AX], -world[W_AY]
    g[G_WX], g[G_WY] = -world[W_AVX], -world[W_AVY]
    g[G_PHI] = nrm(world[W_ABODY] + 180.0)
    g[G_CYCLE] = world[W_CYCLE]
    g[G_PLAYER_RAND], g[G_BALL_RAND] = world[W_PLAYER_RAND], world[W_BALL_RAND]
    g[G_OPP_TACKLING] = world[W_AGENT_TACKLING]
    g[G_PLAY_ON] = 0.0 if memory[M_CATCH_MODE] else 1.0
    dx, dy = g[G_BX] - g[G_PX], g[G_BY] - g[G_PY]
    g[G_DB] = math.hypot(dx, dy)
    g[G_AB] = th(dx, dy)
    g[G_SELF_KICKABLE] = g[G_DB] <= SELF_KICKABLE
    q_ball = math.hypot(g[G_QX] - g[G_BX], g[G_QY] - g[G_BY])
    q_self = math.hypot(g[G_QX] - g[G_PX], g[G_QY] - g[G_PY])
    g[G_OPP_KICKABLE] = (not g[G_OPP_TACKLING]) and q_ball < opponent_kickable_radius(g[G_DB], q_self)
    if g[G_OPP_KICKABLE] and not g[G_SELF_KICKABLE]:
        g[G_UX] = g[G_UY] = 0.0  # the agent controls the ball: its velocity is about to change
    return g


@jit
def _update_last_kicker(g, world, memory):
    """Who touched the ball last (goalie, agent or unknown), from the previous cycle's ball record."""
    if not g[G_PLAY_ON]:
        memory[M_LAST_KICKER] = GOALIE_SIDE
    elif memory[M_PREV_KICKED]:
        memory[M_LAST_KICKER] = GOALIE_SIDE
    elif memory[M_PREV_VALID]:
        ux, uy = memory[M_PREV_UX], memory[M_PREV_UY]
        speed0, speed = math.hypot(ux, uy), math.hypot(g[G_UX], g[G_UY])
        changed = (
            speed > speed0 + 0.1
            or speed < 0.47 * speed0
            or (speed0 > 0.5 and abs(nrm(th(g[G_UX], g[G_UY]) - th(ux, uy))) > 20.0)
        )
        if changed:
            kicked = world[W_AGENT_KICKED] or (world[W_AGENT_TACKLING] and not memory[M_AGENT_WAS_TACKLING])
            near = math.hypot(g[G_QX] - g[G_BX], g[G_QY] - g[G_BY]) < 6.0
            d_prev = math.hypot(g[G_QX] - memory[M_PREV_BX], g[G_QY] - memory[M_PREV_BY])
            touch = 2.0 if world[W_AGENT_TACKLING] else KICKABLE_AREA + 1.0 * 0.16
            if (kicked and near) or (d_prev < 3.0 and d_prev < touch):
                memory[M_LAST_KICKER] = AGENT_SIDE
    g[G_LAST_KICKER_ME] = memory[M_LAST_KICKER] == GOALIE_SIDE


# --- Ball prediction -------------------------------------------------------------------------------------
@jit
def ball_cache(g, cache):
    """The ball's predicted positions, one per cycle from now, into ``cache``; returns how many."""
    x, y, vx, vy = g[G_BX], g[G_BY], g[G_UX], g[G_UY]
    cache[0, 0], cache[0, 1] = x, y
    if g[G_SELF_KICKABLE]:
        return 1
    n = 1
    for i in range(1, 31):
        x += vx
        y += vy
        vx *= BALL_DECAY
        vy *= BALL_DECAY
        cache[n, 0], cache[n, 1] = x, y
        n += 1
        if (i >= 5 and _below(vx, vy, 0.01)) or abs(x) > 57.5 or abs(y) > 39.0:
            break
    return n


@jit
def _below(x, y, r):
    """``math.hypot(x, y) < r`` for r > 0, calling hypot only within 1 % of r (the length lies between
    max(|x|, |y|) and |x| + |y|, and hypot is exact to an ulp)."""
    ax, ay = abs(x), abs(y)
    if ax + ay < 0.99 * r:
        return True
    if max(ax, ay) > 1.01 * r:
        return False
    return math.hypot(x, y) < r


@jit
def _beyond(x, y, r):
    """``r < math.hypot(x, y)`` for r > 0, as :func:`_below` decides it."""
    ax, ay = abs(x), abs(y)
    if ax + ay < 0.99 * r:
        return False
    if max(ax, ay) > 1.01 * r:
        return True
    return r < math.hypot(x, y)


@jit
def ball_at(g, n):
    return inertia(g[G_BX], g[G_BY], g[G_UX], g[G_UY], BALL_DECAY, n)


@jit
def self_at(g, n):
    return inertia(g[G_PX], g[G_PY], g[G_VX], g[G_VY], PLAYER_DECAY, n)


@jit
def opponent_at(g, n):
    return inertia(g[G_QX], g[G_QY], g[G_WX], g[G_WY], PLAYER_DECAY, n)


# --- When the agent reaches the ball ------------------------------------------------------------------------
@jit
def _opponent_turns(g, n, bx, by):
    """0 or 1: librcsc's player intercept grants at most one turn before dashing at the ball."""
    qx, qy = opponent_at(g, n)
    dist = math.hypot(bx - qx, by - qy)
    delta = abs(nrm(th(bx - qx, by - qy) - g[G_PHI]))
    margin = 180.0 if dist <= KICKABLE_AREA else max(12.0, asind(KICKABLE_AREA / dist))
    if dist < 5.0 and delta > 90.0:
        delta = 180.0 - delta  # it would dash backwards
    return 1 if delta > margin else 0


@jit
def opponent_reach(g, cache, length):
    """Cycles the agent needs to reach the ball, as the goalie predicts it (librcsc's player intercept with
    the agent's top speed 1.0 and kickable area 1.085; every accuracy count is 0 under full state)."""
    if g[G_OPP_KICKABLE]:
        return 0
    c = KICKABLE_AREA
    qx, qy = g[G_QX], g[G_QY]
    n0 = int(math.floor(abs(rel(qx - g[G_BX], qy - g[G_BY], th(g[G_UX], g[G_UY]))[1])))
    for n in range(n0, length):
        bx, by = cache[n, 0], cache[n, 1]
        if _beyond(qx - bx, qy - by, c + 1.0 * n + 0.5):
            continue
        n_turn = _opponent_turns(g, n, bx, by)
        if n - n_turn < 0:
            continue
        ox, oy = opponent_at(g, n)
        dist = math.hypot(bx - ox, by - oy) - c
        if dist < 0.0 or dash_cycles(dist) <= n - n_turn:
            return n
    bx, by = cache[length - 1, 0], cache[length - 1, 1]
    n_turn = _opponent_turns(g, 100, bx, by)
    ox, oy = opponent_at(g, 100)
    dist = math.hypot(ox - bx, oy - by) - c - 0.03 * math.hypot(qx - g[G_PX], qy - g[G_PY])
    if dist < 0.0:
        return length
    return max(length, n_turn + max(1, dash_cycles(dist)))


# --- When the goalie reaches the ball ----------------------------------------------------------------
@jit
def _control_radius(g, bx, by, x_max, y_abs, radius):
    """The catchable reach inside the (stage's) penalty box unless the goalie kicked last, else kickable."""
    if not g[G_LAST_KICKER_ME] and bx < x_max and abs(by) < y_abs:
        return radius
    return KICKABLE_AREA


@jit
def _fill(row, exhaust, turns, dashes, power, direction, ex, ey, ball_dist, stamina):
    row[I_EXHAUST], row[I_TURNS], row[I_DASHES] = exhaust, turns, dashes
    row[I_POWER], row[I_DIR], row[I_END_X], row[I_END_Y] = power, direction, ex, ey
    row[I_BALL_DIST], row[I_STAMINA] = ball_dist, stamina


@jit
def _append(infos, count, exhaust, turns, dashes, power, direction, ex, ey, ball_dist, stamina):
    if count < BEST_ROW:
        _fill(infos[count], exhaust, turns, dashes, power, direction, ex, ey, ball_dist, stamina)
        return count + 1
    return count


@jit
def _trap_power(rbx, rby, f, back, rate):
    """The smallest dash, along the dash line, that leaves the ball in a comfortable kick position."""
    if abs(rby) > 0.735:
        return rbx / rate, True
    x_lo = rbx - math.sqrt(0.735**2 - rby**2)
    if abs(rby) > 0.595:
        return 0.0, False
    x_hi = rbx + math.sqrt(0.595**2 - rby**2)
    step = (x_hi - x_lo) / 5.0
    best, found = 0.0, False
    x = x_lo
    while x < x_hi + 0.01:
        if (0.0 <= x < f) or (back < x < 0.0):
            power = x / rate
            if not found or abs(power) < abs(best):
                best, found = power, True
        x += step
        if step <= 0.0:
            break
    return best, found


@jit
def _one_step(g, infos, count):
    """Stage 1: the ball within reach next cycle without a dash, or after one dash in one of 8 directions."""
    b1x, b1y = g[G_BX] + g[G_UX], g[G_BY] + g[G_UY]
    c = _control_radius(g, b1x, b1y, PENALTY_X, PENALTY_HALF_WIDTH, CATCHABLE_AREA)
    if g[G_DB] > 3.0 + 1.0 + c:
        return count
    speed = math.hypot(g[G_UX], g[G_UY])
    m1x, m1y = g[G_PX] + g[G_VX], g[G_PY] + g[G_VY]
    rx, ry = rel(b1x - m1x, b1y - m1y, g[G_TH])
    r = math.hypot(rx, ry)
    if r <= c - 0.15 - speed * g[G_BALL_RAND]:
        ok = True
        if c == KICKABLE_AREA and r > 0.385:
            k = KICK_POWER_RATE * (1.0 - 0.25 * abs(th(rx, ry)) / 180.0 - 0.25 * (r - 0.385) / 0.7)
            ok = 100.0 * k > speed * BALL_DECAY * BALL_DECAY * 1.1
        if ok:
            st = stamina_wait(g[G_ST], g[G_EF], g[G_RC])[0]
            return _append(infos, count, 0.0, 1.0, 0.0, 0.0, 0.0, m1x, m1y, r, st)
    best = infos[BEST_ROW]
    best[:] = np.nan
    s_b = max(c - 0.2 - speed * g[G_BALL_RAND], 0.665)
    for k in range(8):
        direction = -180.0 + 45.0 * k
        for attempt in range(2):
            forward = min(max(g[G_ST] - SAFE_STAMINA, 0.0), 100.0)
            backward = min(max(-(g[G_ST] - SAFE_STAMINA) / 2.0, -100.0), 0.0)
            if attempt == 1:
                if abs(forward - 100.0) <= 1.0 and abs(backward + 100.0) <= 1.0:
                    break
                forward, backward = 100.0, -100.0
            a = g[G_TH] + direction
            rate = g[G_EF] * DASH_POWER_RATE * dash_rate(direction)
            rbx, rby = rel(b1x - m1x, b1y - m1y, a)
            f, back = forward * rate, backward * rate
            cb = c - 0.075
            if abs(rby) > cb:
                continue
            sx = min(max(rbx, back), f)
            if math.hypot(rbx - sx, rby) > cb:
                continue
            power, found = 0.0, False
            if back < rbx < f:
                trap_rate = g[G_EF] * DASH_POWER_RATE * dash_rate(a)  # the global angle, as the client passes it
                power, found = _trap_power(rbx, rby, f, back, trap_rate)
            if not found and f < rbx and math.hypot(rbx - f, rby) < cb:
                power, found = f / rate, True
            if not found and rbx < back and math.hypot(rbx - back, rby) < cb:
                power, found = back / rate, True
            if not found and back < rbx < f:
                power, found = rbx / rate, True
            if not found:
                continue
            ax, ay = polar(power * rate, a)
            ex, ey = m1x + ax, m1y + ay
            dist = math.hypot(ex - b1x, ey - b1y)
            st = stamina_dash(g[G_ST], g[G_EF], g[G_RC], power)[0]
            if np.isnan(best[0]):
                replace = True
            elif dist < s_b and best[I_BALL_DIST] < s_b:
                replace = st > best[I_STAMINA]
            else:
                replace = dist < best[I_BALL_DIST] or (abs(dist - best[I_BALL_DIST]) < 0.001 and st > best[I_STAMINA])
            if replace:
                _fill(best, st < RECOVER_DEC_THR, 0.0, 1.0, power, direction, ex, ey, dist, st)
            break
    if not np.isnan(best[0]):
        infos[count] = best
        count += 1
    return count


@jit
def _better_short(best, cand, s_b):
    """Whether candidate ``cand`` beats ``best`` among the short-stage candidates of one cycle count."""
    if np.isnan(best[0]):
        return True
    if cand[I_BALL_DIST] < s_b and best[I_BALL_DIST] < s_b:
        return cand[I_TURNS] < best[I_TURNS] or (cand[I_TURNS] == best[I_TURNS] and cand[I_STAMINA] > best[I_STAMINA])
    return cand[I_TURNS] <= best[I_TURNS] and (
        cand[I_BALL_DIST] < best[I_BALL_DIST]
        or (abs(cand[I_BALL_DIST] - best[I_BALL_DIST]) < 0.001 and cand[I_STAMINA] > best[I_STAMINA])
    )


@jit
def _offer(best, cand, s_b):
    if _better_short(best, cand, s_b):
        best[:] = cand


@jit
def _short_turn_dash(g, n, bx, by, c, backward, buffer, best, cand, s_b):
    """Turn towards the ball's position after n cycles, then dash with the power that just gets there."""
    ix, iy = self_at(g, n)
    dist = math.hypot(bx - ix, by - iy)
    ang = th(bx - ix, by - iy)
    base = g[G_TH] + (180.0 if backward else 0.0)
    delta = abs(nrm(ang - base))
    margin = 180.0 if buffer >= dist else max(12.5, asind(buffer / dist))
    turns, speed = 0, math.hypot(g[G_VX], g[G_VY])
    while delta > margin:
        delta -= turn_max(speed)
        speed *= PLAYER_DECAY
        turns += 1
    if turns > n:
        return
    a = base
    if turns > 0:
        a = ang - max(0.0, delta) if nrm(ang - base) > 0.0 else ang + max(0.0, delta)
    dashes = n - turns
    px, py = self_at(g, turns)
    vx, vy = g[G_VX] * PLAYER_DECAY**turns, g[G_VY] * PLAYER_DECAY**turns
    st, ef, rc = g[G_ST], g[G_EF], g[G_RC]
    for _ in range(turns):
        st, ef, rc = stamina_wait(st, ef, rc)
    if math.hypot(ix - bx, iy - by) < c - 0.15:
        # No dash needed: the goalie waits all n cycles, and its stamina is that after n waits (one recorded
        # cycle of the seed-42 run needs it: with the stamina after the turns alone, a dash would win).
        wait_st, wait_ef, wait_rc = st, ef, rc
        for _ in range(dashes):
            wait_st, wait_ef, wait_rc = stamina_wait(wait_st, wait_ef, wait_rc)
        _fill(cand, 0.0, turns, dashes, 0.0, 0.0, ix, iy, math.hypot(ix - bx, iy - by), wait_st)
        _offer(best, cand, s_b)
    if abs(nrm(th(bx - ix, by - iy) - a)) > 90.0:
        return
    first_power = 0.0
    for k in range(1, dashes + 1):
        x = rel(bx - px, by - py, a)[0]
        needed = first(x, PLAYER_DECAY, dashes - k + 1)
        power = (needed - rel(vx, vy, a)[0]) / (DASH_POWER_RATE * g[G_EF])
        available = max(0.0, st - SAFE_STAMINA)
        if backward:
            power = max(min(-power, 0.0), -100.0)
            power = max(power, -available / 2.0)
        else:
            power = min(max(power, 0.0), 100.0)
            power = min(power, available)
        if k == 1:
            first_power = power
        ax, ay = polar(abs(power) * DASH_POWER_RATE * g[G_EF], a)
        vx, vy = vx + ax, vy + ay
        px, py = px + vx, py + vy
        vx, vy = vx * PLAYER_DECAY, vy * PLAYER_DECAY
        st, ef, rc = stamina_dash(st, ef, rc, power)
    end_dist = math.hypot(px - bx, py - by)
    travel2 = (px - g[G_PX]) ** 2 + (py - g[G_PY]) ** 2
    if end_dist < c - 0.15 or travel2 > (g[G_PX] - bx) ** 2 + (g[G_PY] - by) ** 2:
        _fill(cand, st < RECOVER_DEC_THR, turns, dashes, first_power, 0.0, px, py, end_dist, st)
        _offer(best, cand, s_b)


@jit
def _short_omni_dash(g, n, bx, by, c, best, cand, s_b):
    """Side-step onto the line the body points along through the ball, then dash forward along it."""
    ix, iy = self_at(g, n)
    theta = g[G_TH]
    if line_distance(ix, iy, bx, by, theta) < c - 0.4:
        return
    for direction in (-180.0, -135.0, -90.0, -45.0, 45.0, 90.0, 135.0):
        if abs(nrm(theta + direction - th(bx - ix, by - iy))) > 91.0:
            continue
        a = theta + direction
        rate = DASH_POWER_RATE * g[G_EF] * dash_rate(direction)
        px, py, vx, vy = g[G_PX], g[G_PY], g[G_VX], g[G_VY]
        st, ef, rc = g[G_ST], g[G_EF], g[G_RC]
        side, done, first_power = 0, False, 0.0
        for k in range(1, min(2, n) + 1):
            speed = first(max(0.0, line_distance(px, py, bx, by, theta)), PLAYER_DECAY, n - k + 1)
            accel = speed - rel(vx, vy, a)[0]
            if abs(accel) < 0.01:
                break
            power = min(max(accel / rate, 0.0), 100.0)
            power = min(power, max(0.0, st - SAFE_STAMINA))
            if k == 1:
                first_power = power
            ax, ay = polar(power * rate, a)
            vx, vy = vx + ax, vy + ay
            px, py = px + vx, py + vy
            vx, vy = vx * PLAYER_DECAY, vy * PLAYER_DECAY
            st, ef, rc = stamina_dash(st, ef, rc, power)
            side = k
            jx, jy = inertia(px, py, vx, vy, PLAYER_DECAY, n - k)
            if line_distance(jx, jy, bx, by, theta) < c - 0.15:
                done = True
                break
        if not done or side == 0:
            continue
        jx, jy = inertia(px, py, vx, vy, PLAYER_DECAY, n - side)
        if rel(bx - jx, by - jy, theta)[0] < 0.0:
            continue
        for k in range(side + 1, n + 1):
            needed = first(rel(bx - px, by - py, theta)[0], PLAYER_DECAY, n - k + 1)
            power = (needed - rel(vx, vy, theta)[0]) / (DASH_POWER_RATE * g[G_EF])
            power = min(min(max(power, 0.0), 100.0), max(0.0, st - SAFE_STAMINA))
            ax, ay = polar(power * DASH_POWER_RATE * g[G_EF], theta)
            vx, vy = vx + ax, vy + ay
            px, py = px + vx, py + vy
            vx, vy = vx * PLAYER_DECAY, vy * PLAYER_DECAY
            st, ef, rc = stamina_dash(st, ef, rc, power)
        mx, my = px - g[G_PX], py - g[G_PY]
        m = math.hypot(mx, my)
        along = abs(((bx - g[G_PX]) * mx + (by - g[G_PY]) * my) / m) if m > 0.0 else 0.0
        end_dist = math.hypot(px - bx, py - by)
        if end_dist < c - 0.15 or m > along:
            _fill(cand, rc < g[G_RC], 0.0, n, first_power, direction, px, py, end_dist, st)
            _offer(best, cand, s_b)


@jit
def _short_steps(g, m_len, infos, count):
    """Stage 2: reach the ball within 2-5 cycles by turning then dashing, or by side-stepping."""
    ua = th(g[G_UX], g[G_UY])
    lateral = abs(rel(g[G_PX] - g[G_BX], g[G_PY] - g[G_BY], ua)[1])
    n_max = min(5, m_len)
    n_min = int(math.ceil(lateral - KICKABLE_AREA))
    if n_min >= n_max:
        return count
    best, cand = infos[BEST_ROW], infos[CAND_ROW]
    for n in range(max(n_min, 2), n_max + 1):
        bx, by = ball_at(g, n)
        c = _control_radius(g, bx, by, -36.5, 19.66, CATCHABLE_AREA)
        if (c + n) ** 2 < (g[G_PX] - bx) ** 2 + (g[G_PY] - by) ** 2:
            continue
        best[:] = np.nan
        s_b = max(c - 0.2 - math.hypot(g[G_BX] - bx, g[G_BY] - by) * g[G_BALL_RAND], 0.665)
        wide, tight = max(0.1, c - 0.4), c - 0.15
        _short_turn_dash(g, n, bx, by, c, False, wide, best, cand, s_b)
        _short_turn_dash(g, n, bx, by, c, False, tight, best, cand, s_b)
        _short_turn_dash(g, n, bx, by, c, True, wide, best, cand, s_b)
        _short_turn_dash(g, n, bx, by, c, True, tight, best, cand, s_b)
        if n <= 2:
            _short_omni_dash(g, n, bx, by, c, best, cand, s_b)
        if not np.isnan(best[0]) and count < BEST_ROW:
            infos[count] = best
            count += 1
    return count


@jit
def _long_turns(g, n, bx, by, c):
    """Turns before a long chase to the ball's position after n cycles; the dash angle; backward or not."""
    ix, iy = self_at(g, n)
    ang = th(bx - ix, by - iy)
    delta = nrm(ang - g[G_TH])
    sign = 1.0 if delta > 0.0 else -1.0
    dist = math.hypot(bx - ix, by - iy)
    buf = max(0.5, c - 0.25)
    margin = max(12.5, 180.0 if buf >= dist else asind(buf / dist))
    backward = False
    a = g[G_TH]
    if abs(delta) >= 100.0:
        if g[G_LAST_KICKER_ME]:
            allowed = n < 5
        else:
            gx, gy = ball_at(g, n)
            allowed = n < 5 or (n < 15 and math.hypot(GOAL_X - gx, gy) <= 21.0)
        if allowed and g[G_ST] - 200.0 * n + 45.0 * g[G_RC] * (n - 1) >= 2605.0:
            backward = True
            a = g[G_TH] + 180.0
    rest = 180.0 - abs(delta) if backward else abs(delta)
    turns, speed = 0, math.hypot(g[G_VX], g[G_VY])
    while rest > margin:
        rest -= turn_max(speed, g[G_PLAYER_RAND])
        speed *= PLAYER_DECAY
        turns += 1
    if turns > 0:
        a = ang + max(0.0, rest) * sign
    return turns, a, backward


@jit
def _long_step(g, n, bx, by, c, infos, count):
    """Stage 3: turn, then dash at full safe power towards the ball's position after n cycles."""
    turns, a, backward = _long_turns(g, n, bx, by, c)
    if turns > n:
        return count, False
    dashes = n - turns
    rx, ry = rel(bx - g[G_PX], by - g[G_PY], a)
    e = math.hypot(g[G_BX] - bx, g[G_BY] - by) * g[G_BALL_RAND] * 0.5
    target = rx + e
    f = (1.0 - PLAYER_DECAY**turns) / (1.0 - PLAYER_DECAY)
    ox, oy = rel(g[G_VX] * f, g[G_VY] * f, a)
    vx, vy = rel(g[G_VX] * PLAYER_DECAY**turns, g[G_VY] * PLAYER_DECAY**turns, a)
    st, ef, rc = g[G_ST], g[G_EF], g[G_RC]
    for _ in range(turns):
        st, ef, rc = stamina_wait(st, ef, rc)
    first_power = 0.0
    success = overtaken = False
    for k in range(dashes):
        power = min(100.0, max(0.0, st - RECOVER_DEC_THR) * (0.5 if backward else 1.0))
        if k == 0:
            first_power = -power if backward else power
        vx += power * DASH_POWER_RATE * g[G_EF]
        ox, oy = ox + vx, oy + vy
        vx, vy = vx * PLAYER_DECAY, vy * PLAYER_DECAY
        st, ef, rc = stamina_dash(st, ef, rc, -power if backward else power)
        if ox * (1.0 - 0.01 * g[G_PLAYER_RAND]) + 0.1 > target:
            success = overtaken = True
            break
    if not success:
        travel = math.hypot(ox, oy)
        buf = 0.2 + travel * g[G_PLAYER_RAND] * 0.5 + e
        success = math.hypot(rx - ox, ry - oy) < max(c - 0.225, c - buf)
    if not success:
        return count, False
    dx, dy = polar(ox, a)
    sx, sy = polar(oy, a + 90.0)
    ex, ey = g[G_PX] + dx + sx, g[G_PY] + dy + sy
    # Once the goalie overtakes the ball along its dash, its end point is taken on the line from its inertia
    # point through the end, level with the ball; an interception found only by the final reach test keeps its
    # own end and ball distance, so it is no goalie-box candidate for the intercept (the recording's chase turns
    # need exactly this: 7 cycles of the seed-42 run).
    ix, iy = self_at(g, n)
    if overtaken and math.hypot(ex - ix, ey - iy) > 0.1:
        lx, ly = ex - ix, ey - iy
        ll = lx * lx + ly * ly
        if ll > 0.0:
            t = ((bx - ix) * lx + (by - iy) * ly) / ll
            ex, ey = ix + t * lx, iy + t * ly
    count = _append(
        infos, count, rc < g[G_RC], turns, dashes, first_power, 0.0, ex, ey, math.hypot(ex - bx, ey - by), st
    )
    return count, True


@jit
def _may_matter(n, n_opp):
    """Whether an interception after n cycles can be chosen by :func:`_best_info` against an opponent reaching
    the ball after ``n_opp`` cycles (goalie box: n < N_opp - 1; aggressive: n < N_opp - 5; the others:
    n < 0.7 N_opp); false from some n on, so the table can stop there."""
    return n < n_opp - 1 or n < 0.7 * n_opp


@jit
def _long_steps(g, infos, count, n_opp):
    """Stage 3, resumable: its cycles n from ``g[G_LONG_N]`` while n < L_max, pausing before the first n at which
    the table already has a candidate and ``_may_matter(n, n_opp)`` fails (-inf: at the first candidate, all
    N_self needs; inf: never). Where the stage ends without an interception, stage 4 follows.

    Its candidates have larger reaches than all earlier ones, so the paused table is the whole table's first
    rows, and the rows it leaves out are never chosen (spec 2.8.5, best info)."""
    if not g[G_LONG_OPEN]:
        return count
    n, n_max, found, m_len = int(g[G_LONG_N]), int(g[G_LONG_MAX]), g[G_LONG_FOUND] != 0.0, int(g[G_M])
    while n < n_max:
        if count > 0 and not _may_matter(n, n_opp):
            g[G_LONG_N], g[G_LONG_MAX], g[G_LONG_FOUND] = n, n_max, found
            return _sort_infos(infos, count)
        bx, by = ball_at(g, n)
        if abs(bx) > 62.5 or abs(by) > 44.0:
            break
        c = _control_radius(g, bx, by, PENALTY_X, PENALTY_HALF_WIDTH, CATCHABLE_AREA)
        if c + n >= math.hypot(g[G_PX] - bx, g[G_PY] - by):
            count, ok = _long_step(g, n, bx, by, c, infos, count)
            if ok and not found:
                found = True
                n_max = min(m_len, n + 10)
        n += 1
    g[G_LONG_OPEN] = 0.0
    if not found:
        count = _final_step(g, m_len, infos, count)
    return _sort_infos(infos, count)


@jit
def _final_step(g, m_len, infos, count):
    """Stage 4, when nothing else reached the ball: walk to where it comes to rest."""
    bx, by = ball_at(g, 100)
    ix, iy = self_at(g, 100)
    c = _control_radius(g, bx, by, PENALTY_X, PENALTY_HALF_WIDTH, CATCHABLE_AREA - 0.15)
    turns = _long_turns(g, 100, bx, by, c)[0]
    dashes = dash_cycles(math.hypot(ix - bx, iy - by) - c)
    if m_len > turns + dashes:
        dashes = m_len - turns
    return _append(infos, count, 0.0, turns, dashes, 100.0, 0.0, bx, by, 0.0, g[G_ST])


@jit
def _sort_infos(infos, count):
    """Insertion sort by reach, then by fewer turns (stable: equal keys keep the stages' order); the stages
    append in reach order, so rows rarely move."""
    for i in range(1, count):
        key = (infos[i, I_TURNS] + infos[i, I_DASHES], infos[i, I_TURNS])
        if (infos[i - 1, I_TURNS] + infos[i - 1, I_DASHES], infos[i - 1, I_TURNS]) <= key:
            continue
        row = infos[i].copy()
        j = i - 1
        while j >= 0 and (infos[j, I_TURNS] + infos[j, I_DASHES], infos[j, I_TURNS]) > key:
            infos[j + 1] = infos[j]
            j -= 1
        infos[j + 1] = row
    return count


@jit
def _first_intercepts(g, m_len, infos):
    """The table's first rows: stages 1 and 2, and stage 3 up to its first interception if those found none
    (or stage 4), so that its first row, N_self, is the whole table's. :func:`_long_steps` adds the rest."""
    count = 0
    count = _one_step(g, infos, count)
    count = _short_steps(g, m_len, infos, count)
    ua = th(g[G_UX], g[G_UY])
    lateral = abs(rel(g[G_PX] - g[G_BX], g[G_PY] - g[G_BY], ua)[1])
    g[G_LONG_OPEN], g[G_M], g[G_LONG_MAX], g[G_LONG_FOUND] = 1.0, m_len, m_len, 0.0
    g[G_LONG_N] = max(6, int(math.ceil(lateral - KICKABLE_AREA - 0.2)))
    return _long_steps(g, infos, count, -math.inf)


@jit
def self_intercept(g, m_len, infos):
    """The goalie's candidate interceptions (rows of ``infos``, sorted by reach); returns their number."""
    return _long_steps(g, infos, _first_intercepts(g, m_len, infos), math.inf)


# --- Movement primitives ---------------------------------------------------------------------------------
# Each returns (issued, kind, arg1, arg2): a turn by arg1 degrees (before encoding) or a dash of power arg1 in
# direction arg2; ``issued`` is False where librcsc's action reports that it did nothing (its caller may then
# try something else; the client sends ``(turn 0)`` if nothing else comes).
@jit
def _nothing():
    return False, TURN, 0.0, 0.0


@jit
def _turn_to_point(g, x, y, n):
    sx, sy = self_at(g, n)
    return True, TURN, nrm(th(x - sx, y - sy) - g[G_TH]), 0.0


@jit
def _avoid_post(g, tx, ty):
    """A target behind a goal post is replaced by a point beside the post (0.66 m off its centre)."""
    px, py = g[G_PX], g[G_PY]
    post_y = 7.07 if py >= 0.0 else -7.07
    post_x = -52.44
    if (px - post_x) ** 2 + (py - post_y) ** 2 > 2.06:  # a squared distance against a distance, as the client
        return tx, ty
    # Does the segment p-T pass within 0.56 of the post?
    dx, dy = tx - px, ty - py
    ll = dx * dx + dy * dy
    t = 0.0 if ll == 0.0 else min(1.0, max(0.0, ((post_x - px) * dx + (post_y - py) * dy) / ll))
    if math.hypot(px + t * dx - post_x, py + t * dy - post_y) > 0.56:
        return tx, ty
    beta = th(post_x - px, post_y - py)
    diff = nrm(g[G_TH]) - nrm(beta)
    side = 90.0 if (0.0 < diff < 180.0 or diff < -180.0) else -90.0
    ox, oy = polar(0.66, beta + side)
    return post_x + ox, post_y + oy


@jit
def _go_to_point(g, tx, ty, eps, max_power, dash_speed, n, save, dir_thr):
    """librcsc's go-to-point: side-step when close, else turn towards the target, else dash along the body."""
    max_power = abs(max_power)
    if max_power < 0.1:
        return _nothing()
    ix, iy = self_at(g, n)
    if math.hypot(tx - ix, ty - iy) < eps:
        return _nothing()
    tx, ty = _avoid_post(g, tx, ty)
    dx, dy = tx - ix, ty - iy
    dist = math.hypot(dx, dy)
    theta, effort = g[G_TH], g[G_EF]
    if dist <= eps + 1.0:
        bx, by = rel(dx, dy, theta)
        if not (abs(by) < eps or abs(th(bx, by)) < dir_thr):
            best_e, best_steps, best_st = 1e6, 1000, 0.0
            best_power, best_dir, found = 0.0, 0.0, False
            for direction in (-90.0, -45.0, 45.0, 90.0):
                if abs(nrm(direction - th(bx, by))) > 90.0:
                    continue
                rate = DASH_POWER_RATE * effort * dash_rate(direction)
                rvx, rvy = rel(g[G_VX], g[G_VY], theta)
                f = (1.0 - PLAYER_DECAY**n) / (1.0 - PLAYER_DECAY)
                posx, posy, velx, vely = rvx * f, rvy * f, rvx, rvy  # the initial velocity counted twice
                st, ef, rc = g[G_ST], effort, g[G_RC]
                steps, first_power = 0, 0.0
                for k in range(min(3, n)):
                    a_k = first(rel(bx - posx, by - posy, direction)[0], PLAYER_DECAY, n - k)
                    if a_k < 0.01:
                        break
                    have = max(st - SAFE_STAMINA, 0.0) if save else st + EXTRA_STAMINA
                    power = min(have, max_power, a_k / rate, 100.0)
                    ax, ay = polar(power * rate, direction)
                    velx, vely = velx + ax, vely + ay
                    posx, posy = posx + velx, posy + vely
                    velx, vely = velx * PLAYER_DECAY, vely * PLAYER_DECAY
                    st, ef, rc = stamina_dash(st, ef, rc, power)
                    if k == 0:
                        first_power = power
                    steps += 1
                if steps == 0:
                    continue
                e = math.hypot(posx - bx, posy - by)
                if e >= eps:
                    continue
                if e < 0.1 or abs(e - best_e) < 0.001:
                    better = steps < best_steps or st > best_st
                else:
                    better = e < best_e
                if better:
                    best_e, best_steps, best_st = e, steps, st
                    best_power, best_dir, found = first_power, direction, True
            if found:
                return True, DASH, best_power, best_dir
    m = nrm(th(dx, dy) - theta)
    speed = math.hypot(g[G_VX], g[G_VY])
    back = abs(m) > turn_max(speed) and abs(m) > 90.0 and dist < 2.0 and g[G_ST] > 2900.0
    if back:
        m = nrm(m + 180.0)
    thr = max(dir_thr, 180.0 if eps >= dist else asind(eps / dist))
    if abs(m) >= thr:
        return True, TURN, m, 0.0
    a = theta + (180.0 if back else 0.0)
    speed_needed = min(max(first(rel(dx, dy, a)[0], PLAYER_DECAY, n), -PLAYER_SPEED_MAX), PLAYER_SPEED_MAX)
    if dash_speed > 0.0:
        speed_needed = min(max(speed_needed, -dash_speed), dash_speed)
    accel = speed_needed - rel(g[G_VX], g[G_VY], a)[0]
    if abs(accel) < 0.05:
        return _nothing()
    power = min(accel / (DASH_POWER_RATE * effort), max_power)
    if back:
        power = -power
    power = min(max(power, -100.0), 100.0)
    if save:
        power = safe_power(power, g[G_ST])
    return True, DASH, power, 0.0


@jit
def _stop_dash(g, save):
    """The dash, over the eight directions, that leaves the goalie slowest; nothing below power 1."""
    best_speed, best_power, best_dir = math.inf, 0.0, 0.0
    for k in range(8):
        direction = -180.0 + 45.0 * k
        a = g[G_TH] + direction
        rate = DASH_POWER_RATE * g[G_EF] * dash_rate(direction)
        power = min(max(-rel(g[G_VX], g[G_VY], a)[0] / rate, -100.0), 100.0)
        if save:
            power = safe_power(power, g[G_ST])
        ax, ay = polar(power * rate, a)
        speed = math.hypot(g[G_VX] + ax, g[G_VY] + ay)
        if speed < best_speed:
            best_speed, best_power, best_dir = speed, power, direction
    if abs(best_power) < 1.0:
        return _nothing()
    return True, DASH, best_power, best_dir


@jit
def _neck_body_to_ball(g):
    nx, ny = g[G_PX] + g[G_VX], g[G_PY] + g[G_VY]
    m = nrm(th(g[G_BX] + g[G_UX] - nx, g[G_BY] + g[G_UY] - ny) - g[G_TH])
    return True, TURN, (0.0 if -85.0 < m < 85.0 else m), 0.0


@jit
def _look_ball_go_to_point(g, tx, ty, eps, power):
    """Go to a point while keeping the ball in view: back off when the ball and the target lie apart."""
    fx, fy = self_at(g, 1000)
    if math.hypot(fx - tx, fy - ty) < eps:
        return True, TURN, 0.0, 0.0
    nx, ny = g[G_PX] + g[G_VX], g[G_PY] + g[G_VY]
    m = nrm(th(tx - nx, ty - ny) - th(g[G_BX] + g[G_UX] - nx, g[G_BY] + g[G_UY] - ny))
    if abs(m) < 85.0:
        result = _go_to_point(g, tx, ty, eps, power, -1.0, 100, True, 15.0)
        if result[0]:
            return result
        return _neck_body_to_ball(g)
    a = th(nx - tx, ny - ty)
    margin = max(6.0, math.degrees(math.atan2(1.3, math.hypot(tx - nx, ty - ny))))
    if abs(nrm(a - g[G_TH])) > margin:
        return True, TURN, nrm(a - g[G_TH]), 0.0
    return True, DASH, safe_power(-power, g[G_ST]), 0.0


@jit
def _go_to_point_look_ball(g, tx, ty, eps, power):
    if g[G_PLAY_ON]:
        return _look_ball_go_to_point(g, tx, ty, eps, power)
    result = _go_to_point(g, tx, ty, eps, power, -1.0, 100, True, 15.0)
    if result[0]:
        return result
    return True, TURN, nrm(g[G_AB] - g[G_TH]), 0.0


@jit
def _go_to_catch_point(g, x, y):
    """Run straight (forwards or backwards) to a point on the ball's line, turning first if needed."""
    dx, dy = rel(x - g[G_PX], y - g[G_PY], g[G_TH])
    m = th(dx, dy)
    buf = math.degrees(math.atan2(1.17, math.hypot(dx, dy)))
    if abs(m) < buf:
        return True, DASH, min(g[G_ST] + EXTRA_STAMINA, 100.0), 0.0
    if abs(m) > 180.0 - buf:
        have = g[G_ST] + EXTRA_STAMINA
        return True, DASH, (-have / 2.0 if have < 200.0 else -100.0), 0.0
    if abs(m) < 90.0:
        return True, TURN, m, 0.0
    return True, TURN, nrm(m - 180.0), 0.0


# --- Tackle ----------------------------------------------------------------------------------------------
@jit
def tackle_probability(g, exponent):
    """Success probability of a tackle (exponent 6) or a foul tackle (10) on the ball where it lies now."""
    x, y = rel(g[G_BX] - g[G_PX], g[G_BY] - g[G_PY], g[G_TH])
    if x <= 0.0:
        return 0.0
    fail = (abs(x) / TACKLE_DIST) ** exponent + (abs(y) / TACKLE_WIDTH) ** exponent
    return 1.0 - fail if fail < 1.0 else 0.0


@jit
def _tackle_needed(g):
    """Whether a tackle with its probability would be worth it: the agent has the ball, or the ball is going in,
    or the agent will get there well before the goalie."""
    p_tackle = tackle_probability(g, TACKLE_EXPONENT)
    p_foul = 0.0 if g[G_N_OPP] > 0 else tackle_probability(g, FOUL_EXPONENT)
    p = p_tackle
    if (g[G_BX] > -35.5 or abs(g[G_BY]) > 20.66) and p_tackle < p_foul:
        p = p_foul
    if p < 0.8:
        return False
    if g[G_OPP_KICKABLE]:
        return True
    ix = ball_at(g, g[G_N_SELF])[0]
    if ix < GOAL_X and g[G_UX] < 0.0:
        y = g[G_BY] + g[G_UY] * (GOAL_X - g[G_BX]) / g[G_UX]
        if abs(y) < 8.01:
            return True
    return g[G_N_OPP] < g[G_N_SELF] - 3 and g[G_N_OPP] < 1000 - 3


@jit
def _pitch_exit(bx, by, vx, vy):
    """Parameter t >= 0 at which the ray b + t v leaves the pitch (|x| <= 52.5, |y| <= 34); inf if never."""
    t = math.inf
    if vx > 0.0:
        t = min(t, (-GOAL_X - bx) / vx)
    elif vx < 0.0:
        t = min(t, (GOAL_X - bx) / vx)
    if vy > 0.0:
        t = min(t, (PITCH_HALF_WIDTH - by) / vy)
    elif vy < 0.0:
        t = min(t, (-PITCH_HALF_WIDTH - by) / vy)
    return max(t, 0.0)


@jit
def _outside_pitch(x, y):
    return abs(x) > -GOAL_X or abs(y) > PITCH_HALF_WIDTH


@jit
def _opponent_reach_after_kick(g, vx, vy):
    """Cycles the agent would need to reach a ball kicked (tackled) to velocity v; 1000 if it leaves the pitch
    first or the agent cannot get there."""
    speed = math.hypot(vx, vy)
    n_max = 50
    ex, ey = g[G_BX] + vx / (1.0 - BALL_DECAY), g[G_BY] + vy / (1.0 - BALL_DECAY)
    if _outside_pitch(ex, ey) and speed > 0.0:
        t = _pitch_exit(g[G_BX], g[G_BY], vx, vy)
        dist = t * speed
        x = 1.0 - dist * (1.0 - BALL_DECAY) / speed
        if x > 0.0:
            n_max = int(math.ceil(math.log(x) / math.log(BALL_DECAY)))
    va = th(vx, vy)
    rx, ry = rel(g[G_QX] - g[G_BX], g[G_QY] - g[G_BY], va)
    n0 = -1 if rx < -1.0 else max(1, int(math.floor(abs(ry))))
    if n0 < 0:
        n0 = 10
    agent_speed = math.hypot(g[G_WX], g[G_WY])
    for n in range(n0, n_max):
        f = (1.0 - BALL_DECAY**n) / (1.0 - BALL_DECAY)
        bx, by = g[G_BX] + vx * f, g[G_BY] + vy * f
        if _outside_pitch(bx, by):
            return 1000
        qx, qy = opponent_at(g, n)
        dist = math.hypot(qx - bx, qy - by)
        if dist - KICKABLE_AREA < 0.001:
            return n
        dash = dist - (KICKABLE_AREA + (0.5 if n > 1 else 0.0))
        if dash > n:
            continue
        dashes = dash_cycles(dash)
        if dashes > n:
            continue
        delta = abs(nrm(th(bx - qx, by - qy) - g[G_PHI]))
        if dist < 5.0 and delta > 90.0:
            delta = abs(delta - 180.0)
        margin = 180.0 if dist <= KICKABLE_AREA else max(15.0, asind(KICKABLE_AREA / dist))
        turns, s = 0, agent_speed
        while delta > margin:
            delta -= turn_max(s)
            s *= PLAYER_DECAY
            turns += 1
        steps = dashes if turns == 0 else turns + dashes + 1
        if steps <= n:
            return n
    return 1000


@jit
def _tackle_direction(g):
    """The tackle direction (relative to the body) whose resulting ball is scored best: away from the goal,
    out towards the touchline, and where the agent needs long to get it."""
    theta = g[G_TH]
    gamma = abs(nrm(g[G_AB] - theta))
    rate = KICK_POWER_RATE * (1.0 - 0.5 * gamma / 180.0)
    goal_angle = th(GOAL_X - g[G_BX], -g[G_BY])
    best_score, best_dir = -math.inf, 0.0
    for k in range(40):
        direction = -180.0 + 9.0 * k
        ax, ay = polar(100.0 * (1.0 - abs(direction) / 180.0) * rate, theta + direction)
        vx, vy = g[G_UX] + ax, g[G_UY] + ay
        speed = math.hypot(vx, vy)
        if speed > BALL_SPEED_MAX:
            vx, vy, speed = vx * BALL_SPEED_MAX / speed, vy * BALL_SPEED_MAX / speed, BALL_SPEED_MAX
        ex, ey = g[G_BX] + vx / (1.0 - BALL_DECAY), g[G_BY] + vy / (1.0 - BALL_DECAY)
        score = -math.inf
        into_goal = False
        if ex < GOAL_X:
            y = g[G_BY] + (ey - g[G_BY]) * (GOAL_X - g[G_BX]) / (ex - g[G_BX])
            if abs(y) < 8.01:
                into_goal = True
                score = -1e4 * math.exp(-((abs(y) - 7.01) ** 2) / (2.0 * 7.01**2)) + 1e4 * math.exp(
                    -(speed**2) / (2.0 * 1.5**2)
                )
        if not into_goal:
            n = _opponent_reach_after_kick(g, vx, vy)
            f = (1.0 - BALL_DECAY**n) / (1.0 - BALL_DECAY)
            fx, fy = g[G_BX] + vx * f, g[G_BY] + vy * f
            if _outside_pitch(fx, fy):
                t = _pitch_exit(g[G_BX], g[G_BY], vx, vy)
                fx, fy = g[G_BX] + vx * t, g[G_BY] + vy * t
            delta = abs(nrm(goal_angle - th(vx, vy)))
            away = 1.0 - math.exp(-(delta**2) / (2.0 * 40.0**2))
            wide = 1.0 if abs(fy) > 33.9 else math.exp(-((abs(fy) - 34.0) ** 2) / (2.0 * 23.8**2))
            late = 1.0 - math.exp(-(n**2) / (2.0 * 30.0**2))
            score = 1e4 * away * wide * late
        if score > best_score:
            best_score, best_dir = score, direction
    return best_dir


@jit
def _tackle(g):
    """Tackle when it is likely to succeed and needed; (issued, TACKLE, direction, foul)."""
    if not _tackle_needed(g):
        return _nothing()
    p_tackle = tackle_probability(g, TACKLE_EXPONENT)
    p_foul = 0.0 if g[G_N_OPP] > 0 else tackle_probability(g, FOUL_EXPONENT)
    foul = (g[G_BX] > -35.5 or abs(g[G_BY]) > 20.66) and p_tackle < p_foul
    if g[G_SELF_KICKABLE] or not g[G_PLAY_ON] or (p_tackle < 0.001 and p_foul < 0.001):
        direction = nrm(-g[G_TH])  # the default: absolute angle 0
    else:
        direction = _tackle_direction(g)
    return True, TACKLE, direction, 1.0 if foul else 0.0


# --- Intercept --------------------------------------------------------------------------------------------
@jit
def _best_info(g, infos, count, save):
    """Which interception to go for: goalie-box catches first, then no-turn, forward or nearest ones."""
    n_opp = g[G_N_OPP]
    mine = g[G_LAST_KICKER_ME]
    speed0 = math.hypot(g[G_UX], g[G_UY])
    goalie, goalie_score = -1, -1.0
    aggressive, aggressive_score = -1, -1e9
    noturn, forward, forward_score, nearest, nearest_score = -1, -1, -1.0, -1, 1e18
    for i in range(count):
        row = infos[i]
        if save and row[I_EXHAUST]:
            continue
        n = int(row[I_TURNS] + row[I_DASHES])
        bx, by = ball_at(g, n)
        vx, vy = g[G_UX] * BALL_DECAY**n, g[G_UY] * BALL_DECAY**n
        if abs(bx) > 51.5 or abs(by) > 33.0:
            continue
        close = (row[I_TURNS] == 0 and row[I_BALL_DIST] < 0.65) or row[I_BALL_DIST] < 0.01
        if not mine and bx < -37.0 and abs(by) < 19.16 and n < n_opp - 1 and close:
            score = (bx - GOAL_X) ** 2 + by**2
            if score > goalie_score:
                goalie, goalie_score = i, score
        close = (row[I_TURNS] == 0 and row[I_BALL_DIST] < 0.5425) or row[I_BALL_DIST] < 0.01
        if not mine and n < 997 and n < n_opp - 5 and (bx > -37.0 or abs(by) > 19.16) and close:
            if bx > aggressive_score:
                aggressive, aggressive_score = i, bx
        # An "attacker" interception needs a ball beyond x = 35 in the goalie's frame: never in HFO's half.
        if n >= 0.7 * n_opp:
            continue
        speed = math.hypot(vx, vy)
        if row[I_TURNS] == 0:
            if noturn < 0 or n < infos[noturn, I_TURNS] + infos[noturn, I_DASHES]:
                noturn = i
        elif vx > 0.1 and n <= n_opp - 5 and speed > 0.6:
            score = 1e4 - min(1e4, (bx - 65.0) ** 2 + by**2)
            if score > forward_score:
                forward, forward_score = i, score
        else:
            sx, sy = self_at(g, n)
            score = (sx - bx) ** 2 + (sy - by) ** 2
            if score < nearest_score:
                nearest, nearest_score = i, score
    if aggressive >= 0:
        return aggressive
    if goalie >= 0:
        return goalie
    if noturn >= 0 and forward >= 0:
        n_nt = infos[noturn, I_TURNS] + infos[noturn, I_DASHES]
        n_fw = infos[forward, I_TURNS] + infos[forward, I_DASHES]
        vx, vy = g[G_UX] * BALL_DECAY**n_nt, g[G_UY] * BALL_DECAY**n_nt
        if vx > 0.1 and (math.hypot(vx, vy) > 0.9 or n_nt <= n_fw + 2):
            return noturn
        return forward
    if forward >= 0:
        return forward
    n0 = infos[0, I_TURNS] + infos[0, I_DASHES]
    bx, by = ball_at(g, n0)
    if (bx > -33.0 or abs(by) > 20.0) and (n0 >= 10 or speed0 * BALL_DECAY**n0 < 1.2):
        return 0
    if noturn >= 0 and nearest >= 0:
        n_nt = infos[noturn, I_TURNS] + infos[noturn, I_DASHES]
        n_nr = infos[nearest, I_TURNS] + infos[nearest, I_DASHES]
        b_nt, b_nr = ball_at(g, n_nt), ball_at(g, n_nr)
        s_nt, s_nr = self_at(g, n_nt), self_at(g, n_nr)
        e_nt = math.hypot(s_nt[0] - b_nt[0], s_nt[1] - b_nt[1])
        e_nr = math.hypot(s_nr[0] - b_nr[0], s_nr[1] - b_nr[1])
        if e_nt < e_nr:
            return noturn
        if n_nr <= n_nt + 2:
            v_nt = (g[G_UX] * BALL_DECAY**n_nt, g[G_UY] * BALL_DECAY**n_nt)
            sp_nr = speed0 * BALL_DECAY**n_nr
            d_nt, d_nr = infos[noturn, I_BALL_DIST], infos[nearest, I_BALL_DIST]
            if (
                sp_nr < 0.7
                or (
                    d_nr < 0.685
                    and d_nr < d_nt
                    and v_nt[0] < 0.5
                    and math.hypot(v_nt[0], v_nt[1]) > 1.0
                    and b_nt[0] > b_nr[0]
                )
                or (sp_nr > 0.7 and e_nr < 1.085)
            ):
                return nearest
        return noturn
    if noturn >= 0:
        return noturn
    if nearest >= 0:
        return nearest
    return 0


@jit
def _intercept(g, infos, count, save):
    """librcsc's intercept: pick an interception, then turn, wait facing the field, or dash towards it."""
    theta = g[G_TH]
    if g[G_DB] < 2.0 and g[G_OPP_KICKABLE]:
        qx, qy = g[G_QX] + g[G_WX], g[G_QY] + g[G_WY]
        nx, ny = g[G_PX] + g[G_VX], g[G_PY] + g[G_VY]
        if (qx - GOAL_X) ** 2 + qy**2 > (nx - GOAL_X) ** 2 + ny**2:
            return _go_to_point(g, qx, qy, 0.1, 100.0, -1.0, 1, True, 15.0)
    if g[G_N_SELF] > 100:
        fx, fy = ball_at(g, 1000)
        return _go_to_point(g, fx, fy, 2.0, 100.0, -1.0, 100, True, 15.0)
    count = _long_steps(g, infos, count, g[G_N_OPP])  # the rows of the table the choice can take
    i = _best_info(g, infos, count, save)
    row = infos[i]
    reach = int(row[I_TURNS] + row[I_DASHES])
    xx, xy = ball_at(g, reach)
    if row[I_DASHES] == 0:
        return _turn_to_point(g, 50.5, 0.75 * g[G_PY], reach)
    if row[I_TURNS] > 0:
        sx, sy = self_at(g, reach)
        a = th(xx - sx, xy - sy) - (180.0 if row[I_POWER] < 0.0 else 0.0)
        return True, TURN, nrm(a - theta), 0.0
    q_dist = math.hypot(g[G_QX] - g[G_PX], g[G_QY] - g[G_PY])
    if not (q_dist < 3.0 or reach > g[G_N_OPP] - 5):
        ix, iy = self_at(g, reach)
        dx, dy = rel(xx - ix, xy - iy, theta)
        extra = 0.1 * min(max(reach - 1, 0), 4)
        ua = abs(nrm(th(g[G_UX], g[G_UY]) - theta))
        if ua < 10.0 or ua > 170.0:
            extra = 0.0
        if math.hypot(dx, dy) <= KICKABLE_AREA - 0.3 + extra:
            if reach > 2:
                # Face across the ball's line, to the side of the larger x (towards the field): the recording
                # (3 cycles of the seed-42 run) contradicts a reading that takes the smaller x.
                rx, ry = g[G_BX] - ix, g[G_BY] - iy
                fx, fy = ix - ry, iy + rx
                if ix + ry > fx:
                    fx, fy = ix + ry, iy - rx
            else:
                fx, fy = 50.5, 0.9 * g[G_PY]
            phi = math.radians(th(fx - ix, fy - iy))
            # The ball's offset rotated by +phi (not -phi): the client's own sign.
            ry = (xx - ix) * math.sin(phi) + (xy - iy) * math.cos(phi)
            noise = math.hypot(xx - g[G_BX], xy - g[G_BY]) * g[G_BALL_RAND]
            if abs(ry) <= KICKABLE_AREA - noise - 0.2:
                return _turn_to_point(g, fx, fy, 1)
    power, direction = row[I_POWER], row[I_DIR]
    if save and g[G_ST] - (power if power >= 0.0 else -2.0 * power) < SAFE_STAMINA:
        return _nothing()
    if reach == 1:
        return True, DASH, power, direction
    dx, dy = rel(xx - g[G_PX], xy - g[G_PY], theta)
    if g[G_LAST_KICKER_ME] and abs(theta) < 50.0:
        ball_speed = math.hypot(g[G_UX], g[G_UY]) * BALL_DECAY**reach
        if reach >= 8 or abs(dy) > 0.835:
            buf = 0.0
        elif dx < 0.3:
            buf = 0.5 if reach >= 3 else 0.3
        elif abs(dy) < 0.5:
            buf = 0.5 if reach >= 3 else min(dx, 0.5)
        elif ball_speed < 1.6:
            buf = 0.4
        else:
            buf = 0.3 if reach >= 3 else min(dx, 0.3)
        dx -= buf
    speed = math.hypot(g[G_UX], g[G_UY]) * BALL_DECAY**reach
    if speed < 1.6275 and abs(direction) < 5.0 and abs(dx) < KICKABLE_AREA + 0.48 * g[G_EF]:
        s = min(max(first(dx, PLAYER_DECAY, reach), -PLAYER_SPEED_MAX), PLAYER_SPEED_MAX)
        power = (s - rel(g[G_VX], g[G_VY], theta)[0]) / (DASH_POWER_RATE * g[G_EF]) / dash_rate(direction)
        power = min(max(power, -100.0), 100.0)
        if save:
            power = safe_power(power, g[G_ST])
    if reach >= 4 and (abs(dx) < 0.5 or abs(power) < 5.0):
        return _turn_to_point(g, 50.5, 0.75 * g[G_PY], 1)
    return True, DASH, power, direction


# --- Chase -----------------------------------------------------------------------------------------------
@jit
def is_shot(g):
    """Whether the ball is a shot heading into the goalie's goal."""
    if g[G_DB] > 30.0 or g[G_BX] > -34.5 or g[G_OPP_KICKABLE]:
        return False
    bx, by, ux, uy = g[G_BX], g[G_BY], g[G_UX], g[G_UY]
    if abs(ux) < 0.1:
        return bx < -46.0 and abs(by) < 9.01
    a = th(ux, uy)
    c = math.cos(math.radians(a))
    if abs(c) <= 0.1:
        return False
    y_goal = by + math.tan(math.radians(a)) * (GOAL_X - bx)
    return (
        abs(y_goal) < 9.01
        and bx < -40.0
        and abs(by) < 15.0
        and math.hypot(ux, uy) > 0.5
        and bx + ux / (1.0 - BALL_DECAY) < -50.5
    )


@jit
def _is_chase_situation(g):
    if not g[G_PLAY_ON]:
        return False
    n_s, n_o = g[G_N_SELF], g[G_N_OPP]
    b1x, b1y = g[G_BX] + g[G_UX], g[G_BY] + g[G_UY]
    if b1x < -44.5 and abs(b1y) < 10.01:
        if g[G_DB] < 3.0 and n_s <= 3:
            return True
        return not (n_s > n_o + 3 and n_o < 7)
    if is_shot(g) and n_s < n_o:
        return True
    ix, iy = ball_at(g, n_s)
    pen = max(1.0, 0.1 * g[G_DB] + 1.0)
    if abs(iy) > PENALTY_HALF_WIDTH - pen or ix > PENALTY_X - pen:
        return False
    if n_o <= n_s - 2:
        return False
    if math.hypot(g[G_QX] - ix, g[G_QY] - iy) < math.hypot(g[G_PX] - ix, g[G_PY] - iy) - 2.0:
        return False
    return True


@jit
def _chase(g, infos, count):
    tackle = _tackle(g)
    if tackle[0]:
        return tackle
    ix, iy = ball_at(g, g[G_N_SELF])
    pen = max(1.0, 0.1 * g[G_DB] + 1.0)
    ua = th(g[G_UX], g[G_UY])
    line_dist = line_distance(g[G_PX], g[G_PY], g[G_BX], g[G_BY], ua)
    inside = abs(iy) < PENALTY_HALF_WIDTH - pen and ix < PENALTY_X - pen
    if -53.5 < ix and inside:
        return _intercept(g, infos, count, line_dist < CATCHABLE_AREA)
    cos_u = math.cos(math.radians(ua))
    valid = abs(cos_u) > 1e-9
    xx = g[G_PX]
    xy = g[G_BY] + math.tan(math.radians(ua)) * (xx - g[G_BX]) if valid else 0.0
    if (not valid or line_dist < 1.04 or abs(xy) > 10.01) and not g[G_OPP_KICKABLE]:
        if g[G_N_SELF] <= g[G_N_OPP] + 2 and -54.5 < ix and inside:
            return _intercept(g, infos, count, False)
        return _go_to_catch_point(g, g[G_BX], g[G_BY])
    if abs(xx) > 53.8 or xx > -37.3 or abs(xy) > 18.86:
        return _intercept(g, infos, count, False)
    fx, fy = self_at(g, 1000)
    if math.hypot(fx - xx, fy - xy) < max(0.5, 0.2 + 0.1 * g[G_DB]):
        return _stop_dash(g, False)
    if g[G_BX] > -35.0:
        xy = 0.0 if g[G_BY] * xy < 0.0 else xy / 2.0
    return _go_to_catch_point(g, xx, xy)


# --- Basic move: where to stand and how to get there -------------------------------------------------------
@jit
def target_point(g):
    """Where the goalie wants to stand: on the line from (-59.5, 0) to the (predicted) ball, at x = -49.8,
    or beside a post when the ball is wide near the goal line."""
    n_b = 0 if g[G_OPP_KICKABLE] else min(1000, g[G_N_OPP])
    bx, by = ball_at(g, n_b)
    if by > 10.01:
        a = th(GOAL_X - bx, GOAL_HALF_WIDTH - by)
        if -140.0 < a < -90.0:
            return -51.5, 7.011
    elif by < -10.01:
        a = th(GOAL_X - bx, -GOAL_HALF_WIDTH - by)
        if 90.0 < a < 140.0:
            return -51.5, -7.011
    if bx < -44.5 and abs(by) > 9.01:
        return -49.8, (6.91 if by >= 0.0 else -6.91)
    if not g[G_OPP_KICKABLE]:
        # A second extrapolation from the predicted ball with the current velocity.
        f = (1.0 - BALL_DECAY ** min(5, g[G_N_OPP])) / (1.0 - BALL_DECAY)
        bx, by = bx + g[G_UX] * f, by + g[G_UY] * f
    bx = max(bx, -59.4)
    y = by * 9.7 / (bx + 59.5)
    return -49.8, min(max(y, -6.51), 6.51)


@jit
def basic_dash_power(g, tx):
    """Dash power for positioning: full when far off the target's x, else by how threatening the ball is."""
    inc = STAMINA_INC_MAX * g[G_RC]
    if abs(g[G_PX] - tx) > 3.0:
        return 100.0
    bx, by = g[G_BX], g[G_BY]
    if bx > -30.0:
        return inc / 2.0 if g[G_ST] < 7200.0 else inc
    if bx > -36.0:
        if abs(by) > 20.0:
            return inc
        if g[G_UX] > 1.0:
            return inc / 2.0
        if g[G_N_OPP] <= 3:
            return 100.0
        if g[G_ST] < 5600.0:
            return 0.7 * inc
        return 60.0
    return 100.0 if (abs(by) < 15.0 or by * g[G_PY] < 0.0) else inc


@jit
def _correct_body(g, tx, ty, consider_opponent):
    """Face along the goal line (towards the ball's side) while the ball is in front of the goal."""
    b1y = g[G_BY] + g[G_UY]
    target = -90.0 if b1y < 0.0 else 90.0
    if abs(nrm(g[G_TH] - target)) < 5.0 or abs(th(g[G_BX] - GOAL_X, g[G_BY])) >= 60.0:
        return _nothing()
    if consider_opponent:
        q_ball = math.hypot(g[G_QX] - g[G_BX], g[G_QY] - g[G_BY])
        if not (q_ball > 7.0 or g[G_DB] > 20.0 or (abs(ty - g[G_PY]) < 1.0 and not g[G_OPP_KICKABLE])):
            return _nothing()
    return True, TURN, nrm(target - g[G_TH]), 0.0


@jit
def _go_to_move_point(g, tx, ty):
    """Move along y to the target: sideways dashes when the body already faces along the goal line."""
    thr = max(0.5, 0.08 * g[G_DB])
    dy = abs(ty - g[G_PY])
    if dy < thr:
        return _nothing()
    power = basic_dash_power(g, tx)
    theta = g[G_TH]
    if abs(abs(theta) - 90.0) < 7.0:
        power = min(power, dy / (DASH_POWER_RATE * g[G_EF]))
        if (ty > g[G_PY] and theta < 0.0) or (ty <= g[G_PY] and theta > 0.0):
            power = -power
        return True, DASH, min(max(power, -100.0), 100.0), 0.0
    return _go_to_point_look_ball(g, tx, ty, thr, power)


@jit
def _basic_move(g, infos, count):
    tx, ty = target_point(g)
    tackle = _tackle(g)
    if tackle[0]:
        return tackle
    thr = max(0.5, 0.1 * g[G_DB])
    fx, fy = self_at(g, 1000)
    # Deep cross: the ball wide of the goal, the target at a post.
    if abs(ty) >= 6.21 and abs(th(g[G_BX] - GOAL_X, g[G_BY])) >= 60.0:
        if math.hypot(fx - tx, fy - ty) > thr:
            return _go_to_point_look_ball(g, tx, ty, thr, basic_dash_power(g, tx))
        return True, TURN, nrm((10.0 if g[G_BY] < 0.0 else -10.0) - g[G_TH]), 0.0
    # Stop at the target.
    if math.hypot(g[G_PX] - tx, g[G_PY] - ty) < thr and math.hypot(fx - tx, fy - ty) >= thr:
        result = _stop_dash(g, True)
        return True, result[1], result[2], result[3]
    # Dangerous state: the ball near the goal with the agent on it; block from in front of the agent.
    b1x, b1y = g[G_BX] + g[G_UX], g[G_BY] + g[G_UY]
    q_ball = math.hypot(g[G_QX] - g[G_BX], g[G_QY] - g[G_BY])
    if abs(tx - g[G_PX]) > 0.5 and b1x < -41.5 and abs(b1y) < 8.01 and q_ball < 2.0:
        kx = min(g[G_QX] - 2.5, g[G_PX])
        result = _go_to_move_point(g, kx, ty)
        if result[0]:
            return result
        return _go_to_point_look_ball(g, tx, ty, thr, 100.0)
    # Correct x.
    if abs(tx - g[G_PX]) >= 0.5 and ((not g[G_OPP_KICKABLE] and g[G_N_OPP] >= 4) or g[G_DB] > 18.0):
        power = basic_dash_power(g, tx)
        if not g[G_OPP_KICKABLE] and g[G_DB] > 30.0:
            result = _go_to_point(g, tx, ty, 0.5, power, -1.0, 100, True, 15.0)
            if result[0]:
                return result
            return True, TURN, nrm((90.0 if g[G_TH] > 0.0 else -90.0) - g[G_TH]), 0.0
        return _go_to_point_look_ball(g, tx, ty, 0.5, power)
    result = _correct_body(g, tx, ty, True)
    if result[0]:
        return result
    result = _go_to_move_point(g, tx, ty)
    if result[0]:
        return result
    result = _correct_body(g, tx, ty, False)
    if result[0]:
        return result
    return True, TURN, 0.0, 0.0


# --- The decision --------------------------------------------------------------------------------------
@jit
def catch_direction(g):
    """The catch direction relative to the body: the ball on the diagonal of the catch rectangle."""
    return nrm(g[G_AB] - g[G_TH] + CATCH_AIM)


@jit
def _can_catch(g, memory):
    return (
        g[G_PLAY_ON]
        and g[G_CYCLE] > memory[M_LAST_CATCH] + CATCH_WAIT
        and g[G_DB] < CATCH_DISTANCE
        and GOAL_X <= g[G_BX] <= -37.0
        and abs(g[G_BY]) <= 19.16
    )


@jit
def _body_command(g, memory, infos, count):
    """The body command before encoding: (kind, arg1, arg2)."""
    if not g[G_PLAY_ON]:
        # Goalie-catch mode (after its own catch, until the reset): the set-play behaviour.
        if g[G_SELF_KICKABLE]:
            x = -37.0 if g[G_PX] > -36.885 else 0.0
            return _turn_to_point(g, x, 0.0, 1)[1:]
        return _basic_move(g, infos, count)[1:]
    if _can_catch(g, memory):
        return CATCH, catch_direction(g), 0.0
    if g[G_SELF_KICKABLE]:
        # A clearing kick, reachable only on the cycle after the goalie's capture (the reset wipes the kick);
        # its direction search is not modelled yet (issue 43), only that the goalie kicked.
        return KICK, math.nan, math.nan
    if _is_chase_situation(g):
        return _chase(g, infos, count)[1:]
    return _basic_move(g, infos, count)[1:]


@jit
def _encode(g, kind, a1, a2):
    """What librcsc sends for the command: turns pre-multiplied by the inertia factor, dashes on the 45-degree
    grid with stamina kept, arguments on the protocol's 0.001 grid (a catch direction to 6 digits)."""
    if kind == TURN:
        moment = a1 * (1.0 + INERTIA_MOMENT * math.hypot(g[G_VX], g[G_VY]))
        return TURN, np.rint(min(max(moment, -180.0), 180.0) * 1000.0) / 1000.0, 0.0
    if kind == DASH:
        power = min(max(a1, -100.0), 100.0)
        direction = 45.0 * np.rint(min(max(a2, -180.0), 180.0) / 45.0)
        available = g[G_ST] + EXTRA_STAMINA
        if power >= 0.0 and power > available:
            power = available
        elif power < 0.0 and -2.0 * power > available:
            power = -available / 2.0
        return DASH, np.rint(power * 1000.0) / 1000.0, direction
    if kind == CATCH:
        return CATCH, _six_digits(a1), 0.0
    return kind, a1, a2


@jit
def _six_digits(x):
    if x == 0.0:
        return 0.0
    scale = 10.0 ** (5 - int(math.floor(math.log10(abs(x)))))
    return np.rint(x * scale) / scale


@jit
def _forced_kickable(g):
    """librcsc also treats a ball just inside the kickable area (beyond its 0.055 buffer) as kickable when
    nobody else would get it soon, or when it is about to leave the field."""
    n_self, n_opp = g[G_N_SELF], g[G_N_OPP]
    if n_self >= 10 or (n_opp < n_self - 7 and n_opp < 1000 - 7):
        return True
    bx, by = ball_at(g, min(n_self, n_opp))
    return abs(bx) > -GOAL_X or abs(by) > PITCH_HALF_WIDTH


@jit
def decide(world, memory):
    """The goalie's body command for one cycle, decided on ``world`` (``W_*`` layout, server frame).

    Updates ``memory`` (``M_*`` layout) as the goalie's client does. Returns ``(kind, arg1, arg2)``: kind
    ``NONE`` while frozen by its own tackle; ``TURN`` (moment); ``DASH`` (power, direction); ``CATCH``
    (direction); ``TACKLE`` (direction, 1 for a foul); ``KICK`` (not modelled: NaN arguments).
    """
    g = _world_model(world, memory)
    _update_last_kicker(g, world, memory)
    cache = np.empty((MAX_CACHE, 2))
    length = ball_cache(g, cache)
    infos = np.empty((MAX_INFOS, INFO_SIZE))
    count = 0
    g[G_N_OPP] = opponent_reach(g, cache, length)
    if g[G_SELF_KICKABLE]:
        g[G_N_SELF] = 0
    else:
        count = _first_intercepts(g, min(30, length), infos)  # the rest only if the intercept needs it
        g[G_N_SELF] = infos[0, I_TURNS] + infos[0, I_DASHES] if count and not infos[0, I_EXHAUST] else 1000
    if not g[G_SELF_KICKABLE] and g[G_DB] < KICKABLE_AREA - 0.001 and _forced_kickable(g):
        g[G_SELF_KICKABLE] = 1.0
    memory[M_PREV_BX], memory[M_PREV_BY] = g[G_BX], g[G_BY]
    memory[M_PREV_UX], memory[M_PREV_UY] = g[G_UX], g[G_UY]
    memory[M_PREV_VALID] = 1.0
    memory[M_AGENT_WAS_TACKLING] = world[W_AGENT_TACKLING]
    if world[W_GOALIE_FREEZE] > 0:
        memory[M_PREV_KICKED] = 0.0
        return NONE, 0.0, 0.0
    kind, a1, a2 = _body_command(g, memory, infos, count)
    memory[M_PREV_KICKED] = 1.0 if kind == KICK or kind == TACKLE else 0.0
    if kind == CATCH:
        memory[M_LAST_CATCH] = g[G_CYCLE] + 1.0
        memory[M_CATCH_MODE] = 1.0  # under full state a catch tried below 1.25 m always succeeds
    return _encode(g, kind, a1, a2)


def new_memory() -> np.ndarray:
    """The goalie's memory when its program starts: no catch yet, nobody kicked, no ball record."""
    memory = np.zeros(MEMORY_SIZE)
    memory[M_LAST_CATCH] = -1000.0
    return memory


def start_episode(memory: np.ndarray) -> None:
    """What an HFO reset changes in the goalie's memory: the referee's play_on ends goalie-catch mode."""
    memory[M_CATCH_MODE] = 0.0


def world_from_fields(
    ball,
    agent,
    agent_body,
    goalie,
    goalie_body,
    stamina,
    effort,
    recovery,
    cycle,
    agent_kicked=0.0,
    player_rand=0.0,
    ball_rand=0.0,
) -> np.ndarray:
    """A ``world`` vector from named pieces (server frame): ball (x, y, vx, vy), agent and goalie (x, y, vx, vy)."""
    world = np.zeros(WORLD_SIZE)
    world[W_BX : W_BX + 4] = ball
    world[W_AX : W_AX + 4] = agent
    world[W_ABODY] = agent_body
    world[W_GX : W_GX + 4] = goalie
    world[W_GBODY], world[W_GSTAMINA], world[W_GEFFORT], world[W_GRECOVERY] = goalie_body, stamina, effort, recovery
    world[W_CYCLE], world[W_AGENT_KICKED] = cycle, agent_kicked
    world[W_PLAYER_RAND], world[W_BALL_RAND] = player_rand, ball_rand
    return world
