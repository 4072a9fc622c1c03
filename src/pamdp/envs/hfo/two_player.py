"""Server rules that need a second player on the pitch: the goalie's catch, and collisions between three bodies.

rcssserver (the HFO fork, mhauskn/rcssserver) applies a goalie's ``(catch dir)`` when the command arrives,
before the cycle's movement. In HFO mode the server's catch referee is off, so the goalie may catch anywhere
and no free kick follows: a successful catch only teleports the goalie next to the ball, facing it, at rest;
the ball keeps its velocity. The server then resolves collisions at once, and whether the ball and the goalie
overlap after the jump is decided by the last bits of the arithmetic (the jump lands them exactly touching).

All in the server frame (metres, degrees). Pure functions of scalars, compiled by Numba, so that an
environment can call them per copy.
"""

from __future__ import annotations

import math

import numpy as np

from pamdp.envs.hfo.dynamics import jit

#: The catch rectangle: 1.2 m along the catch direction, 1.0 m wide (player type 0: no stretch).
CATCHABLE_AREA_L = 1.2
CATCHABLE_AREA_W = 1.0
CATCH_BAN_CYCLE = 5
PLAYER_SIZE = 0.3
BALL_SIZE = 0.085
#: Every object of a collision has its velocity multiplied by this once.
COLLISION_VELOCITY_FACTOR = -0.1
#: Added to each half of a resolved contact so that the pair ends strictly apart.
SEPARATION_EPSILON = 1e-10
TACKLE_DIST, TACKLE_WIDTH, TACKLE_EXPONENT, FOUL_EXPONENT = 2.0, 1.25, 6.0, 10.0
TACKLE_POWER_RATE, MAX_TACKLE_POWER = 0.027, 100.0
TACKLE_CYCLES = 10
KICKABLE_AREA = 1.085
BALL_SPEED_MAX, BALL_DECAY = 3.0, 0.94
#: Object-pair contact distances: ball-player and player-player.
BALL_PLAYER_CONTACT = BALL_SIZE + PLAYER_SIZE
PLAYER_PLAYER_CONTACT = 2.0 * PLAYER_SIZE
MAX_COLLISION_PASSES = 10


@jit
def catchable(goalie_x, goalie_y, body, direction, ball_x, ball_y):
    """Whether the ball lies in the catch rectangle of a catch ``direction`` degrees off the body (inclusive)."""
    kappa = math.radians(body + min(max(direction, -180.0), 180.0))
    dx, dy = ball_x - goalie_x, ball_y - goalie_y
    x = dx * math.cos(kappa) + dy * math.sin(kappa)
    y = -dx * math.sin(kappa) + dy * math.cos(kappa)
    return 0.0 <= x <= CATCHABLE_AREA_L and -CATCHABLE_AREA_W / 2.0 <= y <= CATCHABLE_AREA_W / 2.0


@jit
def catch(goalie_x, goalie_y, body, direction, ban, ball_x, ball_y):
    """The server's catch command (play_on, catch probability 1): ``(success, ban, goalie_x, goalie_y, body)``.

    The ban counter becomes 5 after any catch that the ban itself does not refuse. On success the goalie jumps
    along the line to the ball until the two touch, faces the ball and stops (velocity 0); the ball keeps its
    position and velocity. The server then resolves collisions at once (:func:`collide`): the jump lands the
    pair exactly touching, and whether the double-precision distance falls below contact, turning the ball's
    velocity to -0.1 of itself, is decided by the last bits of the arithmetic.
    """
    if ban > 0:
        return False, ban, goalie_x, goalie_y, body
    if not catchable(goalie_x, goalie_y, body, direction, ball_x, ball_y):
        return False, CATCH_BAN_CYCLE, goalie_x, goalie_y, body
    dx, dy = ball_x - goalie_x, ball_y - goalie_y
    dist = math.sqrt(dx * dx + dy * dy)
    scale = (dist - (BALL_SIZE + PLAYER_SIZE)) / dist
    return True, CATCH_BAN_CYCLE, goalie_x + dx * scale, goalie_y + dy * scale, math.degrees(math.atan2(dy, dx))


