"""One copy of Half Field Offense 1v0: physics, referee, features and shaped reward, compiled by Numba.

The one writing (``LARG/HFO`` and ``rcsoccersim/rcssserver``, cited below by the sections of the project's
written account of them, "spec 2.x") of rcssserver 15.2.2's
movement, kick, dash, turn, stamina and collisions, the agent-side processing that HFO's C++ agent
(librcsc) applies to each low-level action, HFO's referee, the LOW_LEVEL_FEATURE_SET for one agent and
Hausknecht & Stone's shaped reward. Every function works on one copy: its state is a float64 vector
(the indices below) and its random numbers come from its own stream (:func:`uniform`). The envs (the
scalar one at one copy) call :func:`step_batch` and :func:`reset_batch`, one compiled loop over the copies.

Frame (spec 2.1): the server's metres, goal centre at (52.5, 0), y grows "downwards", angles in
degrees normalised to (-180, 180], +90 along +y, positive relative angles on the agent's right.

Everything Numba compiles lives in this one module with the constants it reads, so that Numba's
on-disk cache (keyed by this file) is never stale. ``fastmath`` stays off: the recording of the real
server is matched to the last digits the agent sees (``tests/test_hfo_traces.py``). The speed of the
compiled loop is recorded in ``benchmarks/hfo_speed.md``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

#: ``error_model="numpy"``: no zero-divisor checks (every division here has a nonzero divisor or a guard).
jit = numba.njit(cache=True, nogil=True, error_model="numpy")

# --- Geometry (spec 2.1) -----------------------------------------------------------------------
PITCH_HALF_LENGTH = 52.5
PITCH_HALF_WIDTH = 34.0
GOAL_HALF_WIDTH = 7.01
PENALTY_AREA_X = 36.0
PENALTY_AREA_HALF_WIDTH = 20.16
GOAL_POST_RADIUS = 0.06
#: Centre of the post discs: (±(52.5 - 0.06), ±(7.01 + 0.06)).
POST_X = PITCH_HALF_LENGTH - GOAL_POST_RADIUS
POST_Y = GOAL_HALF_WIDTH + GOAL_POST_RADIUS

# --- Server parameters (spec 2.2, rcssserver 15.2.2 defaults, player type 0) ---------------------
PLAYER_SIZE = 0.3
BALL_SIZE = 0.085
PLAYER_DECAY = 0.4
BALL_DECAY = 0.94
PLAYER_RAND = 0.1
BALL_RAND = 0.05
KICK_RAND = 0.1
PLAYER_ACCEL_MAX = 1.0
PLAYER_SPEED_MAX = 1.05
BALL_ACCEL_MAX = 2.7
BALL_SPEED_MAX = 3.0
DASH_POWER_RATE = 0.006
KICK_POWER_RATE = 0.027
KICKABLE_MARGIN = 0.7
#: Server's kickable distance between centres: player_size + kickable_margin + ball_size.
KICKABLE_AREA = PLAYER_SIZE + KICKABLE_MARGIN + BALL_SIZE
#: The HFO agent's own kickable test under fullstate: librcsc keeps a 0.055 m buffer (spec 2.3).
AGENT_KICKABLE_AREA = KICKABLE_AREA - 0.055
INERTIA_MOMENT = 5.0
DASH_ANGLE_STEP = 45.0
SIDE_DASH_RATE = 0.4
BACK_DASH_RATE = 0.6
STAMINA_MAX = 8000.0
STAMINA_INC_MAX = 45.0
EXTRA_STAMINA = 50.0
STAMINA_CAPACITY = 130600.0
RECOVER_DEC_THR, RECOVER_DEC, RECOVER_MIN = 0.3, 0.002, 0.5
EFFORT_DEC_THR, EFFORT_DEC, EFFORT_MIN = 0.3, 0.005, 0.6
EFFORT_INC_THR, EFFORT_INC, EFFORT_MAX = 0.6, 0.01, 1.0
#: Both velocities are multiplied by this after a player-ball overlap (spec 2.5 step 2).
COLLISION_VELOCITY_FACTOR = -0.1
#: Centre distance at which player and ball touch.
TOUCH_DISTANCE = PLAYER_SIZE + BALL_SIZE
#: Small outward push after resolving a contact, so that the bodies do not overlap again by rounding.
CONTACT_EPSILON = 1e-6

# --- HFO referee (spec 2.7) --------------------------------------------------------------------
#: The ball has crossed the goal line when its centre passes x = 52.5 + ball radius.
GOAL_LINE_X = PITCH_HALF_LENGTH + BALL_SIZE
UNTOUCHED_TIME = 100
FRAMES_PER_TRIAL = 500
#: Both referee counters already stand at 2 when the agent first acts (spec 2.7 "counting").
COUNTERS_AT_FIRST_OBSERVATION = 2
#: Reset distribution: ball x in U(0, 0.2 * 52.5), y in U(-0.8 * 34, 0.8 * 34).
BALL_X_MAX = 0.2 * PITCH_HALF_LENGTH
BALL_Y_MAX = 0.8 * PITCH_HALF_WIDTH
#: The ten offsets (in units of 10.5 m) from which the offensive player's start is drawn.
START_OFFSETS = np.array(
    [(-1, -1), (-1, 1), (1, 1), (1, -1), (0, 2), (0, -2), (-2, -2), (-2, 2), (2, 2), (2, -2)], dtype=float
)
START_SPREAD = 10.5
START_X_MIN = -0.1

IN_GAME, GOAL, OUT_OF_BOUNDS, OUT_OF_TIME = 0, 1, 2, 3
#: Only with the goalie (``defense``): the defense took the ball.
CAPTURED_BY_DEFENSE = 4
STATUS_NAMES = ("IN_GAME", "GOAL", "OUT_OF_BOUNDS", "OUT_OF_TIME", "CAPTURED_BY_DEFENSE")
DASH, TURN, KICK = 0, 1, 2

# --- One copy's state vector ---------------------------------------------------------------------
#: The server's state (spec 2.11), then what the agent sees of it in the same order (6 digits, fullstate).
PX, PY, PVX, PVY, BODY, STAMINA, BX, BY, BVX, BVY = range(10)
SEEN = 10
#: Stamina model; the ball at the end of the previous cycle (the referee's); referee counters and flags.
EFFORT, RECOVERY, CAPACITY, PREV_BX, PREV_BY = range(20, 25)
HOLDER, UNTOUCHED, CYCLES, KICKED, LAST_ACTION_OK, COLLIDED_BALL, COLLIDED_POST, KICKABLE_NOW = range(25, 33)
#: Actions this episode; the kick bonus paid; the previous features the reward differences (f12, f53, and the
#: ball-to-goal distance).
STEPS, BONUS_PAID, PREV_KICKABLE, PREV_BALL_PROXIMITY, PREV_TO_GOAL = range(33, 38)
#: The seen body angle whose cosine and sine are kept (they change only when the player turns).
TRIG_BODY, COS_BODY, SIN_BODY = range(38, 41)
STATE_SIZE = 41

# --- Settings vector (built by :func:`settings`) -----------------------------------------------
_PLAYER_RAND, _BALL_RAND, _KICK_RAND, _MAX_DIST, _OOB_X, _OOB_Y = range(6)
_TIMEOUT_TERMINAL, _TERMINAL_DELTAS, _FIRST_STEP_REWARD, _UNIFORM_BODY = range(6, 10)


@dataclass(frozen=True)
class FeatureProfile:
    """The normalisers and size of one HFO release's low-level features (spec 2.8 "version profiles")."""

    n_features: int
    """58 before HFO added the last-action flag (Aug 2017), 59 since."""
    max_dist: float
    """Dmax, the proximity normaliser of landmarks and the ball."""
    oob_x: float
    """N_x, normaliser of the left/right out-of-bounds proximities."""
    oob_y: float
    """N_y, normaliser of the top/bottom out-of-bounds proximities."""


