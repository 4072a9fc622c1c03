"""The batched HFO step as two fused Numba loops over the games: the optional fast backend of
``hfo_vector.HalfFieldOffenseVectorEnv`` (``pip install pamdp[fast]``).

The NumPy step makes some twenty passes over ``(rows, N)`` arrays; at N = 1024 it is bound by that
memory traffic, not by the arithmetic. Here each game is stepped start to finish while its numbers
sit in registers. Every formula is the NumPy env's (``hfo_vector.py``, ``hfo_features.feature_rows``),
operation for operation and in the same order, so the two backends agree bit for bit
(``tests/test_hfo_kernel.py``). ``fastmath`` stays off: reassociation or fused multiply-adds would
change the roundings. ``math.cos`` and ``math.sin`` here are the C library's, which give NumPy's
numbers; NumPy's ``arctan2`` does not always (its SIMD version differs in the last bit), so the kick's
one arctangent is taken in NumPy by the caller.

Random numbers are never drawn here: the env draws them from its own generator, in the NumPy step's
order and amounts, and passes them in. Two draws depend on the state mid-step (a player and ball at
exactly the same spot, after the movement or after a placement), so the step is two kernels,
:func:`act_and_move` and :func:`finish_step`, with those rare draws between them.

Numba caches the compiled kernels on disk keyed by this file's modification time and size only, yet the
constants of ``hfo_physics``, ``hfo_features``, ``hfo_vector`` and ``hfo_interface`` are compiled in. So
:func:`refresh_cache` keeps a digest of those modules next to the cache and drops the cached kernels when it
changes: an edit of any of them recompiles the kernels at the next import.
"""

from __future__ import annotations

import math
from pathlib import Path

import numba
import numpy as np

from pamdp.envs import hfo_features as feats
from pamdp.envs import hfo_physics as phys
from pamdp.envs import numba_cache
from pamdp.envs.hfo_features import LANDMARKS
from pamdp.envs.hfo_vector import _DASH_RATES, _SCALES, _THRESHOLD_BITS

DASH, TURN, KICK = phys.DASH, phys.TURN, phys.KICK
IN_GAME, GOAL, OUT_OF_BOUNDS, OUT_OF_TIME = phys.IN_GAME, phys.GOAL, phys.OUT_OF_BOUNDS, phys.OUT_OF_TIME
# Rows of the state matrix (hfo_vector._STATE): object o's x, y, vx, vy are rows o, 2 + o, 4 + o, 6 + o.
_PX, _BX, _PY, _BY, _PVX, _BVX, _PVY, _BVY, _BODY, _STAMINA = range(10)

# Constants folded as the NumPy env folds them (Python floats, evaluated once, in the same order).
_ACCEL_MAX = np.array([phys.PLAYER_ACCEL_MAX, phys.BALL_ACCEL_MAX])
_SPEED_MAX = np.array([phys.PLAYER_SPEED_MAX, phys.BALL_SPEED_MAX])
_DECAY = np.array([phys.PLAYER_DECAY, phys.BALL_DECAY])
_POST_REACH = np.array([phys.GOAL_POST_RADIUS + phys.PLAYER_SIZE, phys.GOAL_POST_RADIUS + phys.BALL_SIZE])
_PLAYER_SPEED_MAX_SQ = phys.PLAYER_SPEED_MAX**2
_KICK_SPEED_NORMALISER = phys.BALL_SPEED_MAX * phys.BALL_DECAY
_HALF_TOUCH = 0.5 * phys.TOUCH_DISTANCE + phys.CONTACT_EPSILON
_DEG2RAD = np.pi / 180.0  # np.radians multiplies by this
_TWO_PI = 2.0 * np.pi
_LANDMARK_X = LANDMARKS[:, 0].copy()
_LANDMARK_Y = LANDMARKS[:, 1].copy()
_MAGNITUDE_BITS = 0x7FFFFFFFFFFFFFFF
_TINY_BITS = int(np.float64(1e-200).view(np.int64))


DEPENDENCIES = ("hfo_physics.py", "hfo_features.py", "hfo_vector.py", "hfo_interface.py")