@jit
def tackle(goalie_x, goalie_y, body, direction, foul, ball_x, ball_y, ball_vx, ball_vy, agent_dist, draws, kick_rand):
    """The server's tackle command: ``(success, freeze, ax, ay)``, the ball's acceleration on success.

    Every tackle freezes the tackler for 10 cycles (a successful foul ends the freeze at once). The ball must lie
    ahead of the body (no back tackles); a foul tackle (``foul``) counts as one only while the agent is within
    its kickable distance of the ball (``agent_dist``), with the flatter exponent 10 instead of 6. Success is a
    Bernoulli draw with probability 1 - f, f = (x/2)**e + (y/1.25)**e of the ball's body-frame offset, random
    even under ``--deterministic``: ``draws`` are three U(0, 1) numbers from the caller's stream (the success
    draw, then the noise length and direction, the noise scaled by ``kick_rand``, 0 under ``--deterministic``).
    """
    a = math.radians(body)
    dx, dy = ball_x - goalie_x, ball_y - goalie_y
    x = dx * math.cos(a) + dy * math.sin(a)
    y = -dx * math.sin(a) + dy * math.cos(a)
    if x <= 0.0:
        return False, TACKLE_CYCLES, 0.0, 0.0
    is_foul = foul and agent_dist <= KICKABLE_AREA
    e = FOUL_EXPONENT if is_foul else TACKLE_EXPONENT
    fail = (abs(x) / TACKLE_DIST) ** e + (abs(y) / TACKLE_WIDTH) ** e
    if fail >= 1.0 or draws[0] >= 1.0 - fail:
        return False, TACKLE_CYCLES, 0.0, 0.0
    direction = min(max(direction, -180.0), 180.0)
    gamma = math.atan2(y, x)
    power = MAX_TACKLE_POWER * (1.0 - abs(direction) / 180.0) * TACKLE_POWER_RATE * (1.0 - 0.5 * abs(gamma) / math.pi)
    phi = math.radians(body + direction)
    ax, ay = power * math.cos(phi), power * math.sin(phi)
    if kick_rand > 0.0:
        pos_rate = 0.5 + 0.5 * (1.0 - fail)
        speed_rate = 0.5 + 0.5 * math.hypot(ball_vx, ball_vy) / (BALL_SPEED_MAX * BALL_DECAY)
        length = draws[1] * kick_rand * 2.0 * (pos_rate + speed_rate)
        angle = (2.0 * draws[2] - 1.0) * math.pi
        ax, ay = ax + length * math.cos(angle), ay + length * math.sin(angle)
    return True, 0 if is_foul else TACKLE_CYCLES, ax, ay


@jit
def _separate(pos, acc, counts, i, j, contact):
    """Add to the accumulators the positions of objects i and j pushed apart about their midpoint to just
    beyond ``contact``."""
    dx, dy = pos[j, 0] - pos[i, 0], pos[j, 1] - pos[i, 1]
    d = math.sqrt(dx * dx + dy * dy)
    # Coincident centres: the server draws a random direction; a fixed one here (never met in play).
    ux, uy = (dx / d, dy / d) if d > 1e-10 else (1.0, 0.0)
    mx, my = (pos[i, 0] + pos[j, 0]) / 2.0, (pos[i, 1] + pos[j, 1]) / 2.0
    half = contact / 2.0 + SEPARATION_EPSILON
    ox, oy = ux * half, uy * half
    for _ in range(10):
        if (2.0 * ox) ** 2 + (2.0 * oy) ** 2 >= contact * contact:
            break
        ox, oy = ox * 1.0001, oy * 1.0001
    acc[i, 0] += mx - ox
    acc[i, 1] += my - oy
    acc[j, 0] += mx + ox
    acc[j, 1] += my + oy
    counts[i] += 1
    counts[j] += 1


@jit
def collide(pos, vel, collided):
    """rcssserver's collision resolution after a movement phase (or a catch), in place.

    ``pos``, ``vel``: (K, 2) arrays, row 0 the ball, then the enabled players in the server's list order (the
    agent, then the goalie). Each pass pushes apart every overlapping ball-player pair (0.385 m) and then every
    overlapping pair of players (0.6 m), and moves each object that collided to the average of the positions its
    pairs asked for; passes repeat while anything overlapped, at most 10. Every object that collided has its
    velocity multiplied by -0.1 once; ``collided`` (bool, K) marks them.
    """
    k = pos.shape[0]
    acc = np.empty((k, 2))
    counts = np.empty(k)
    for _ in range(MAX_COLLISION_PASSES):
        acc[:] = 0.0
        counts[:] = 0.0
        for i in range(1, k):
            dx, dy = pos[i, 0] - pos[0, 0], pos[i, 1] - pos[0, 1]
            if dx * dx + dy * dy < BALL_PLAYER_CONTACT * BALL_PLAYER_CONTACT:
                _separate(pos, acc, counts, 0, i, BALL_PLAYER_CONTACT)
        for i in range(1, k):
            for j in range(i + 1, k):
                dx, dy = pos[j, 0] - pos[i, 0], pos[j, 1] - pos[i, 1]
                if dx * dx + dy * dy < PLAYER_PLAYER_CONTACT * PLAYER_PLAYER_CONTACT:
                    _separate(pos, acc, counts, i, j, PLAYER_PLAYER_CONTACT)
        if not counts.any():
            break
        for i in range(k):
            if counts[i] > 0:
                pos[i, 0], pos[i, 1] = acc[i, 0] / counts[i], acc[i, 1] / counts[i]
                collided[i] = True
    for i in range(k):
        if collided[i]:
            vel[i, 0] *= COLLISION_VELOCITY_FACTOR
            vel[i, 1] *= COLLISION_VELOCITY_FACTOR