_DMAX_2016 = math.hypot(PITCH_HALF_LENGTH, PITCH_HALF_WIDTH)  # 62.548
_DMAX_2018 = math.hypot(PITCH_HALF_LENGTH, 2.0 * PITCH_HALF_WIDTH)  # 85.908
PROFILES = {
    "hfo2016": FeatureProfile(58, _DMAX_2016, 52.5, 68.0),  # Hausknecht & Stone 2016
    "hfo2017": FeatureProfile(59, _DMAX_2016, 52.5, 68.0),  # Wei, Wicke & Luke 2018 (the seed paper)
    "hfo2019": FeatureProfile(59, _DMAX_2018, 1.1 * 52.5, 1.05 * 68.0),  # HFO master since March 2019
}

#: Feature indices the reward and the scripted scorer read (spec 2.8, 2.9).
KICKABLE, GOAL_SIN, GOAL_COS, GOAL_PROXIMITY = 12, 13, 14, 15
BALL_SIN, BALL_COS, BALL_PROXIMITY = 51, 52, 53
LAST_ACTION_OK_FEATURE = 58
#: Landmarks of features 13-45, in order: goal centre, goal posts top/bottom, penalty box centre and
#: top/bottom corners, "center field", corners top-left, top-right, bottom-right, bottom-left.
LANDMARKS = np.array(
    [
        (PITCH_HALF_LENGTH, 0.0),
        (PITCH_HALF_LENGTH, -GOAL_HALF_WIDTH),
        (PITCH_HALF_LENGTH, GOAL_HALF_WIDTH),
        (PENALTY_AREA_X, 0.0),
        (PENALTY_AREA_X, -PENALTY_AREA_HALF_WIDTH),
        (PENALTY_AREA_X, PENALTY_AREA_HALF_WIDTH),
        (0.0, 0.0),
        (0.0, -PITCH_HALF_WIDTH),
        (PITCH_HALF_LENGTH, -PITCH_HALF_WIDTH),
        (PITCH_HALF_LENGTH, PITCH_HALF_WIDTH),
        (0.0, PITCH_HALF_WIDTH),
    ]
)
SELF_SPEED_NORMALISER = 0.46
BALL_SPEED_NORMALISER = 5.0


def settings(
    profile: FeatureProfile, deterministic: bool, timeout_terminal: bool, terminal_deltas: bool,
    first_step_reward: bool, uniform_body: bool,
) -> np.ndarray:  # fmt: skip
    """The settings vector the compiled functions read: noise levels, the feature profile, the reward's flags."""
    noise = (0.0, 0.0, 0.0) if deterministic else (PLAYER_RAND, BALL_RAND, KICK_RAND)
    return np.array(
        [*noise, profile.max_dist, profile.oob_x, profile.oob_y,
         timeout_terminal, terminal_deltas, first_step_reward, uniform_body],
        dtype=np.float64,
    )  # fmt: skip


# --- Small helpers -----------------------------------------------------------------------------
@jit
def normalize_angle(deg):
    """An angle in degrees mapped to (-180, 180] (Numba's float % has Python's sign rule)."""
    return 180.0 - (180.0 - deg) % 360.0


@jit
def norm(x, y):
    return math.sqrt(x * x + y * y)


@jit
def clip(x, lo, hi):
    return lo if x < lo else hi if x > hi else x