def refresh_cache(directory: Path | None = None) -> bool:
    """Drop this module's cached kernels if :data:`DEPENDENCIES` changed; True if it did (see ``numba_cache``)."""
    return numba_cache.refresh_cache(__file__, DEPENDENCIES, directory)


refresh_cache()  # before the first kernel is compiled or loaded from the cache
_jit = numba.njit(cache=True, fastmath=False, nogil=True)


@_jit
def _norm(x, y):
    return math.sqrt(x * x + y * y)


@_jit
def _normalize_angle(deg):
    # Numba's float % has Python's (and np.mod's) sign rule
    return 180.0 - (180.0 - deg) % 360.0


@_jit
def _round_command(value):
    return np.rint(value * 1000.0) / 1000.0


@_jit
def _clip(x, lo, hi):
    return min(max(x, lo), hi)


@_jit
def _fullstate(x, bits):
    """``hfo_vector.fullstate_values`` of one number ``x`` whose bit pattern is ``bits``."""
    magnitude = bits & _MAGNITUDE_BITS
    if magnitude < _TINY_BITS:  # zeros and magnitudes below 1e-200 stay as they are
        return x
    biased = magnitude >> 52
    scale = _SCALES[2 * biased + (1 if magnitude >= _THRESHOLD_BITS[biased] else 0)]
    return np.rint(x * scale) / scale


@_jit
def _segment_circle_entry(x, y, path_x, path_y, cx, cy, reach):
    a = path_x * path_x + path_y * path_y
    fx, fy = x - cx, y - cy
    b = 2.0 * (fx * path_x + fy * path_y)
    c = fx * fx + fy * fy - reach * reach
    disc = b * b - 4.0 * a * c
    if a != 0.0 and b < 0.0 and disc > 0.0:
        t = (-b - math.sqrt(disc)) / (2.0 * a)
        if 0.0 <= t <= 1.0:
            return t
    return np.inf


@_jit
def _post_collisions(x, y, vx, vy, reach):
    """``hfo_vector.post_collisions`` for one object: the end position, velocity and the collision flag."""
    near_x = abs(abs(x) - phys.POST_X) <= abs(vx) + reach
    if not (near_x and abs(abs(y) - phys.POST_Y) <= abs(vy) + reach):
        return x + vx, y + vy, vx, vy, False
    cx, cy = math.copysign(phys.POST_X, x), math.copysign(phys.POST_Y, y)
    dx, dy = x - cx, y - cy
    dist = _norm(dx, dy)
    hit_any = dist < reach
    if hit_any:
        if dist > 0.0:
            nx, ny = dx / dist, dy / dist
        else:
            nx, ny = math.copysign(1.0, x), 0.0
        x, y = cx + nx * (reach + phys.CONTACT_EPSILON), cy + ny * (reach + phys.CONTACT_EPSILON)
        v_n = vx * nx + vy * ny
        if v_n < 0.0:
            vx, vy = vx - 2.0 * v_n * nx, vy - 2.0 * v_n * ny
    path_x, path_y = vx, vy
    for _ in range(3):
        t, hit_cx, hit_cy = np.inf, 0.0, 0.0
        for k in range(2):  # the post nearest the start, then the one nearest the end
            qx, qy = (x, y) if k == 0 else (x + path_x, y + path_y)
            cx, cy = math.copysign(phys.POST_X, qx), math.copysign(phys.POST_Y, qy)
            t_c = _segment_circle_entry(x, y, path_x, path_y, cx, cy, reach)
            if t_c < t:
                t, hit_cx, hit_cy = t_c, cx, cy
        if not math.isfinite(t):
            break
        qx, qy = x + t * path_x, y + t * path_y
        nx, ny = (qx - hit_cx) / reach, (qy - hit_cy) / reach
        x, y = qx + phys.CONTACT_EPSILON * nx, qy + phys.CONTACT_EPSILON * ny
        rest_x, rest_y = (1.0 - t) * path_x, (1.0 - t) * path_y
        r_n, v_n = rest_x * nx + rest_y * ny, vx * nx + vy * ny
        path_x, path_y = rest_x - 2.0 * r_n * nx, rest_y - 2.0 * r_n * ny
        vx, vy = vx - 2.0 * v_n * nx, vy - 2.0 * v_n * ny
        hit_any = True
    return x + path_x, y + path_y, vx, vy, hit_any


