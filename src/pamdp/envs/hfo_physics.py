"""The physics and referee of Half Field Offense 1v0 for one game, in plain Python ``math``.

This is the reference implementation of ``shared/specs/hfo.md`` section 2 (cited below as "spec 2.x"):
rcssserver 15.2.2's movement, kick, dash, turn, stamina and collisions, the agent-side processing that
HFO's C++ agent (librcsc) applies to each low-level action before sending it, and HFO's referee. It is
written for one game at a time because a scalar ``math`` step is several times faster than NumPy on
length-1 arrays; ``hfo_vector.py`` is the batched NumPy twin, tested equal to this one step for step.

Frame (spec 2.1): the server's metres, goal centre at (52.5, 0), y grows "downwards", angles in
degrees normalised to (-180, 180], +90 along +y, positive relative angles on the agent's right.
"""

from __future__ import annotations

import math

import numpy as np

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

#: Actuator-noise draws are taken from the generator this many at a time.
NOISE_BLOCK = 1024

IN_GAME, GOAL, OUT_OF_BOUNDS, OUT_OF_TIME = 0, 1, 2, 3
STATUS_NAMES = ("IN_GAME", "GOAL", "OUT_OF_BOUNDS", "OUT_OF_TIME")

DASH, TURN, KICK = 0, 1, 2


def normalize_angle(deg: float) -> float:
    """An angle in degrees mapped to (-180, 180]."""
    return 180.0 - (180.0 - deg) % 360.0


def heading(x: float, y: float) -> float:
    """Direction of the vector (x, y) in degrees; 0 for the zero vector (spec 2.1)."""
    return math.degrees(math.atan2(y, x)) if (x != 0.0 or y != 0.0) else 0.0


def dash_direction_rate(direction: float) -> float:
    """Efficiency of a dash ``direction`` degrees off the body (already a multiple of 45; spec 2.4.3)."""
    d = abs(direction)
    if d <= 90.0:
        rate = SIDE_DASH_RATE + (1.0 - SIDE_DASH_RATE) * (1.0 - d / 90.0)
    else:
        rate = BACK_DASH_RATE - (BACK_DASH_RATE - SIDE_DASH_RATE) * (1.0 - (d - 90.0) / 90.0)
    return 0.0 if rate < 0.0 else 1.0 if rate > 1.0 else rate  # min(max(rate, 0), 1)


def round_dash_direction(direction: float) -> float:
    """Clamp to [-180, 180] and round to a multiple of 45 degrees, halves to even (spec 2.4.1)."""
    direction = -180.0 if direction < -180.0 else 180.0 if direction > 180.0 else direction
    return DASH_ANGLE_STEP * round(direction / DASH_ANGLE_STEP)


def norm(x: float, y: float) -> float:
    """Length of (x, y), computed as the batched env computes it (``np.hypot`` is slow)."""
    return math.sqrt(x * x + y * y)


#: Powers of ten 10**k for k in [-POW10_OFFSET, POW10_OFFSET], shared by both envs so that they round alike.
POW10_OFFSET = 300
POW10 = [10.0**k for k in range(-POW10_OFFSET, POW10_OFFSET + 1)]
LOG10_2 = math.log10(2.0)


def _fullstate_scales() -> dict[int, tuple[float, float, float]]:
    """For each binary exponent e (``math.frexp``) of a magnitude in [1e-200, 1e300): the power of ten
    10**(k + 1) bounding its decimal exponent estimate k = floor((e - 1) log10 2), and the two scales
    10**(5 - k) and 10**(4 - k) giving 6 significant digits below and at or above that bound."""
    table = {}
    for e in range(-664, 998):
        k = math.floor((e - 1) * LOG10_2)
        table[e] = (POW10[k + 1 + POW10_OFFSET], POW10[5 - k + POW10_OFFSET], POW10[4 - k + POW10_OFFSET])
    return table


_FULLSTATE_SCALES = _fullstate_scales()
#: ``y + 1.5 * 2**52 - 1.5 * 2**52`` is ``float(round(y))`` for |y| < 2**51: the sum falls where doubles
#: are the integers, so adding rounds to the nearest, ties to even, as ``round`` does, and subtracting is
#: exact (+0.0 for the ties at 0 too). Faster than ``round``, which also makes an int.
_ROUNDING_SHIFT = 1.5 * 2.0**52