@jit
def round_command(value):
    """The 0.001 resolution of command arguments in the client's text protocol (halves to even)."""
    return np.rint(value * 1000.0) / 1000.0


# --- One copy's random stream ---------------------------------------------------------------
# xoshiro256++ (Blackman & Vigna, https://prng.di.unimi.it/xoshiro256plusplus.c): four uint64 words per
# copy, advanced in place, instead of buffers refilled from N NumPy generators in Python and read scattered
# over N rows, which slowed the batched step (``benchmarks/hfo_speed.md``, notes). Each copy's words are
# seeded from its own generator (``seed_stream``).
@jit
def _rotl(x, k):
    return (x << np.uint64(k)) | (x >> np.uint64(64 - k))


@jit
def next_double(r):
    """The next number of the stream ``r`` (uint64[4]) in [0, 1): its top 53 bits times 2**-53."""
    s0, s1, s2, s3 = r[0], r[1], r[2], r[3]
    result = _rotl(s0 + s3, 23) + s0
    t = s1 << np.uint64(17)
    s2 ^= s0
    s3 ^= s1
    s1 ^= s2
    s0 ^= s3
    s2 ^= t
    r[0], r[1], r[2], r[3] = s0, s1, s2, _rotl(s3, 45)
    return (result >> np.uint64(11)) * (1.0 / 9007199254740992.0)


@jit
def _splitmix64(x):
    """SplitMix64's output for ``x`` (https://prng.di.unimi.it/splitmix64.c): spreads the bits of a seed."""
    z = x + np.uint64(0x9E3779B97F4A7C15)
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


@jit
def seed_stream(r, u):
    """Seed the stream ``r`` from four numbers ``u`` in [0, 1) drawn from the copy's generator."""
    for k in range(4):
        r[k] = _splitmix64(np.uint64(u[k] * 9007199254740992.0) + np.uint64(k))


@jit
def uniform(rng, low, high):
    """The next U(low, high) draw of a copy's stream ``rng``, as NumPy draws it: low + (high - low) u."""
    return low + (high - low) * next_double(rng)


def _fullstate_table() -> np.ndarray:
    """Per biased binary exponent b of a float64 (its bits 52-62): the decimal exponent estimate
    k = floor((b - 1023) log10 2) of a magnitude with that exponent, the power 10**(k + 1) bounding it, and
    the scales 10**(5 - k) and 10**(4 - k) giving 6 significant digits below and at or above that bound."""
    rows = []
    for b in range(2048):
        k = min(max(math.floor((b - 1023) * math.log10(2.0)), -294), 294)  # beyond: never reached
        rows.append((10.0 ** (k + 1), 10.0 ** (5 - k), 10.0 ** (4 - k)))
    return np.array(rows)


_FULLSTATE = _fullstate_table()


@jit
def six_digits(x, biased_exponent):
    """``x`` to 6 significant digits, given the biased binary exponent of its float64 (halves to even)."""
    magnitude = abs(x)
    if magnitude < 1e-200:
        return x  # zero, or a decayed velocity too small to matter
    row = _FULLSTATE[biased_exponent]
    scale = row[2] if magnitude >= row[0] else row[1]
    return np.rint(x * scale) / scale


@jit
def fullstate_value(x):
    """``x`` to the 6 significant digits in which the server prints fullstate information to the agent.

    HFO's agent sees only these digits: its features, its kickable test and its turn compensation are
    computed from them, and the recording shows rounding boundaries mattering (a turn moment 0.0005 from
    a multiple of 0.001 is rounded the other way when computed from the exact speed).
    """
    return six_digits(x, math.frexp(abs(x))[1] + 1022)


# --- The agent's view (spec 2.3) ---------------------------------------------------------------
@jit
def sense(s):
    """What the agent sees (fullstate, 6 digits) and its kickable test (feature 12; whether a KICK is sent).

    1.03 m between centres (spec 2.3), except on the cycle after a kick was sent, where the recording
    shows the server's 1.085 m (a ball 1.046 m away was reported kickable and kicked; one such case in
    the trace, and no counter-example).
    """
    bits = s[:10].view(np.int64)  # the exponents from the bits: cheaper than frexp, the same numbers
    for k in range(10):
        s[SEEN + k] = six_digits(s[k], (bits[k] >> 52) & 0x7FF)
    dist = norm(s[SEEN + BX] - s[SEEN + PX], s[SEEN + BY] - s[SEEN + PY])
    s[KICKABLE_NOW] = dist <= (KICKABLE_AREA if s[KICKED] else AGENT_KICKABLE_AREA)


# --- Agent-side processing and server-side commands (spec 2.3, 2.4) ----------------------------
@jit
def dash_direction_rate(direction):
    """Efficiency of a dash ``direction`` degrees off the body (a multiple of 45; spec 2.4.3)."""
    d = abs(direction)
    if d <= 90.0:
        rate = SIDE_DASH_RATE + (1.0 - SIDE_DASH_RATE) * (1.0 - d / 90.0)
    else:
        rate = BACK_DASH_RATE - (BACK_DASH_RATE - SIDE_DASH_RATE) * (1.0 - (d - 90.0) / 90.0)
    return clip(rate, 0.0, 1.0)