@_jit
def _dash(state, seen, effort, g, power, direction, seen_speed):
    """``HalfFieldOffenseVectorEnv._dash`` for game ``g``; pays the stamina, returns the acceleration."""
    power = _clip(power, -100.0, 100.0)
    steps = np.rint(_clip(direction, -180.0, 180.0) / phys.DASH_ANGLE_STEP)
    direction = phys.DASH_ANGLE_STEP * steps
    rate = _DASH_RATES[int(steps) + 4]
    available = seen[_STAMINA, g] + phys.EXTRA_STAMINA
    if power >= 0.0:
        power = min(power, available)
    elif -2.0 * power > available:
        power = -available / 2.0
    accel_rate = rate * effort * phys.DASH_POWER_RATE
    accel = abs(power * accel_rate)
    if seen_speed + accel > phys.PLAYER_SPEED_MAX and accel_rate > 0.0:  # librcsc's speed-cap conservation
        svx, svy = seen[_PVX, g], seen[_PVY, g]
        phi = (seen[_BODY, g] + direction + (180.0 if power < 0.0 else 0.0)) * _DEG2RAD
        ux, uy = math.cos(phi), math.sin(phi)
        if _norm(svx + accel * ux, svy + accel * uy) > phys.PLAYER_SPEED_MAX:
            v_par = svx * ux + svy * uy
            v_perp2 = svx * svx + svy * svy - v_par * v_par
            new_accel = max(math.sqrt(max(_PLAYER_SPEED_MAX_SQ - v_perp2, 0.0)) - v_par, 0.0)
            power = math.copysign(new_accel / accel_rate, power)
    power = _round_command(power)
    # server side
    backward = power < 0.0
    stamina = state[_STAMINA, g]
    need = min(-2.0 * power if backward else power, stamina + phys.EXTRA_STAMINA)
    state[_STAMINA, g] = max(0.0, stamina - need)
    power = -need / 2.0 if backward else need
    accel = abs(effort * power * rate * phys.DASH_POWER_RATE)
    phi = state[_BODY, g] + direction
    if backward:
        phi += 180.0
    phi *= _DEG2RAD
    return accel * math.cos(phi), accel * math.sin(phi)


@_jit
def _kick(state, g, power, direction, heading, kick_rand, length_u, angle):
    """``HalfFieldOffenseVectorEnv._kick`` for game ``g``: the ball's acceleration (0 if out of reach).

    ``heading`` is the direction of the ball from the player in degrees (NumPy's arctan2)."""
    power = _round_command(_clip(power, 0.0, 100.0))
    direction = _clip(direction, -180.0, 180.0)
    body = state[_BODY, g]
    dist = _norm(state[_BX, g] - state[_PX, g], state[_BY, g] - state[_PY, g])
    dir_diff = abs(_normalize_angle(heading - body)) / 180.0
    gap = (dist - phys.TOUCH_DISTANCE) / phys.KICKABLE_MARGIN
    effective = power * phys.KICK_POWER_RATE * (1.0 - 0.25 * dir_diff - 0.25 * gap)
    phi = (body + direction) * _DEG2RAD
    kx, ky = effective * math.cos(phi), effective * math.sin(phi)
    if kick_rand:
        pos_rate = 0.5 + 0.25 * (dir_diff + gap)
        speed_rate = 0.5 + 0.5 * _norm(state[_BVX, g], state[_BVY, g]) / _KICK_SPEED_NORMALISER
        max_noise = kick_rand * (power / 100.0) * (pos_rate + speed_rate)
        length = length_u * max_noise
        kx, ky = kx + length * math.cos(angle), ky + length * math.sin(angle)
    if dist <= phys.KICKABLE_AREA:
        return kx, ky
    return 0.0, 0.0