def fullstate_value(x: float) -> float:
    """``x`` to the 6 significant digits in which the server prints fullstate information to the agent.

    HFO's agent sees only these digits: its features, its kickable test and its turn compensation are
    computed from them, and the recordings show rounding boundaries mattering (a turn moment 0.0005 from
    a multiple of 0.001 is rounded the other way when computed from the exact speed).
    """
    magnitude = abs(x)
    if magnitude < 1e-200:
        return x  # zero, or a decayed velocity too small to matter
    # Decimal exponent from the binary one (cheaper than log10, and identical in the batched env).
    bound, scale, scale_at_bound = _FULLSTATE_SCALES[math.frexp(magnitude)[1]]
    if magnitude >= bound:
        scale = scale_at_bound
    return round(x * scale) / scale


def round_command(value: float) -> float:
    """The 0.001 resolution of command arguments in the client's text protocol."""
    return round(value * 1000.0) / 1000.0


class HFOGame:
    """One HFO 1v0 game: the server's state, the agent's commands, one cycle of physics and the referee.

    Args:
        rng: the generator every random draw comes from (placements and actuator noise).
        deterministic: zero the actuator noise (player_rand, ball_rand, kick_rand), as HFO's
            ``--deterministic``.

    Attributes (server state, spec 2.11): player position ``px, py``, velocity ``pvx, pvy``, body angle
    ``body`` (degrees); stamina, effort, recovery, capacity; ball position ``bx, by`` and velocity
    ``bvx, bvy``; the referee's ``prev_bx, prev_by`` (ball at the end of the previous cycle),
    ``untouched`` and ``cycles`` counters and ``holder`` flag; this cycle's collision flags and whether
    the last action was actually sent (``last_action_ok``, feature 58).
    """

    def __init__(self, rng: np.random.Generator, deterministic: bool = False):
        self.set_rng(rng)
        self.player_rand = 0.0 if deterministic else PLAYER_RAND
        self.ball_rand = 0.0 if deterministic else BALL_RAND
        self.kick_rand = 0.0 if deterministic else KICK_RAND
        self.body = 0.0  # the very first episode faces the goal; later ones carry over (spec 2.7.3)
        self.place(0.0, 0.0, -10.0, 0.0)

    def set_rng(self, rng: np.random.Generator) -> None:
        """Draw from ``rng`` from now on (a seeded reset replaces the env's generator)."""
        self.rng = rng
        self._noise = []

    def _uniform(self, low: float, high: float) -> float:
        """One U(low, high) draw of actuator noise.

        Drawn in blocks from ``rng``: a scalar draw from a NumPy generator costs more than the rest of
        the step's physics. A block is kept reversed, so that each draw pops the next from its end.
        """
        noise = self._noise
        if not noise:
            noise = self._noise = self.rng.random(NOISE_BLOCK)[::-1].tolist()
        return low + (high - low) * noise.pop()

    # --- episode start (spec 2.7 "Reset") ---------------------------------------------------------
    def draw_placement(self) -> tuple[float, float, float, float]:
        """Ball and player positions from HFO's reset distribution, as ``(bx, by, px, py)``."""
        u = self.rng.random(5)
        bx = BALL_X_MAX * u[0]
        by = -BALL_Y_MAX + 2.0 * BALL_Y_MAX * u[1]
        ox, oy = START_OFFSETS[min(int(10.0 * u[2]), 9)]
        px = min(max(bx + START_SPREAD * (u[3] + ox), START_X_MIN), PITCH_HALF_LENGTH)
        py = min(max(by + START_SPREAD * (u[4] + oy), -BALL_Y_MAX), BALL_Y_MAX)
        return float(bx), float(by), float(px), float(py)

    def place(self, bx: float, by: float, px: float, py: float) -> None:
        """Start an episode with ball and player at rest at these positions; the body angle is kept.

        Mirrors what the agent first observes, two server cycles after HFO's placement (spec 2.7): full
        stamina, both referee counters at 2 (untouched at 0 if the ball is already in the kickable
        area), and a player-ball overlap already pushed apart.
        """
        self.px, self.py, self.pvx, self.pvy = px, py, 0.0, 0.0
        self.bx, self.by, self.bvx, self.bvy = bx, by, 0.0, 0.0
        self.stamina, self.effort, self.recovery = STAMINA_MAX, 1.0, 1.0
        self.capacity = STAMINA_CAPACITY
        self.pax = self.pay = self.bax = self.bay = 0.0  # accumulated accelerations
        if norm(bx - px, by - py) < TOUCH_DISTANCE:
            self._resolve_overlap()
        self.prev_bx, self.prev_by = self.bx, self.by
        near = norm(self.bx - self.px, self.by - self.py) <= KICKABLE_AREA
        self.holder = near
        self.untouched = 0 if near else COUNTERS_AT_FIRST_OBSERVATION
        self.cycles = COUNTERS_AT_FIRST_OBSERVATION
        self.collided_ball = self.collided_post = False
        self.last_action_ok = False  # HFO's interface took NOOPs between episodes (spec 2.8, f58)
        self.kicked = False
        self.sense()

    def sense(self) -> None:
        """Update ``seen``, the agent's world model: the state to 6 significant digits (fullstate).

        ``seen = (px, py, pvx, pvy, body, stamina, bx, by, bvx, bvy)``. :func:`fullstate_value` written
        out in the loop (ten calls a step cost a sixth of the step), rounding with ``_ROUNDING_SHIFT``:
        ``x * scale`` has 6 or 7 digits before the point, far below 2**51.
        """
        scales, frexp, shift = _FULLSTATE_SCALES, math.frexp, _ROUNDING_SHIFT
        seen = []
        for x in (self.px, self.py, self.pvx, self.pvy, self.body, self.stamina,
                  self.bx, self.by, self.bvx, self.bvy):  # fmt: skip
            magnitude = abs(x)
            if magnitude < 1e-200:
                seen.append(x)
                continue
            bound, scale, scale_at_bound = scales[frexp(magnitude)[1]]
            if magnitude >= bound:
                scale = scale_at_bound
            seen.append((x * scale + shift - shift) / scale)
        self.seen = tuple(seen)

    # --- agent-side processing and server-side commands (spec 2.3, 2.4) -------------------------
    def act(self, action: int, x0: float, x1: float) -> None:
        """Apply one agent action, ``DASH(x0, x1)``, ``TURN(x0)`` or ``KICK(x0, x1)``, as HFO's agent does."""
        if action == DASH:
            self.dash(x0, x1)
            sent = True
        elif action == TURN:
            self.turn(x0)
            sent = True
        else:
            sent = self.kick(x0, x1)
        self.kicked = action == KICK and sent
        self.last_action_ok = sent

    def agent_kickable(self) -> bool:
        """The HFO agent's kickable test (feature 12, and whether a KICK is sent).

        1.03 m between centres (spec 2.3), except on the cycle after a kick was sent, where the
        recording shows the server's 1.085 m (a ball 1.046 m away was reported kickable and kicked;
        one such case in the trace, and no counter-example).
        """
        seen = self.seen
        dx, dy = seen[6] - seen[0], seen[7] - seen[1]
        return math.sqrt(dx * dx + dy * dy) <= (KICKABLE_AREA if self.kicked else AGENT_KICKABLE_AREA)

    def dash(self, power: float, direction: float) -> None:
        """DASH(power, direction): librcsc's conservation of stamina and speed, then the server's dash.

        The agent's side works from what it sees (``seen``); the server's side from the true state.
        """
        power = -100.0 if power < -100.0 else 100.0 if power > 100.0 else power
        direction = round_dash_direction(direction)
        rate = dash_direction_rate(direction)
        _, _, svx, svy, body, stamina, _, _, _, _ = self.seen
        available = stamina + EXTRA_STAMINA
        if power >= 0.0 and power > available:
            power = available
        elif power < 0.0 and -2.0 * power > available:
            power = -available / 2.0
        accel_rate = rate * self.effort * DASH_POWER_RATE
        accel = abs(power * accel_rate)
        if norm(svx, svy) + accel > PLAYER_SPEED_MAX and accel_rate > 0.0:
            # Only possible, never binding, with player_decay 0.4; part of librcsc's dash (spec 2.3.3).
            phi = math.radians(body + direction + (180.0 if power < 0.0 else 0.0))
            ux, uy = math.cos(phi), math.sin(phi)
            if norm(svx + accel * ux, svy + accel * uy) > PLAYER_SPEED_MAX:
                v_par = svx * ux + svy * uy
                v_perp2 = svx**2 + svy**2 - v_par**2
                accel = max(math.sqrt(max(PLAYER_SPEED_MAX**2 - v_perp2, 0.0)) - v_par, 0.0)
                power = math.copysign(accel / accel_rate, power)
        self._server_dash(round_command(power), direction, rate)

    def _server_dash(self, power: float, direction: float, rate: float) -> None:
        """The server's dash (spec 2.4): pay stamina, then accelerate along body + direction."""
        backward = power < 0.0
        need, available = -2.0 * power if backward else power, self.stamina + EXTRA_STAMINA
        if available < need:
            need = available
        stamina = self.stamina - need
        self.stamina = stamina if stamina > 0.0 else 0.0
        power = -need / 2.0 if backward else need
        accel = abs(self.effort * power * rate * DASH_POWER_RATE)
        phi = math.radians(self.body + direction + (180.0 if backward else 0.0))
        self.pax += accel * math.cos(phi)
        self.pay += accel * math.sin(phi)

    def turn(self, direction: float) -> None:
        """TURN(direction): the agent pre-multiplies by the inertia factor the server divides by."""
        seen_speed = norm(self.seen[2], self.seen[3])
        moment = direction * (1.0 + INERTIA_MOMENT * seen_speed)
        moment = round_command(-180.0 if moment < -180.0 else 180.0 if moment > 180.0 else moment)
        inertia = 1.0 + INERTIA_MOMENT * norm(self.pvx, self.pvy)
        noise = 1.0 + self._uniform(-self.player_rand, self.player_rand) if self.player_rand else 1.0
        self.body = normalize_angle(self.body + noise * moment / inertia)

    def kick(self, power: float, direction: float) -> bool:
        """KICK(power, direction); returns False (and sends nothing) if the agent's test says unkickable."""
        if not self.agent_kickable():
            return False  # HFO sends (turn 0) instead: no effect on the state (spec 2.12.3)
        power = round_command(0.0 if power < 0.0 else 100.0 if power > 100.0 else power)
        direction = -180.0 if direction < -180.0 else 180.0 if direction > 180.0 else direction
        dx, dy = self.bx - self.px, self.by - self.py
        dist = norm(dx, dy)
        if dist > KICKABLE_AREA:
            return True
        dir_diff = abs(normalize_angle(heading(dx, dy) - self.body)) / 180.0  # delta / pi
        gap = (dist - TOUCH_DISTANCE) / KICKABLE_MARGIN
        effective = power * KICK_POWER_RATE * (1.0 - 0.25 * dir_diff - 0.25 * gap)
        phi = math.radians(self.body + direction)
        kx, ky = effective * math.cos(phi), effective * math.sin(phi)
        if self.kick_rand and power > 0.0:
            pos_rate = 0.5 + 0.25 * (dir_diff + gap)
            speed_rate = 0.5 + 0.5 * norm(self.bvx, self.bvy) / (BALL_SPEED_MAX * BALL_DECAY)
            max_noise = self.kick_rand * (power / 100.0) * (pos_rate + speed_rate)
            length, angle = self._uniform(0.0, max_noise), self._uniform(-math.pi, math.pi)
            kx += length * math.cos(angle)
            ky += length * math.sin(angle)
        self.bax += kx
        self.bay += ky
        return True

    # --- one simulation cycle (spec 2.5) ----------------------------------------------------------
    def advance(self) -> int:
        """Run one server cycle after the command: movement, collisions, referee, stamina.

        Returns the referee's status (``IN_GAME``, ``GOAL``, ``OUT_OF_BOUNDS`` or ``OUT_OF_TIME``).
        """
        self.px, self.py, self.pvx, self.pvy, post_p = self._move(
            self.px, self.py, self.pvx, self.pvy, self.pax, self.pay,
            PLAYER_ACCEL_MAX, PLAYER_SPEED_MAX, self.player_rand, PLAYER_DECAY, PLAYER_SIZE,
        )  # fmt: skip
        self.bx, self.by, self.bvx, self.bvy, _ = self._move(
            self.bx, self.by, self.bvx, self.bvy, self.bax, self.bay,
            BALL_ACCEL_MAX, BALL_SPEED_MAX, self.ball_rand, BALL_DECAY, BALL_SIZE,
        )  # fmt: skip
        self.pax = self.pay = self.bax = self.bay = 0.0
        self.collided_post = post_p
        dx, dy = self.bx - self.px, self.by - self.py
        self.collided_ball = math.sqrt(dx * dx + dy * dy) < TOUCH_DISTANCE
        if self.collided_ball:
            self._resolve_overlap()
        status = self._referee()
        self._update_stamina()
        self.sense()
        return status

    def _move(self, x, y, vx, vy, ax, ay, accel_max, speed_max, rand, decay, radius):
        """Spec 2.5.1 for one object; returns the new position, velocity and the post-collision flag."""
        sqrt, uniform = math.sqrt, self._uniform
        if ax != 0.0 or ay != 0.0:
            a = sqrt(ax * ax + ay * ay)
            shrink = accel_max / a if a > accel_max else 1.0
            vx, vy = vx + ax * shrink, vy + ay * shrink
            speed = sqrt(vx * vx + vy * vy)
            shrink = speed_max / speed if speed > speed_max else 1.0
            vx, vy = vx * shrink, vy * shrink
        if rand and (vx != 0.0 or vy != 0.0):
            length = uniform(0.0, rand * sqrt(vx * vx + vy * vy))
            angle = uniform(-math.pi, math.pi)
            vx, vy = vx + length * math.cos(angle), vy + length * math.sin(angle)
        reach = GOAL_POST_RADIUS + radius
        if abs(abs(x) - POST_X) > reach + abs(vx) or abs(abs(y) - POST_Y) > reach + abs(vy):
            return x + vx, y + vy, vx * decay, vy * decay, False  # post_collisions' common case, without its call
        x, y, vx, vy, collided = post_collisions(x, y, vx, vy, radius)
        return x, y, vx * decay, vy * decay, collided

    def _resolve_overlap(self) -> None:
        """Push player and ball apart about their midpoint to touching distance; both velocities * -0.1."""
        dx, dy = self.bx - self.px, self.by - self.py
        dist = norm(dx, dy)
        if dist > 0.0:
            nx, ny = dx / dist, dy / dist
        else:
            angle = self._uniform(-math.pi, math.pi)
            nx, ny = math.cos(angle), math.sin(angle)
        mx, my = 0.5 * (self.bx + self.px), 0.5 * (self.by + self.py)
        half = 0.5 * TOUCH_DISTANCE + CONTACT_EPSILON
        self.bx, self.by = mx + half * nx, my + half * ny
        self.px, self.py = mx - half * nx, my - half * ny
        self.pvx, self.pvy = self.pvx * COLLISION_VELOCITY_FACTOR, self.pvy * COLLISION_VELOCITY_FACTOR
        self.bvx, self.bvy = self.bvx * COLLISION_VELOCITY_FACTOR, self.bvy * COLLISION_VELOCITY_FACTOR

    def _referee(self) -> int:
        """HFO's per-cycle referee for 1v0 (spec 2.7), with the counters as the agent sees them."""
        bx, by, prev_x, prev_y = self.bx, self.by, self.prev_bx, self.prev_by
        status = IN_GAME
        self.cycles += 1
        if goal_crossed(prev_x, prev_y, bx, by):
            status = GOAL
        elif prev_x < 0.0 or prev_x > PITCH_HALF_LENGTH or abs(prev_y) > PITCH_HALF_WIDTH:
            status = OUT_OF_BOUNDS  # judged on the previous cycle's ball: one step late
        elif self.untouched > UNTOUCHED_TIME or self.cycles > FRAMES_PER_TRIAL:
            status = OUT_OF_TIME
        else:
            self.untouched += 1
            dx, dy = bx - self.px, by - self.py
            if math.sqrt(dx * dx + dy * dy) <= KICKABLE_AREA:
                self.holder = True
                self.untouched = 0
        self.prev_bx, self.prev_by = bx, by
        return status

    def _update_stamina(self) -> None:
        """Spec 2.6: recovery and effort decay below 30% stamina, effort recovers above 60%.

        The clips are conditionals with the comparisons of ``min`` and ``max``, whose calls cost more.
        """
        stamina = self.stamina
        if stamina <= RECOVER_DEC_THR * STAMINA_MAX:
            recovery = self.recovery - RECOVER_DEC
            self.recovery = recovery if recovery > RECOVER_MIN else RECOVER_MIN
        if stamina <= EFFORT_DEC_THR * STAMINA_MAX:
            effort = self.effort - EFFORT_DEC
            self.effort = effort if effort > EFFORT_MIN else EFFORT_MIN
        if stamina >= EFFORT_INC_THR * STAMINA_MAX and self.effort < EFFORT_MAX:
            effort = self.effort + EFFORT_INC
            self.effort = effort if effort < EFFORT_MAX else EFFORT_MAX
        inc = self.recovery * STAMINA_INC_MAX
        if STAMINA_MAX - stamina < inc:
            inc = STAMINA_MAX - stamina
        if self.capacity < inc:
            inc = self.capacity
        self.stamina = stamina + inc
        self.capacity -= inc