@jit
def dash(s, power, direction):
    """DASH(power, direction): librcsc's conservation of stamina and speed (from what the agent sees),
    then the server's dash (on the true state). Pays the stamina; returns the player's acceleration."""
    power = clip(power, -100.0, 100.0)
    direction = DASH_ANGLE_STEP * np.rint(clip(direction, -180.0, 180.0) / DASH_ANGLE_STEP)  # halves to even
    rate = dash_direction_rate(direction)
    svx, svy, available = s[SEEN + PVX], s[SEEN + PVY], s[SEEN + STAMINA] + EXTRA_STAMINA
    if power >= 0.0 and power > available:
        power = available
    elif power < 0.0 and -2.0 * power > available:
        power = -available / 2.0
    accel_rate = rate * s[EFFORT] * DASH_POWER_RATE
    accel = abs(power * accel_rate)
    if norm(svx, svy) + accel > PLAYER_SPEED_MAX and accel_rate > 0.0:
        # Only possible, never binding, with player_decay 0.4; part of librcsc's dash (spec 2.3.3).
        phi = math.radians(s[SEEN + BODY] + direction + (180.0 if power < 0.0 else 0.0))
        ux, uy = math.cos(phi), math.sin(phi)
        if norm(svx + accel * ux, svy + accel * uy) > PLAYER_SPEED_MAX:
            v_par = svx * ux + svy * uy
            v_perp2 = svx * svx + svy * svy - v_par * v_par
            accel = max(math.sqrt(max(PLAYER_SPEED_MAX * PLAYER_SPEED_MAX - v_perp2, 0.0)) - v_par, 0.0)
            power = math.copysign(accel / accel_rate, power)
    s[STAMINA], ax, ay = server_dash(s[STAMINA], s[EFFORT], s[BODY], round_command(power), direction, rate)
    return ax, ay


@jit
def server_dash(stamina, effort, body, power, direction, rate):
    """The server's dash of any player (``direction`` on the 45-degree grid, its efficiency ``rate``): pay the
    stamina, then accelerate along body + direction. Returns ``(stamina, ax, ay)``."""
    backward = power < 0.0
    need = min(-2.0 * power if backward else power, stamina + EXTRA_STAMINA)
    stamina = max(stamina - need, 0.0)
    power = -need / 2.0 if backward else need
    accel = abs(effort * power * rate * DASH_POWER_RATE)
    phi = math.radians(body + direction + (180.0 if backward else 0.0))
    return stamina, accel * math.cos(phi), accel * math.sin(phi)


@jit
def turn(s, rng, direction, player_rand):
    """TURN(direction): the agent pre-multiplies by the inertia factor the server divides by."""
    moment = direction * (1.0 + INERTIA_MOMENT * norm(s[SEEN + PVX], s[SEEN + PVY]))
    moment = round_command(clip(moment, -180.0, 180.0))
    inertia = 1.0 + INERTIA_MOMENT * norm(s[PVX], s[PVY])
    noise = 1.0 + uniform(rng, -player_rand, player_rand) if player_rand else 1.0
    s[BODY] = normalize_angle(s[BODY] + noise * moment / inertia)


@jit
def kick(s, rng, power, direction, kick_rand):
    """KICK(power, direction), sent only if the agent's test says kickable; returns the ball's acceleration."""
    power = round_command(clip(power, 0.0, 100.0))
    direction = clip(direction, -180.0, 180.0)
    dx, dy = s[BX] - s[PX], s[BY] - s[PY]
    dist = norm(dx, dy)
    if dist > KICKABLE_AREA:
        return 0.0, 0.0
    heading = math.degrees(math.atan2(dy, dx)) if (dx != 0.0 or dy != 0.0) else 0.0
    dir_diff = abs(normalize_angle(heading - s[BODY])) / 180.0  # delta / pi
    gap = (dist - TOUCH_DISTANCE) / KICKABLE_MARGIN
    effective = power * KICK_POWER_RATE * (1.0 - 0.25 * dir_diff - 0.25 * gap)
    phi = math.radians(s[BODY] + direction)
    kx, ky = effective * math.cos(phi), effective * math.sin(phi)
    if kick_rand and power > 0.0:
        pos_rate = 0.5 + 0.25 * (dir_diff + gap)
        speed_rate = 0.5 + 0.5 * norm(s[BVX], s[BVY]) / (BALL_SPEED_MAX * BALL_DECAY)
        max_noise = kick_rand * (power / 100.0) * (pos_rate + speed_rate)
        length = uniform(rng, 0.0, max_noise)
        angle = uniform(rng, -math.pi, math.pi)
        kx += length * math.cos(angle)
        ky += length * math.sin(angle)
    return kx, ky


# --- One simulation cycle (spec 2.5) ------------------------------------------------------------
@jit
def segment_circle_entry(x, y, path_x, path_y, cx, cy, reach):
    """Fraction t in [0, 1] at which the path (x, y) + t * path enters the disc, or +inf."""
    a = path_x * path_x + path_y * path_y
    fx, fy = x - cx, y - cy
    b = 2.0 * (fx * path_x + fy * path_y)
    c = fx * fx + fy * fy - reach * reach
    disc = b * b - 4.0 * a * c
    if a == 0.0 or b >= 0.0 or disc <= 0.0:
        return np.inf  # at rest, moving away from the centre, or missing the disc
    t = (-b - math.sqrt(disc)) / (2.0 * a)
    return t if 0.0 <= t <= 1.0 else np.inf