@_jit
def act_and_move(
    a, dash_params, turn_params, kick_params, active, kickable, state, seen, effort, player_rand, kick_rand,
    turn_u, kick_heading, kick_length_u, kick_angle, noise_u, rand, kicked, last_action_ok, collided_post,
    collided_ball,
):  # fmt: skip
    """The agents' actions and the movement of one cycle in every game (``_act`` and ``_advance`` up to
    the player-ball overlap). Draws: ``turn_u`` (N) for the turns' noise, ``kick_length_u`` and
    ``kick_angle`` (N each) for the kicks', ``noise_u`` (4, N) for the movement's, each used only if
    the NumPy step draws it. Returns how many games need a random direction to resolve an overlap."""
    n = state.shape[1]
    zero_overlaps = 0
    for g in range(n):
        pax = pay = bax = bay = 0.0
        kick = sent = False
        if active[g]:
            action = a[g]
            seen_speed = _norm(seen[_PVX, g], seen[_PVY, g])
            if action == DASH:
                pax, pay = _dash(state, seen, effort[g], g, dash_params[g, 0], dash_params[g, 1], seen_speed)
                sent = True
            elif action == TURN:
                moment = turn_params[g, 0] * (1.0 + phys.INERTIA_MOMENT * seen_speed)
                moment = _round_command(_clip(moment, -180.0, 180.0))
                inertia = 1.0 + phys.INERTIA_MOMENT * _norm(state[_PVX, g], state[_PVY, g])
                noise = 1.0
                if player_rand:
                    noise = turn_u[g] * (2.0 * player_rand) + -player_rand + 1.0
                state[_BODY, g] = _normalize_angle(state[_BODY, g] + noise * moment / inertia)
                sent = True
            elif action == KICK and kickable[g]:
                bax, bay = _kick(
                    state, g, kick_params[g, 0], kick_params[g, 1], kick_heading[g], kick_rand, kick_length_u[g],
                    kick_angle[g],
                )  # fmt: skip
                kick = sent = True
        kicked[g] = kick
        last_action_ok[g] = sent
        for obj in range(2):  # spec 2.5.1: the player, then the ball
            x, y, vx, vy = state[obj, g], state[2 + obj, g], state[4 + obj, g], state[6 + obj, g]
            ax, ay = (pax, pay) if obj == 0 else (bax, bay)
            if ax != 0.0 or ay != 0.0:
                a_len = _norm(ax, ay)
                if a_len > _ACCEL_MAX[obj]:
                    shrink = _ACCEL_MAX[obj] / a_len
                    ax, ay = ax * shrink, ay * shrink
                vx, vy = vx + ax, vy + ay
                speed = _norm(vx, vy)
                if speed > _SPEED_MAX[obj]:
                    shrink = _SPEED_MAX[obj] / speed
                    vx, vy = vx * shrink, vy * shrink
            if player_rand:
                length = noise_u[2 * obj, g] * rand[obj] * _norm(vx, vy)
                if length != 0.0:
                    angle = noise_u[2 * obj + 1, g] * _TWO_PI + -np.pi
                    vx, vy = vx + length * math.cos(angle), vy + length * math.sin(angle)
            x, y, vx, vy, collided = _post_collisions(x, y, vx, vy, _POST_REACH[obj])
            state[obj, g], state[2 + obj, g] = x, y
            state[4 + obj, g], state[6 + obj, g] = vx * _DECAY[obj], vy * _DECAY[obj]
            if obj == 0:
                collided_post[g] = collided
        dist = _norm(state[_BX, g] - state[_PX, g], state[_BY, g] - state[_PY, g])
        collided_ball[g] = dist < phys.TOUCH_DISTANCE
        if collided_ball[g] and dist == 0.0:
            zero_overlaps += 1
    return zero_overlaps