def goal_crossed(prev_x: float, prev_y: float, x: float, y: float) -> bool:
    """Did the ball's centre cross x = 52.585 between the goal posts this cycle (spec 2.7.1)?"""
    if not (x > GOAL_LINE_X and prev_x <= GOAL_LINE_X and prev_x != x):
        return False
    if abs(prev_y) > POST_Y and prev_x > PITCH_HALF_LENGTH:
        return False
    y_at_line = prev_y + (y - prev_y) * (GOAL_LINE_X - prev_x) / (x - prev_x)
    return abs(y_at_line) <= POST_Y


def post_collisions(x: float, y: float, vx: float, vy: float, radius: float):
    """Move an object of ``radius`` by ``(vx, vy)``, bouncing elastically off the goal posts (spec 2.5.1.4).

    Returns ``(x, y, vx, vy, collided)`` with the end position and the (undecayed) velocity.
    Only the post nearest to the object (by the signs of x and y) can be hit, at the start or at the end
    of the path; an object already inside a post disc is first pushed out radially.
    """
    reach = GOAL_POST_RADIUS + radius
    if abs(abs(x) - POST_X) > reach + abs(vx) or abs(abs(y) - POST_Y) > reach + abs(vy):
        return x + vx, y + vy, vx, vy, False  # far from every post: the common case
    collided = False
    cx, cy = math.copysign(POST_X, x), math.copysign(POST_Y, y)
    dx, dy = x - cx, y - cy
    dist = norm(dx, dy)
    if dist < reach:
        nx, ny = (dx / dist, dy / dist) if dist > 0.0 else (math.copysign(1.0, x), 0.0)
        x, y = cx + nx * (reach + CONTACT_EPSILON), cy + ny * (reach + CONTACT_EPSILON)
        v_n = vx * nx + vy * ny
        if v_n < 0.0:
            vx, vy = vx - 2.0 * v_n * nx, vy - 2.0 * v_n * ny
        collided = True
    # Sweep the path; each bounce reflects the rest of the path and the velocity across the tangent.
    path_x, path_y = vx, vy
    for _ in range(3):
        hit = None
        for cx, cy in {
            (math.copysign(POST_X, x), math.copysign(POST_Y, y)),
            (math.copysign(POST_X, x + path_x), math.copysign(POST_Y, y + path_y)),
        }:
            t = _segment_circle_entry(x, y, path_x, path_y, cx, cy, reach)
            if t is not None and (hit is None or t < hit[0]):
                hit = (t, cx, cy)
        if hit is None:
            break
        t, cx, cy = hit
        x, y = x + t * path_x, y + t * path_y
        nx, ny = (x - cx) / reach, (y - cy) / reach
        x, y = x + CONTACT_EPSILON * nx, y + CONTACT_EPSILON * ny
        rest_x, rest_y = (1.0 - t) * path_x, (1.0 - t) * path_y
        r_n, v_n = rest_x * nx + rest_y * ny, vx * nx + vy * ny
        path_x, path_y = rest_x - 2.0 * r_n * nx, rest_y - 2.0 * r_n * ny
        vx, vy = vx - 2.0 * v_n * nx, vy - 2.0 * v_n * ny
        collided = True
    return x + path_x, y + path_y, vx, vy, collided


def _segment_circle_entry(x, y, path_x, path_y, cx, cy, reach):
    """Fraction t in [0, 1] at which the path (x, y) + t * path enters the disc, or None."""
    a = path_x * path_x + path_y * path_y
    if a == 0.0:
        return None
    fx, fy = x - cx, y - cy
    b = 2.0 * (fx * path_x + fy * path_y)
    c = fx * fx + fy * fy - reach * reach
    disc = b * b - 4.0 * a * c
    if b >= 0.0 or disc <= 0.0:
        return None  # moving away from the centre, or missing the disc
    t = (-b - math.sqrt(disc)) / (2.0 * a)
    return t if 0.0 <= t <= 1.0 else None