@jit
def post_collisions(x, y, vx, vy, radius):
    """Move an object of ``radius`` by ``(vx, vy)``, bouncing elastically off the goal posts (spec 2.5.1.4).

    Returns ``(x, y, vx, vy, collided)`` with the end position and the (undecayed) velocity. Only the
    post nearest to the object (by the signs of x and y) can be hit, at the start or at the end of the
    path; an object already inside a post disc is first pushed out radially.
    """
    reach = GOAL_POST_RADIUS + radius
    if abs(abs(x) - POST_X) > reach + abs(vx) or abs(abs(y) - POST_Y) > reach + abs(vy):
        return x + vx, y + vy, vx, vy, False  # far from every post: the common case
    collided = False
    cx, cy = math.copysign(POST_X, x), math.copysign(POST_Y, y)
    dx, dy = x - cx, y - cy
    dist = norm(dx, dy)
    if dist < reach:
        if dist > 0.0:
            nx, ny = dx / dist, dy / dist
        else:
            nx, ny = math.copysign(1.0, x), 0.0
        x, y = cx + nx * (reach + CONTACT_EPSILON), cy + ny * (reach + CONTACT_EPSILON)
        v_n = vx * nx + vy * ny
        if v_n < 0.0:
            vx, vy = vx - 2.0 * v_n * nx, vy - 2.0 * v_n * ny
        collided = True
    # Sweep the path; each bounce reflects the rest of the path and the velocity across the tangent.
    path_x, path_y = vx, vy
    for _ in range(3):
        t, hit_cx, hit_cy = np.inf, 0.0, 0.0
        for k in range(2):  # the post nearest the start, then the one nearest the end
            qx, qy = (x, y) if k == 0 else (x + path_x, y + path_y)
            cx, cy = math.copysign(POST_X, qx), math.copysign(POST_Y, qy)
            t_c = segment_circle_entry(x, y, path_x, path_y, cx, cy, reach)
            if t_c < t:
                t, hit_cx, hit_cy = t_c, cx, cy
        if t == np.inf:
            break
        x, y = x + t * path_x, y + t * path_y
        nx, ny = (x - hit_cx) / reach, (y - hit_cy) / reach
        x, y = x + CONTACT_EPSILON * nx, y + CONTACT_EPSILON * ny
        rest_x, rest_y = (1.0 - t) * path_x, (1.0 - t) * path_y
        r_n, v_n = rest_x * nx + rest_y * ny, vx * nx + vy * ny
        path_x, path_y = rest_x - 2.0 * r_n * nx, rest_y - 2.0 * r_n * ny
        vx, vy = vx - 2.0 * v_n * nx, vy - 2.0 * v_n * ny
        collided = True
    return x + path_x, y + path_y, vx, vy, collided


@jit
def move(s, rng, o, ax, ay, accel_max, speed_max, rand, decay, radius):
    """Spec 2.5.1 for the object whose x is ``s[o]`` (player ``PX`` or ball ``BX``); returns the post flag."""
    x, y, vx, vy = s[o], s[o + 1], s[o + 2], s[o + 3]
    if ax != 0.0 or ay != 0.0:
        a = norm(ax, ay)
        shrink = accel_max / a if a > accel_max else 1.0
        vx, vy = vx + ax * shrink, vy + ay * shrink
        speed = norm(vx, vy)
        shrink = speed_max / speed if speed > speed_max else 1.0
        vx, vy = vx * shrink, vy * shrink
    if rand and (vx != 0.0 or vy != 0.0):
        length = uniform(rng, 0.0, rand * norm(vx, vy))
        angle = uniform(rng, -math.pi, math.pi)
        vx, vy = vx + length * math.cos(angle), vy + length * math.sin(angle)
    x, y, vx, vy, collided = post_collisions(x, y, vx, vy, radius)
    s[o], s[o + 1], s[o + 2], s[o + 3] = x, y, vx * decay, vy * decay
    return collided


@jit
def resolve_overlap(s, rng):
    """Push player and ball apart about their midpoint to touching distance; both velocities * -0.1."""
    dx, dy = s[BX] - s[PX], s[BY] - s[PY]
    dist = norm(dx, dy)
    if dist > 0.0:
        nx, ny = dx / dist, dy / dist
    else:
        angle = uniform(rng, -math.pi, math.pi)
        nx, ny = math.cos(angle), math.sin(angle)
    mx, my = 0.5 * (s[BX] + s[PX]), 0.5 * (s[BY] + s[PY])
    half = 0.5 * TOUCH_DISTANCE + CONTACT_EPSILON
    s[BX], s[BY] = mx + half * nx, my + half * ny
    s[PX], s[PY] = mx - half * nx, my - half * ny
    for k in (PVX, PVY, BVX, BVY):
        s[k] *= COLLISION_VELOCITY_FACTOR


@jit
def goal_crossed(prev_x, prev_y, x, y):
    """Did the ball's centre cross x = 52.585 between the goal posts this cycle (spec 2.7.1)?"""
    if not (x > GOAL_LINE_X and prev_x <= GOAL_LINE_X and prev_x != x):
        return False
    if abs(prev_y) > POST_Y and prev_x > PITCH_HALF_LENGTH:
        return False
    y_at_line = prev_y + (y - prev_y) * (GOAL_LINE_X - prev_x) / (x - prev_x)
    return abs(y_at_line) <= POST_Y


@jit
def referee(s):
    """HFO's per-cycle referee for 1v0 (spec 2.7), with the counters as the agent sees them."""
    bx, by, prev_x, prev_y = s[BX], s[BY], s[PREV_BX], s[PREV_BY]
    status = IN_GAME
    s[CYCLES] += 1
    if goal_crossed(prev_x, prev_y, bx, by):
        status = GOAL
    elif prev_x < 0.0 or prev_x > PITCH_HALF_LENGTH or abs(prev_y) > PITCH_HALF_WIDTH:
        status = OUT_OF_BOUNDS  # judged on the previous cycle's ball: one step late
    elif s[UNTOUCHED] > UNTOUCHED_TIME or s[CYCLES] > FRAMES_PER_TRIAL:
        status = OUT_OF_TIME
    else:
        s[UNTOUCHED] += 1
        if norm(bx - s[PX], by - s[PY]) <= KICKABLE_AREA:
            s[HOLDER] = 1.0
            s[UNTOUCHED] = 0.0
    s[PREV_BX], s[PREV_BY] = bx, by
    return status