@_jit
def _resolve_overlap(state, g, angle):
    """``HalfFieldOffenseVectorEnv._resolve_overlap`` for game ``g``; ``angle`` is used if the two coincide."""
    px, py, bx, by = state[_PX, g], state[_PY, g], state[_BX, g], state[_BY, g]
    dx, dy = bx - px, by - py
    dist = _norm(dx, dy)
    if dist > 0.0:
        nx, ny = dx / dist, dy / dist
    else:
        nx, ny = math.cos(angle), math.sin(angle)
    mx, my = 0.5 * (bx + px), 0.5 * (by + py)
    state[_BX, g], state[_BY, g] = mx + _HALF_TOUCH * nx, my + _HALF_TOUCH * ny
    state[_PX, g], state[_PY, g] = mx - _HALF_TOUCH * nx, my - _HALF_TOUCH * ny
    for row in (_PVX, _PVY, _BVX, _BVY):
        state[row, g] *= phys.COLLISION_VELOCITY_FACTOR


@_jit
def _placement(u):
    """Ball and player positions from one row of 5 uniform draws (``HalfFieldOffenseVectorEnv._place``)."""
    bx = phys.BALL_X_MAX * u[0]
    by = -phys.BALL_Y_MAX + 2.0 * phys.BALL_Y_MAX * u[1]
    k = min(int(10.0 * u[2]), 9)
    px = _clip(bx + phys.START_SPREAD * (u[3] + phys.START_OFFSETS[k, 0]), phys.START_X_MIN, phys.PITCH_HALF_LENGTH)
    py = _clip(by + phys.START_SPREAD * (u[4] + phys.START_OFFSETS[k, 1]), -phys.BALL_Y_MAX, phys.BALL_Y_MAX)
    return bx, by, px, py


@_jit
def placements_coincide(u):
    """Does any placement drawn from the rows of ``u`` put the player exactly on the ball (which takes a
    random direction to push them apart)?"""
    for j in range(u.shape[0]):
        bx, by, px, py = _placement(u[j])
        if _norm(bx - px, by - py) == 0.0:
            return True
    return False