@jit
def update_stamina(s):
    """Spec 2.6: recovery and effort decay below 30% stamina, effort recovers above 60%."""
    s[STAMINA], s[EFFORT], s[RECOVERY], s[CAPACITY] = stamina_model(s[STAMINA], s[EFFORT], s[RECOVERY], s[CAPACITY])


@jit
def stamina_model(stamina, effort, recovery, capacity):
    """One cycle of the stamina model for any player: ``(stamina, effort, recovery, capacity)`` after it."""
    if stamina <= RECOVER_DEC_THR * STAMINA_MAX:
        recovery = max(recovery - RECOVER_DEC, RECOVER_MIN)
    if stamina <= EFFORT_DEC_THR * STAMINA_MAX:
        effort = max(effort - EFFORT_DEC, EFFORT_MIN)
    if stamina >= EFFORT_INC_THR * STAMINA_MAX and effort < EFFORT_MAX:
        effort = min(effort + EFFORT_INC, EFFORT_MAX)
    inc = min(recovery * STAMINA_INC_MAX, STAMINA_MAX - stamina, capacity)
    return stamina + inc, effort, recovery, capacity - inc


@jit
def agent_command(s, rng, a, x0, x1, cfg):
    """The agent's action as the server applies it when it arrives: a turn at once; returns the accelerations
    ``(player x, y, ball x, y)`` of a dash or a kick for the movement phase."""
    pax = pay = bax = bay = 0.0
    sent = True
    if a == DASH:
        pax, pay = dash(s, x0, x1)
    elif a == TURN:
        turn(s, rng, x0, cfg[_PLAYER_RAND])
    elif s[KICKABLE_NOW]:
        bax, bay = kick(s, rng, x0, x1, cfg[_KICK_RAND])
    else:
        sent = False  # HFO sends (turn 0) instead: no effect on the state (spec 2.12.3)
    s[KICKED] = a == KICK and sent
    s[LAST_ACTION_OK] = sent
    return pax, pay, bax, bay


@jit
def simulate(s, rng, a, x0, x1, cfg):
    """One agent action (``DASH(x0, x1)``, ``TURN(x0)`` or ``KICK(x0, x1)``) and one server cycle after it:
    movement, collisions, referee, stamina, the agent's new view. Returns the referee's status."""
    pax, pay, bax, bay = agent_command(s, rng, a, x0, x1, cfg)
    rand = cfg[_PLAYER_RAND]
    s[COLLIDED_POST] = move(s, rng, PX, pax, pay, PLAYER_ACCEL_MAX, PLAYER_SPEED_MAX, rand, PLAYER_DECAY, PLAYER_SIZE)
    move(s, rng, BX, bax, bay, BALL_ACCEL_MAX, BALL_SPEED_MAX, cfg[_BALL_RAND], BALL_DECAY, BALL_SIZE)
    s[COLLIDED_BALL] = norm(s[BX] - s[PX], s[BY] - s[PY]) < TOUCH_DISTANCE
    if s[COLLIDED_BALL]:
        resolve_overlap(s, rng)
    status = referee(s)
    update_stamina(s)
    sense(s)
    return status


# --- Episode start (spec 2.7 "Reset") -----------------------------------------------------------
@jit
def place(s, rng, bx, by, px, py):
    """Start an episode with ball and player at rest at these positions; the body angle is kept.

    Mirrors what the agent first observes, two server cycles after HFO's placement (spec 2.7): full
    stamina, both referee counters at 2 (untouched at 0 if the ball is already in the kickable area),
    and a player-ball overlap already pushed apart.
    """
    s[PX], s[PY], s[PVX], s[PVY] = px, py, 0.0, 0.0
    s[BX], s[BY], s[BVX], s[BVY] = bx, by, 0.0, 0.0
    s[STAMINA], s[EFFORT], s[RECOVERY], s[CAPACITY] = STAMINA_MAX, 1.0, 1.0, STAMINA_CAPACITY
    if norm(bx - px, by - py) < TOUCH_DISTANCE:
        resolve_overlap(s, rng)
    s[PREV_BX], s[PREV_BY] = s[BX], s[BY]
    near = norm(s[BX] - s[PX], s[BY] - s[PY]) <= KICKABLE_AREA
    s[HOLDER] = near
    s[UNTOUCHED] = 0.0 if near else COUNTERS_AT_FIRST_OBSERVATION
    s[CYCLES] = COUNTERS_AT_FIRST_OBSERVATION
    s[COLLIDED_BALL] = s[COLLIDED_POST] = s[KICKED] = 0.0
    s[LAST_ACTION_OK] = 0.0  # HFO's interface took NOOPs between episodes (spec 2.8, f58)
    s[TRIG_BODY] = np.nan
    sense(s)


@jit
def start_episode(s, rng, cfg, options, f):
    """A new episode: HFO's placement, the body angle by the settings' rule, then any of ``options``
    (ball x, y, player x, y, body; NaN where not given) in their place. The features go to ``f``."""
    u0, u1, u2 = uniform(rng, 0.0, 1.0), uniform(rng, 0.0, 1.0), uniform(rng, 0.0, 1.0)
    u3, u4 = uniform(rng, 0.0, 1.0), uniform(rng, 0.0, 1.0)
    bx = BALL_X_MAX * u0
    by = -BALL_Y_MAX + 2.0 * BALL_Y_MAX * u1
    k = min(int(10.0 * u2), 9)
    px = clip(bx + START_SPREAD * (u3 + START_OFFSETS[k, 0]), START_X_MIN, PITCH_HALF_LENGTH)
    py = clip(by + START_SPREAD * (u4 + START_OFFSETS[k, 1]), -BALL_Y_MAX, BALL_Y_MAX)
    if cfg[_UNIFORM_BODY]:
        s[BODY] = normalize_angle(uniform(rng, -180.0, 180.0))
    if not math.isnan(options[0]):
        bx, by = options[0], options[1]
    if not math.isnan(options[2]):
        px, py = options[2], options[3]
    if not math.isnan(options[4]):
        s[BODY] = normalize_angle(options[4])
    place(s, rng, bx, by, px, py)
    s[STEPS] = s[BONUS_PAID] = 0.0
    features(s, cfg, f)
    s[PREV_KICKABLE], s[PREV_BALL_PROXIMITY], s[PREV_TO_GOAL] = f[KICKABLE], f[BALL_PROXIMITY], ball_to_goal(f)


# --- Features (spec 2.8) and reward (spec 2.9) --------------------------------------------------
@jit
def direction_of(x, y):
    """Unit vector and length of (x, y), exact for velocities decayed so far that their squares underflow
    (a held player's velocity decays by 0.4 per cycle for hundreds of cycles): the components are first
    divided by the larger one. The zero vector's direction is (1, 0)."""
    m = max(abs(x), abs(y))
    if m == 0.0:
        return 1.0, 0.0, 0.0
    x, y = x / m, y / m
    length = math.sqrt(x * x + y * y)
    return x / length, y / length, length * m


@jit
def bearing(dx, dy, cos_t, sin_t, d, max_dist, f, i):
    """Landmark features ``f[i:i + 3]``: the bearing of (dx, dy), length ``d``, relative to the body as
    (sin, cos), and the proximity ``1 - 2 min(d / Dmax, 1)``."""
    if d > 0.0:
        dx, dy = dx / d, dy / d
    else:
        dx, dy = 1.0, 0.0  # the player exactly on a landmark or the ball: heading 0
    f[i] = dy * cos_t - dx * sin_t
    f[i + 1] = dx * cos_t + dy * sin_t
    q = d / max_dist
    f[i + 2] = 1.0 - 2.0 * q if q < 1.0 else -1.0


@jit
def features(s, cfg, f):
    """HFO's LOW_LEVEL_FEATURE_SET of what the agent sees, for one agent without teammates or opponents,
    into ``f`` (float64, at least 59 long; the first ``n_features`` are the observation). Every feature
    lies in [-1, 1]; flags are ``2 f - 1``."""
    px, py, body, stamina = s[SEEN + PX], s[SEEN + PY], s[SEEN + BODY], s[SEEN + STAMINA]
    bx, by = s[SEEN + BX], s[SEEN + BY]
    if s[TRIG_BODY] != body:  # NaN after a placement
        theta = math.radians(body)
        s[TRIG_BODY], s[COS_BODY], s[SIN_BODY] = body, math.cos(theta), math.sin(theta)
    cos_t, sin_t = s[COS_BODY], s[SIN_BODY]
    f[0] = f[1] = f[50] = f[54] = 1.0  # position and velocity valid, ball position and velocity valid
    f[8] = f[10] = -1.0  # no opponent collision, no teammate collision
    f[9] = 1.0 if s[COLLIDED_BALL] else -1.0
    f[11] = 1.0 if s[COLLIDED_POST] else -1.0
    f[KICKABLE] = 1.0 if s[KICKABLE_NOW] else -1.0
    f[LAST_ACTION_OK_FEATURE] = 1.0 if s[LAST_ACTION_OK] else -1.0
    ux, uy, speed = direction_of(s[SEEN + PVX], s[SEEN + PVY])
    f[2] = sin_t * ux - cos_t * uy  # body minus velocity heading (HFO's sign order)
    f[3] = cos_t * ux + sin_t * uy
    f[4] = 2.0 * min(speed, SELF_SPEED_NORMALISER) / SELF_SPEED_NORMALISER - 1.0
    f[5], f[6] = sin_t, cos_t
    f[7] = 2.0 * clip(stamina, 0.0, STAMINA_MAX) / STAMINA_MAX - 1.0
    max_dist = cfg[_MAX_DIST]
    for k in range(11):
        dx, dy = LANDMARKS[k, 0] - px, LANDMARKS[k, 1] - py
        bearing(dx, dy, cos_t, sin_t, math.sqrt(dx * dx + dy * dy), max_dist, f, 13 + 3 * k)
    oob_x, oob_y = cfg[_OOB_X], cfg[_OOB_Y]
    f[46] = 1.0 - 2.0 * clip(px / oob_x, 0.0, 1.0)
    f[47] = 1.0 - 2.0 * clip((PITCH_HALF_LENGTH - px) / oob_x, 0.0, 1.0)
    f[48] = 1.0 - 2.0 * clip((PITCH_HALF_WIDTH + py) / oob_y, 0.0, 1.0)
    f[49] = 1.0 - 2.0 * clip((PITCH_HALF_WIDTH - py) / oob_y, 0.0, 1.0)
    dx, dy = bx - px, by - py
    bearing(dx, dy, cos_t, sin_t, math.sqrt(dx * dx + dy * dy), max_dist, f, BALL_SIN)
    ux, uy, speed = direction_of(s[SEEN + BVX], s[SEEN + BVY])
    f[55] = 2.0 * min(speed, BALL_SPEED_NORMALISER) / BALL_SPEED_NORMALISER - 1.0
    f[56], f[57] = uy, ux  # a ball at rest has heading 0: (sin, cos) = (0, 1)