@_jit
def finish_step(
    state, state_bits, seen, effort, recovery, capacity, prev_bx, prev_by, holder, untouched, cycles, steps,
    status, collided_ball, collided_post, kicked, last_action_ok, bonus_paid, kickable, trig_body, cos_body,
    sin_body, memory, overlap_angle, resetting, place_u, body_u, uniform_body, place_angle, profile, flags, obs,
    reward, terminated, truncated,
):  # fmt: skip
    """The rest of the step in every game: the overlap, referee and stamina (``_advance``), new
    episodes for the ``resetting`` games (rows of ``place_u`` and ``body_u`` in order), the agents'
    view, the features into ``obs`` (float32) and the reward. ``memory`` holds, per game, the
    previous features the reward reads (kickable, ball proximity) and the ball-to-goal term.
    ``profile`` is (n_features, -Dmax / 2, -N_x / 2, -N_y / 2); ``flags`` is (timeout_terminal,
    terminal_deltas, first_step_reward)."""
    n = state.shape[1]
    n_features = int(profile[0])
    neg_half_dmax, oob_x_divisor, oob_y_divisor = profile[1], profile[2], profile[3]
    timeout_terminal, terminal_deltas, first_step_reward = flags[0], flags[1], flags[2]
    j = 0  # the next row of placement draws
    f = np.empty(59)  # one game's features, float64; every entry is written for each game
    for g in range(n):
        # --- _advance after the movement
        if collided_ball[g]:
            _resolve_overlap(state, g, overlap_angle[g])
        px, py, bx, by = state[_PX, g], state[_PY, g], state[_BX, g], state[_BY, g]
        dist = _norm(bx - px, by - py)
        # referee
        cycles[g] += 1
        prev_x, prev_y = prev_bx[g], prev_by[g]
        goal = False
        if bx > phys.GOAL_LINE_X and prev_x <= phys.GOAL_LINE_X and prev_x != bx:
            if not (abs(prev_y) > phys.POST_Y and prev_x > phys.PITCH_HALF_LENGTH):
                y_at_line = prev_y + (by - prev_y) * (phys.GOAL_LINE_X - prev_x) / (bx - prev_x)
                goal = abs(y_at_line) <= phys.POST_Y
        s = IN_GAME
        if goal:
            s = GOAL
        elif prev_x < 0.0 or prev_x > phys.PITCH_HALF_LENGTH or abs(prev_y) > phys.PITCH_HALF_WIDTH:
            s = OUT_OF_BOUNDS
        elif untouched[g] > phys.UNTOUCHED_TIME or cycles[g] > phys.FRAMES_PER_TRIAL:
            s = OUT_OF_TIME
        else:
            untouched[g] += 1
            if dist <= phys.KICKABLE_AREA:
                untouched[g] = 0
                holder[g] = True
        prev_bx[g], prev_by[g] = bx, by
        # stamina
        stamina = state[_STAMINA, g]
        if stamina <= phys.RECOVER_DEC_THR * phys.STAMINA_MAX:
            recovery[g] = max(phys.RECOVER_MIN, recovery[g] - phys.RECOVER_DEC)
        if stamina <= phys.EFFORT_DEC_THR * phys.STAMINA_MAX:
            effort[g] = max(phys.EFFORT_MIN, effort[g] - phys.EFFORT_DEC)
        if effort[g] < phys.EFFORT_MAX and stamina >= phys.EFFORT_INC_THR * phys.STAMINA_MAX:
            effort[g] = min(phys.EFFORT_MAX, effort[g] + phys.EFFORT_INC)
        inc = min(min(recovery[g] * phys.STAMINA_INC_MAX, phys.STAMINA_MAX - stamina), capacity[g])
        state[_STAMINA, g] = stamina + inc
        capacity[g] -= inc
        steps[g] += 1
        # --- a new episode where the last one ended (HFOGame.place)
        if resetting[g]:
            bx, by, px, py = _placement(place_u[j])
            if uniform_body:
                state[_BODY, g] = _normalize_angle(360.0 * body_u[j] - 180.0)
            j += 1
            state[_PX, g], state[_PY, g], state[_PVX, g], state[_PVY, g] = px, py, 0.0, 0.0
            state[_BX, g], state[_BY, g], state[_BVX, g], state[_BVY, g] = bx, by, 0.0, 0.0
            state[_STAMINA, g], effort[g], recovery[g] = phys.STAMINA_MAX, 1.0, 1.0
            capacity[g] = phys.STAMINA_CAPACITY
            if _norm(bx - px, by - py) < phys.TOUCH_DISTANCE:
                _resolve_overlap(state, g, place_angle[g])
                px, py, bx, by = state[_PX, g], state[_PY, g], state[_BX, g], state[_BY, g]
            prev_bx[g], prev_by[g] = bx, by
            near = _norm(bx - px, by - py) <= phys.KICKABLE_AREA
            holder[g] = near
            untouched[g] = 0 if near else phys.COUNTERS_AT_FIRST_OBSERVATION
            cycles[g] = phys.COUNTERS_AT_FIRST_OBSERVATION
            collided_ball[g] = collided_post[g] = kicked[g] = last_action_ok[g] = False
            steps[g] = 0
            bonus_paid[g] = False
        # --- the agent's view (fullstate_values) and its kickable test
        for row in range(10):
            seen[row, g] = _fullstate(state[row, g], state_bits[row, g])
        spx, spy, sbx, sby = seen[_PX, g], seen[_PY, g], seen[_BX, g], seen[_BY, g]
        limit = phys.KICKABLE_AREA if kicked[g] else phys.AGENT_KICKABLE_AREA
        kickable[g] = _norm(sbx - spx, sby - spy) <= limit
        if trig_body[g] != seen[_BODY, g]:
            trig_body[g] = seen[_BODY, g]
            theta = trig_body[g] * _DEG2RAD
            cos_body[g], sin_body[g] = math.cos(theta), math.sin(theta)
        cos_t, sin_t = cos_body[g], sin_body[g]
        # --- the features (hfo_features.feature_rows), then the observation
        f[0] = f[1] = f[50] = f[54] = 1.0
        f[8] = f[10] = -1.0
        # the flags, 2 f - 1
        f[9] = 1.0 if collided_ball[g] else -1.0
        f[11] = 1.0 if collided_post[g] else -1.0
        f[12] = 1.0 if kickable[g] else -1.0
        f[58] = 1.0 if last_action_ok[g] else -1.0
        f[5], f[6] = sin_t, cos_t
        for obj in range(2):  # velocity directions and speeds (hfo_features._directions)
            vx, vy = seen[_PVX + obj, g], seen[_PVY + obj, g]
            m = max(abs(vx), abs(vy))
            if m == 0.0:
                ux, uy, speed = 1.0, 0.0, 0.0
            else:
                ux, uy = vx / m, vy / m
                length = math.sqrt(ux * ux + uy * uy)
                ux, uy, speed = ux / length, uy / length, length * m
            if obj == 0:
                f[2] = sin_t * ux - cos_t * uy
                f[3] = cos_t * ux + sin_t * uy
                f[4] = min(speed, feats.SELF_SPEED_MAX) / (feats.SELF_SPEED_MAX / 2.0) - 1.0
            else:
                f[55] = min(speed, feats.BALL_SPEED_MAX) / (feats.BALL_SPEED_MAX / 2.0) - 1.0
                f[56], f[57] = uy, ux
        f[7] = min(max(seen[_STAMINA, g], 0.0), phys.STAMINA_MAX) / (phys.STAMINA_MAX / 2.0) - 1.0
        for k in range(12):  # the 11 landmarks, then the ball
            if k < 11:
                dx, dy, row = _LANDMARK_X[k] - spx, _LANDMARK_Y[k] - spy, 13 + 3 * k
            else:
                dx, dy, row = sbx - spx, sby - spy, 51
            d = math.sqrt(dx * dx + dy * dy)
            if d > 0.0:
                dx, dy = dx / d, dy / d
            else:
                dx, dy = 1.0, 0.0
            f[row] = dy * cos_t - dx * sin_t
            f[row + 1] = dx * cos_t + dy * sin_t
            f[row + 2] = max(d / neg_half_dmax, -2.0) + 1.0
        f[46] = max(min(spx / oob_x_divisor, 0.0), -2.0) + 1.0
        f[47] = max(min((phys.PITCH_HALF_LENGTH - spx) / oob_x_divisor, 0.0), -2.0) + 1.0
        f[48] = max(min((phys.PITCH_HALF_WIDTH + spy) / oob_y_divisor, 0.0), -2.0) + 1.0
        f[49] = max(min((phys.PITCH_HALF_WIDTH - spy) / oob_y_divisor, 0.0), -2.0) + 1.0
        for k in range(n_features):
            obs[g, k] = np.float32(f[k])
        # --- the reward (hfo_features.ball_to_goal_rows and shaped_reward, then the step's quirks)
        ball_dist, goal_dist = 1.0 - f[53], 1.0 - f[15]
        cos_alpha = f[52] * f[14] + f[51] * f[13]
        squared = ball_dist * ball_dist + goal_dist * goal_dist - 2.0 * ball_dist * goal_dist * cos_alpha
        to_goal = math.sqrt(max(squared, 0.0))
        r = 0.0
        paid = False
        terminal = s != IN_GAME
        if not resetting[g]:
            r = f[53] - memory[1, g]
            paid = not bonus_paid[g] and f[12] - memory[0, g] >= 1.0
            r += 1.0 if paid else 0.0
            r += 3.0 * (memory[2, g] - to_goal) if holder[g] else 3.0 * 0.0
            r += 5.0 if goal else 0.0
            if (terminal and not terminal_deltas) or (steps[g] == 1 and not first_step_reward):
                r = 5.0 if goal else 0.0
                paid = False
            bonus_paid[g] |= paid
            timeout = s == OUT_OF_TIME
            terminated[g] = goal or s == OUT_OF_BOUNDS or (timeout and timeout_terminal)
            truncated[g] = timeout and not timeout_terminal
        else:
            terminated[g] = truncated[g] = False
            s = IN_GAME
        reward[g] = r
        status[g] = s
        memory[0, g], memory[1, g], memory[2, g] = f[12], f[53], to_goal