@jit
def ball_to_goal(f):
    """2 d(ball, goal) / Dmax recovered from the features by the law of cosines, as H&S's code does."""
    ball_dist, goal_dist = 1.0 - f[BALL_PROXIMITY], 1.0 - f[GOAL_PROXIMITY]
    # cos(alpha_ball - alpha_goal) from the (sin, cos) pairs: H&S's cos(atan2(...) - atan2(...))
    cos_alpha = f[BALL_COS] * f[GOAL_COS] + f[BALL_SIN] * f[GOAL_SIN]
    squared = ball_dist * ball_dist + goal_dist * goal_dist - 2.0 * ball_dist * goal_dist * cos_alpha
    return math.sqrt(max(squared, 0.0))


@jit
def step_copy(s, rng, a, x0, x1, cfg, f):
    """One step of one copy: the action, a server cycle, the features into ``f`` and Hausknecht & Stone's
    reward ``Δ ball proximity + 1[first time kickable] + 3 · (−Δ ball-to-goal, if the agent holds the
    ball) + 5 · 1[goal]`` with the quirks of the settings (spec 2.9). Returns ``(reward, status)``."""
    status = simulate(s, rng, a, x0, x1, cfg)
    s[STEPS] += 1
    features(s, cfg, f)
    return shaped_reward(s, cfg, f, status), status


@jit
def shaped_reward(s, cfg, f, status):
    """The reward of a transition whose new features are ``f`` (spec 2.9); keeps what the next one differences."""
    to_goal = ball_to_goal(f)
    goal = status == GOAL
    if (status != IN_GAME and not cfg[_TERMINAL_DELTAS]) or (s[STEPS] == 1 and not cfg[_FIRST_STEP_REWARD]):
        reward = 5.0 if goal else 0.0  # H&S's and dqn-hfo's code pay only the goal on these transitions
    else:
        reward = f[BALL_PROXIMITY] - s[PREV_BALL_PROXIMITY]
        if not s[BONUS_PAID] and f[KICKABLE] - s[PREV_KICKABLE] >= 1.0:
            reward += 1.0
            s[BONUS_PAID] = 1.0
        reward += 3.0 * (s[PREV_TO_GOAL] - to_goal) if s[HOLDER] else 0.0
        reward += 5.0 if goal else 0.0
    s[PREV_KICKABLE], s[PREV_BALL_PROXIMITY], s[PREV_TO_GOAL] = f[KICKABLE], f[BALL_PROXIMITY], to_goal
    return reward


@jit
def ending(status, cfg):
    """``(terminated, truncated)`` of a status: a timeout is a truncation unless the settings say terminal."""
    timeout = status == OUT_OF_TIME
    timeout_terminal = cfg[_TIMEOUT_TERMINAL] != 0.0
    ended = status == GOAL or status == OUT_OF_BOUNDS or status == CAPTURED_BY_DEFENSE
    return ended or (timeout and timeout_terminal), timeout and not timeout_terminal


# --- Entry points: the loops over the copies ----------------------------------------------------
@jit
def first_bad_action(a, dash_params, turn_params, kick_params):
    """The checks of a batch of actions: ``(i, 0)`` for the first copy whose discrete action is not 0, 1 or 2
    (an integral float counts as its integer), else ``(i, 1)`` for the first with a parameter that is not finite
    (any of its five: the unused ones too, as on every domain), else ``(-1, 0)``."""
    for i in range(a.shape[0]):
        if not (a[i] == DASH or a[i] == TURN or a[i] == KICK):
            return i, 0
    for i in range(a.shape[0]):
        d0, d1, t0, k0, k1 = (
            dash_params[i, 0],
            dash_params[i, 1],
            turn_params[i, 0],
            kick_params[i, 0],
            kick_params[i, 1],
        )
        if not (
            math.isfinite(d0) and math.isfinite(d1) and math.isfinite(t0) and math.isfinite(k0) and math.isfinite(k1)
        ):
            return i, 1
    return -1, 0


@jit
def step_batch(states, rngs, a, dash_params, turn_params, kick_params, resetting, cfg, obs, reward, status,
               terminated, truncated):  # fmt: skip
    """Every copy i steps on its own state row and stream; a copy whose episode ended on the previous step
    (``resetting``) starts a new one instead, ignoring its action (Gymnasium's next-step autoreset)."""
    f = np.empty(59)
    no_options = np.full(5, np.nan)
    for i in range(states.shape[0]):
        s, r = states[i], rngs[i]
        if resetting[i]:
            start_episode(s, r, cfg, no_options, f)
            reward[i], status[i], terminated[i], truncated[i] = 0.0, IN_GAME, False, False
        else:
            action = a[i]
            if action == DASH:
                x0, x1 = dash_params[i, 0], dash_params[i, 1]
            elif action == TURN:
                x0 = x1 = turn_params[i, 0]
            else:
                x0, x1 = kick_params[i, 0], kick_params[i, 1]
            reward[i], status[i] = step_copy(s, r, action, x0, x1, cfg, f)
            terminated[i], truncated[i] = ending(status[i], cfg)
        for k in range(obs.shape[1]):
            obs[i, k] = f[k]


@jit
def reset_batch(states, rngs, mask, cfg, options, obs):
    """A new episode in every copy where ``mask`` is true, row i of ``options`` as :func:`start_episode`'s;
    the other copies' rows of ``obs`` get their current observation."""
    f = np.empty(59)
    for i in range(states.shape[0]):
        if mask[i]:
            start_episode(states[i], rngs[i], cfg, options[i], f)
        else:
            features(states[i], cfg, f)
        for k in range(obs.shape[1]):
            obs[i, k] = f[k]
