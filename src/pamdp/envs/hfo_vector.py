"""N games of HFO 1v0 stepped at once with NumPy: the batched twin of ``hfo_physics.HFOGame``.

Every line of the scalar simulation has its masked, array-wide counterpart here, in the same order, so
that with the actuator noise off the two agree step for step (``tests/test_hfo_vector.py``). Rare
branches (goal posts, the speed caps of the dash) run on the subset of games that need them.
"""

from __future__ import annotations

import gymnasium
import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode
from gymnasium.vector.utils import batch_space

from pamdp.envs import hfo_physics as phys
from pamdp.envs.hfo_features import PROFILES, low_level_features, shaped_reward
from pamdp.envs.hfo_interface import (
    ACTION_FORM,
    PARAM_SIZES,
    check_options,
    draw_half_field,
    hfo_action_space,
    parse_reset_options,
)

_STATUS_NAMES = np.array(phys.STATUS_NAMES)


def normalize_angle(deg):
    """Angles in degrees mapped to (-180, 180]."""
    return 180.0 - np.mod(180.0 - deg, 360.0)


def norm(x, y):
    """Lengths of the vectors (x, y), as ``hfo_physics.norm``."""
    return np.sqrt(x * x + y * y)


_POW10 = np.array(phys.POW10)


def fullstate_values(x):
    """:func:`hfo_physics.fullstate_value` over an array: 6 significant digits."""
    magnitude = np.abs(x)
    tiny = magnitude < 1e-200
    exponent = np.floor((np.frexp(magnitude)[1] - 1) * phys.LOG10_2).astype(np.int64)
    exponent = np.clip(exponent, -phys.POW10_OFFSET + 6, phys.POW10_OFFSET - 6)
    exponent += magnitude >= _POW10[exponent + 1 + phys.POW10_OFFSET]
    scale = _POW10[5 - exponent + phys.POW10_OFFSET]
    return np.where(tiny, x, np.rint(x * scale) / scale)


def dash_direction_rate(direction):
    """Efficiency of dashes ``direction`` degrees off the body (multiples of 45; spec 2.4.3)."""
    d = np.abs(direction)
    side = phys.SIDE_DASH_RATE + (1.0 - phys.SIDE_DASH_RATE) * (1.0 - d / 90.0)
    back = phys.BACK_DASH_RATE - (phys.BACK_DASH_RATE - phys.SIDE_DASH_RATE) * (1.0 - (d - 90.0) / 90.0)
    return np.clip(np.where(d <= 90.0, side, back), 0.0, 1.0)


def round_command(value):
    """The 0.001 resolution of command arguments."""
    return np.rint(value * 1000.0) / 1000.0


def goal_crossed(prev_x, prev_y, x, y):
    """:func:`hfo_physics.goal_crossed` over arrays."""
    crossing = (x > phys.GOAL_LINE_X) & (prev_x <= phys.GOAL_LINE_X) & (prev_x != x)
    crossing &= ~((np.abs(prev_y) > phys.POST_Y) & (prev_x > phys.PITCH_HALF_LENGTH))
    span = np.where(crossing, x - prev_x, 1.0)
    y_at_line = prev_y + (y - prev_y) * (phys.GOAL_LINE_X - prev_x) / span
    return crossing & (np.abs(y_at_line) <= phys.POST_Y)


def _segment_circle_entry(x, y, path_x, path_y, cx, cy, reach):
    """Per game, the fraction t in [0, 1] at which the path enters the disc, or +inf."""
    a = path_x * path_x + path_y * path_y
    fx, fy = x - cx, y - cy
    b = 2.0 * (fx * path_x + fy * path_y)
    c = fx * fx + fy * fy - reach * reach
    disc = b * b - 4.0 * a * c
    ok = (a != 0.0) & (b < 0.0) & (disc > 0.0)
    t = (-b - np.sqrt(np.where(ok, disc, 0.0))) / (2.0 * np.where(ok, a, 1.0))
    return np.where(ok & (t >= 0.0) & (t <= 1.0), t, np.inf)


def post_collisions(x, y, vx, vy, radius):
    """:func:`hfo_physics.post_collisions` over arrays; the sweep runs only on games near a post."""
    reach = phys.GOAL_POST_RADIUS + radius
    near = (np.abs(np.abs(x) - phys.POST_X) <= reach + np.abs(vx)) & (
        np.abs(np.abs(y) - phys.POST_Y) <= reach + np.abs(vy)
    )
    collided = np.zeros(x.shape, dtype=bool)
    if not near.any():
        return x + vx, y + vy, vx, vy, collided
    i = np.flatnonzero(near)
    sx, sy, svx, svy = x[i], y[i], vx[i], vy[i]
    cx, cy = np.copysign(phys.POST_X, sx), np.copysign(phys.POST_Y, sy)
    dx, dy = sx - cx, sy - cy
    dist = norm(dx, dy)
    inside = dist < reach
    safe = np.where(dist > 0.0, dist, 1.0)
    nx = np.where(dist > 0.0, dx / safe, np.copysign(1.0, sx))
    ny = np.where(dist > 0.0, dy / safe, 0.0)
    sx = np.where(inside, cx + nx * (reach + phys.CONTACT_EPSILON), sx)
    sy = np.where(inside, cy + ny * (reach + phys.CONTACT_EPSILON), sy)
    v_n = svx * nx + svy * ny
    flip = inside & (v_n < 0.0)
    svx, svy = np.where(flip, svx - 2.0 * v_n * nx, svx), np.where(flip, svy - 2.0 * v_n * ny, svy)
    hit_any = inside.copy()
    path_x, path_y = svx.copy(), svy.copy()
    for _ in range(3):
        t = np.full(sx.shape, np.inf)
        hit_cx, hit_cy = np.zeros(sx.shape), np.zeros(sx.shape)
        for px, py in ((sx, sy), (sx + path_x, sy + path_y)):
            cx, cy = np.copysign(phys.POST_X, px), np.copysign(phys.POST_Y, py)
            t_c = _segment_circle_entry(sx, sy, path_x, path_y, cx, cy, reach)
            better = t_c < t
            t, hit_cx, hit_cy = np.where(better, t_c, t), np.where(better, cx, hit_cx), np.where(better, cy, hit_cy)
        hit = np.isfinite(t)
        if not hit.any():
            break
        t = np.where(hit, t, 0.0)
        qx, qy = sx + t * path_x, sy + t * path_y
        nx, ny = (qx - hit_cx) / reach, (qy - hit_cy) / reach
        qx, qy = qx + phys.CONTACT_EPSILON * nx, qy + phys.CONTACT_EPSILON * ny
        rest_x, rest_y = (1.0 - t) * path_x, (1.0 - t) * path_y
        r_n, v_n = rest_x * nx + rest_y * ny, svx * nx + svy * ny
        sx, sy = np.where(hit, qx, sx), np.where(hit, qy, sy)
        path_x = np.where(hit, rest_x - 2.0 * r_n * nx, path_x)
        path_y = np.where(hit, rest_y - 2.0 * r_n * ny, path_y)
        svx, svy = np.where(hit, svx - 2.0 * v_n * nx, svx), np.where(hit, svy - 2.0 * v_n * ny, svy)
        hit_any |= hit
    end_x, end_y, vx, vy = x + vx, y + vy, vx.copy(), vy.copy()
    end_x[i], end_y[i], vx[i], vy[i], collided[i] = sx + path_x, sy + path_y, svx, svy, hit_any
    return end_x, end_y, vx, vy, collided


class HalfFieldOffenseVectorEnv(gymnasium.vector.VectorEnv):
    """``num_envs`` HFO 1v0 games in NumPy, with Gymnasium's next-step autoreset.

    Takes the keyword arguments of :class:`pamdp.envs.hfo.HalfFieldOffenseEnv`. Actions are the
    ``batch_space`` of the scalar action space: ``(a[N], (dash[N, 2], turn[N, 1], kick[N, 2]))``.
    A game that ended on the previous step is reset instead of stepped (its action is ignored) and
    returns its first observation with reward 0. ``infos`` holds ``status`` (strings) and ``step``
    per game. ``reset(options=...)`` takes the scalar env's options, applied to every game (each
    value may also be given per game, with a leading axis of size N).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 10, "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(
        self,
        num_envs: int = 1,
        render_mode: str | None = None,
        profile: str = "hfo2017",
        deterministic: bool = False,
        timeout_terminal: bool = False,
        body_reset: str = "carry",
        first_step_reward: bool = False,
        terminal_deltas: bool = False,
    ):
        check_options(profile, body_reset)
        if not (isinstance(num_envs, int | np.integer) and num_envs >= 1):
            raise ValueError(f"num_envs={num_envs!r}; expected a positive integer")
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode={render_mode!r}; expected None or 'rgb_array'")
        self.num_envs = int(num_envs)
        self.render_mode = render_mode
        self.profile = PROFILES[profile]
        self.deterministic = bool(deterministic)
        self.timeout_terminal = bool(timeout_terminal)
        self.body_reset = body_reset
        self.first_step_reward = bool(first_step_reward)
        self.terminal_deltas = bool(terminal_deltas)
        self.player_rand = 0.0 if deterministic else phys.PLAYER_RAND
        self.ball_rand = 0.0 if deterministic else phys.BALL_RAND
        self.kick_rand = 0.0 if deterministic else phys.KICK_RAND
        self.single_observation_space = spaces.Box(-1.0, 1.0, (self.profile.n_features,), dtype=np.float32)
        self.single_action_space = hfo_action_space()
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        n = self.num_envs
        self.body = np.zeros(n)  # the first episode faces the goal, later ones carry over
        self._needs_reset = np.ones(n, dtype=bool)

    # --- Gymnasium API ------------------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        if seed is not None:
            self.body[:] = 0.0  # a new server run, as in the scalar env
        placement = _per_game_options(options, self.num_envs)
        self._place(np.ones(self.num_envs, dtype=bool), placement)
        self._needs_reset[:] = False
        return self._features.astype(np.float32), self._infos()

    def step(self, actions):
        if not hasattr(self, "px"):
            raise gymnasium.error.ResetNeeded("call reset() before step()")
        a, x0, x1 = self._parse_actions(actions)
        resetting = self._needs_reset.copy()
        active = ~resetting
        self._act(a, x0, x1, active)
        status = self._advance()
        self.steps += 1
        prev, features = self._features, self._observe()
        goal = status == phys.GOAL
        terminal = status != phys.IN_GAME
        reward, paid = shaped_reward(prev, features, self.holder, ~self.bonus_paid, goal)
        # Quirks of H&S's code (see HalfFieldOffenseEnv): only the goal bonus on these transitions.
        plain = (terminal & (not self.terminal_deltas)) | ((self.steps == 1) & (not self.first_step_reward))
        reward = np.where(plain, np.where(goal, 5.0, 0.0), reward)
        self.bonus_paid |= paid & ~plain
        self._features = features
        timeout = status == phys.OUT_OF_TIME
        terminated = goal | (status == phys.OUT_OF_BOUNDS) | (timeout & self.timeout_terminal)
        truncated = timeout & (not self.timeout_terminal)
        self.status = status
        if resetting.any():
            self._place(resetting, {})
            reward[resetting] = 0.0
            terminated[resetting] = truncated[resetting] = False
        self._needs_reset = terminated | truncated
        return self._features.astype(np.float32), reward, terminated, truncated, self._infos()

    def render(self):
        if self.render_mode != "rgb_array":
            return None
        return tuple(
            draw_half_field(self.px[i], self.py[i], self.body[i], self.bx[i], self.by[i]) for i in range(self.num_envs)
        )

    # --- episode start ------------------------------------------------------------------------
    def _place(self, mask, placement: dict) -> None:
        """Start new episodes in the games of ``mask`` (draws as ``HFOGame.draw_placement``/``place``)."""
        idx = np.flatnonzero(mask)
        k = idx.size
        u = self.np_random.random((k, 5))
        bx = phys.BALL_X_MAX * u[:, 0]
        by = -phys.BALL_Y_MAX + 2.0 * phys.BALL_Y_MAX * u[:, 1]
        offsets = phys.START_OFFSETS[np.minimum((10.0 * u[:, 2]).astype(int), 9)]
        px = np.clip(bx + phys.START_SPREAD * (u[:, 3] + offsets[:, 0]), phys.START_X_MIN, phys.PITCH_HALF_LENGTH)
        py = np.clip(by + phys.START_SPREAD * (u[:, 4] + offsets[:, 1]), -phys.BALL_Y_MAX, phys.BALL_Y_MAX)
        body = self.body[idx]
        if self.body_reset == "uniform":
            body = normalize_angle(360.0 * self.np_random.random(k) - 180.0)
        if "ball" in placement:
            bx, by = placement["ball"][idx, 0], placement["ball"][idx, 1]
        if "player" in placement:
            px, py = placement["player"][idx, 0], placement["player"][idx, 1]
        if "body" in placement:
            body = normalize_angle(placement["body"][idx])
        if not hasattr(self, "px"):
            self._allocate()
        self.px[idx], self.py[idx], self.pvx[idx], self.pvy[idx] = px, py, 0.0, 0.0
        self.bx[idx], self.by[idx], self.bvx[idx], self.bvy[idx] = bx, by, 0.0, 0.0
        self.body[idx] = body
        self.stamina[idx], self.effort[idx], self.recovery[idx] = phys.STAMINA_MAX, 1.0, 1.0
        self.capacity[idx] = phys.STAMINA_CAPACITY
        overlap = np.zeros(self.num_envs, dtype=bool)
        overlap[idx] = norm(bx - px, by - py) < phys.TOUCH_DISTANCE
        if overlap.any():
            self._resolve_overlap(overlap)
        self.prev_bx[idx], self.prev_by[idx] = self.bx[idx], self.by[idx]
        near = norm(self.bx[idx] - self.px[idx], self.by[idx] - self.py[idx]) <= phys.KICKABLE_AREA
        self.holder[idx] = near
        self.untouched[idx] = np.where(near, 0, phys.COUNTERS_AT_FIRST_OBSERVATION)
        self.cycles[idx] = phys.COUNTERS_AT_FIRST_OBSERVATION
        self.collided_ball[idx] = self.collided_post[idx] = False
        self.last_action_ok[idx] = self.kicked[idx] = False
        self.steps[idx] = 0
        self.bonus_paid[idx] = False
        self.status[idx] = phys.IN_GAME
        self._sense()
        if not hasattr(self, "_features"):
            self._features = np.zeros((self.num_envs, self.profile.n_features))
        self._features[idx] = self._observe(idx)

    def _allocate(self) -> None:
        n = self.num_envs
        for name in ("px", "py", "pvx", "pvy", "bx", "by", "bvx", "bvy", "prev_bx", "prev_by"):
            setattr(self, name, np.zeros(n))
        for name in ("stamina", "effort", "recovery", "capacity"):
            setattr(self, name, np.zeros(n))
        for name in ("holder", "kicked", "last_action_ok", "collided_ball", "collided_post", "bonus_paid"):
            setattr(self, name, np.zeros(n, dtype=bool))
        self.untouched = np.zeros(n, dtype=np.int64)
        self.cycles = np.zeros(n, dtype=np.int64)
        self.steps = np.zeros(n, dtype=np.int64)
        self.status = np.zeros(n, dtype=np.int64)

    # --- agent-side processing and server-side commands (spec 2.3, 2.4) -------------------------
    def _agent_kickable(self):
        limit = np.where(self.kicked, phys.KICKABLE_AREA, phys.AGENT_KICKABLE_AREA)
        return norm(self.seen[6] - self.seen[0], self.seen[7] - self.seen[1]) <= limit

    def _act(self, a, x0, x1, active) -> None:
        """Apply the agents' DASH / TURN / KICK to the ``active`` games (``HFOGame.act``)."""
        dash, turn = active & (a == phys.DASH), active & (a == phys.TURN)
        kick = active & (a == phys.KICK) & self._agent_kickable()
        self.pax, self.pay = np.zeros(self.num_envs), np.zeros(self.num_envs)
        self.bax, self.bay = np.zeros(self.num_envs), np.zeros(self.num_envs)
        if dash.any():
            self._dash(x0, x1, dash)
        if turn.any():
            self._turn(x0, turn)
        if kick.any():
            self._kick(x0, x1, kick)
        self.kicked = kick
        self.last_action_ok = dash | turn | kick

    def _dash(self, power, direction, mask) -> None:
        power = np.clip(power, -100.0, 100.0)
        direction = phys.DASH_ANGLE_STEP * np.rint(np.clip(direction, -180.0, 180.0) / phys.DASH_ANGLE_STEP)
        rate = dash_direction_rate(direction)
        svx, svy, s_body, s_stamina = self.seen[2], self.seen[3], self.seen[4], self.seen[5]
        available = s_stamina + phys.EXTRA_STAMINA
        power = np.where(
            power >= 0.0, np.minimum(power, available), np.where(-2.0 * power > available, -available / 2.0, power)
        )
        accel_rate = rate * self.effort * phys.DASH_POWER_RATE
        accel = np.abs(power * accel_rate)
        capped = mask & (norm(svx, svy) + accel > phys.PLAYER_SPEED_MAX) & (accel_rate > 0.0)
        if capped.any():  # librcsc's speed-cap conservation; never binding with player_decay 0.4
            phi = np.radians(s_body + direction + np.where(power < 0.0, 180.0, 0.0))
            ux, uy = np.cos(phi), np.sin(phi)
            capped &= norm(svx + accel * ux, svy + accel * uy) > phys.PLAYER_SPEED_MAX
            v_par = svx * ux + svy * uy
            v_perp2 = svx**2 + svy**2 - v_par**2
            new_accel = np.maximum(np.sqrt(np.maximum(phys.PLAYER_SPEED_MAX**2 - v_perp2, 0.0)) - v_par, 0.0)
            safe_rate = np.where(accel_rate > 0.0, accel_rate, 1.0)
            power = np.where(capped, np.copysign(new_accel / safe_rate, power), power)
        power = round_command(power)
        # server side
        backward = power < 0.0
        need = np.minimum(np.where(backward, -2.0 * power, power), self.stamina + phys.EXTRA_STAMINA)
        self.stamina = np.where(mask, np.maximum(0.0, self.stamina - need), self.stamina)
        power = np.where(backward, -need / 2.0, need)
        accel = np.abs(self.effort * power * rate * phys.DASH_POWER_RATE)
        phi = np.radians(self.body + direction + np.where(backward, 180.0, 0.0))
        self.pax = np.where(mask, self.pax + accel * np.cos(phi), self.pax)
        self.pay = np.where(mask, self.pay + accel * np.sin(phi), self.pay)

    def _turn(self, direction, mask) -> None:
        seen_speed = norm(self.seen[2], self.seen[3])
        moment = round_command(np.clip(direction * (1.0 + phys.INERTIA_MOMENT * seen_speed), -180.0, 180.0))
        inertia = 1.0 + phys.INERTIA_MOMENT * norm(self.pvx, self.pvy)
        noise = 1.0
        if self.player_rand:
            noise = 1.0 + self.np_random.uniform(-self.player_rand, self.player_rand, self.num_envs)
        self.body = np.where(mask, normalize_angle(self.body + noise * moment / inertia), self.body)

    def _kick(self, power, direction, mask) -> None:
        power = round_command(np.clip(power, 0.0, 100.0))
        direction = np.clip(direction, -180.0, 180.0)
        dx, dy = self.bx - self.px, self.by - self.py
        dist = norm(dx, dy)
        mask = mask & (dist <= phys.KICKABLE_AREA)
        dir_diff = np.abs(normalize_angle(np.degrees(np.arctan2(dy, dx)) - self.body)) / 180.0
        gap = (dist - phys.TOUCH_DISTANCE) / phys.KICKABLE_MARGIN
        effective = power * phys.KICK_POWER_RATE * (1.0 - 0.25 * dir_diff - 0.25 * gap)
        phi = np.radians(self.body + direction)
        kx, ky = effective * np.cos(phi), effective * np.sin(phi)
        if self.kick_rand:
            pos_rate = 0.5 + 0.25 * (dir_diff + gap)
            speed_rate = 0.5 + 0.5 * norm(self.bvx, self.bvy) / (phys.BALL_SPEED_MAX * phys.BALL_DECAY)
            max_noise = self.kick_rand * (power / 100.0) * (pos_rate + speed_rate)
            length = self.np_random.uniform(0.0, 1.0, self.num_envs) * max_noise
            angle = self.np_random.uniform(-np.pi, np.pi, self.num_envs)
            kx, ky = kx + length * np.cos(angle), ky + length * np.sin(angle)
        self.bax = np.where(mask, self.bax + kx, self.bax)
        self.bay = np.where(mask, self.bay + ky, self.bay)

    # --- one simulation cycle (spec 2.5) ----------------------------------------------------------
    def _advance(self):
        self.px, self.py, self.pvx, self.pvy, self.collided_post = self._move(
            self.px, self.py, self.pvx, self.pvy, self.pax, self.pay,
            phys.PLAYER_ACCEL_MAX, phys.PLAYER_SPEED_MAX, self.player_rand, phys.PLAYER_DECAY, phys.PLAYER_SIZE,
        )  # fmt: skip
        self.bx, self.by, self.bvx, self.bvy, _ = self._move(
            self.bx, self.by, self.bvx, self.bvy, self.bax, self.bay,
            phys.BALL_ACCEL_MAX, phys.BALL_SPEED_MAX, self.ball_rand, phys.BALL_DECAY, phys.BALL_SIZE,
        )  # fmt: skip
        self.collided_ball = norm(self.bx - self.px, self.by - self.py) < phys.TOUCH_DISTANCE
        if self.collided_ball.any():
            self._resolve_overlap(self.collided_ball)
        status = self._referee()
        self._update_stamina()
        self._sense()
        return status

    def _move(self, x, y, vx, vy, ax, ay, accel_max, speed_max, rand, decay, radius):
        accelerating = (ax != 0.0) | (ay != 0.0)
        a = norm(ax, ay)
        shrink = np.where(a > accel_max, accel_max / np.where(a > 0.0, a, 1.0), 1.0)
        vx, vy = vx + ax * shrink, vy + ay * shrink
        speed = norm(vx, vy)
        shrink = np.where(accelerating & (speed > speed_max), speed_max / np.where(speed > 0.0, speed, 1.0), 1.0)
        vx, vy = vx * shrink, vy * shrink
        if rand:
            length = self.np_random.uniform(0.0, 1.0, self.num_envs) * rand * norm(vx, vy)
            angle = self.np_random.uniform(-np.pi, np.pi, self.num_envs)
            vx, vy = vx + length * np.cos(angle), vy + length * np.sin(angle)
        x, y, vx, vy, collided = post_collisions(x, y, vx, vy, radius)
        return x, y, vx * decay, vy * decay, collided

    def _resolve_overlap(self, mask) -> None:
        dx, dy = self.bx - self.px, self.by - self.py
        dist = norm(dx, dy)
        angle = self.np_random.uniform(-np.pi, np.pi, self.num_envs) if (mask & (dist == 0.0)).any() else 0.0
        safe = np.where(dist > 0.0, dist, 1.0)
        nx = np.where(dist > 0.0, dx / safe, np.cos(angle))
        ny = np.where(dist > 0.0, dy / safe, np.sin(angle))
        mx, my = 0.5 * (self.bx + self.px), 0.5 * (self.by + self.py)
        half = 0.5 * phys.TOUCH_DISTANCE + phys.CONTACT_EPSILON
        self.bx, self.by = np.where(mask, mx + half * nx, self.bx), np.where(mask, my + half * ny, self.by)
        self.px, self.py = np.where(mask, mx - half * nx, self.px), np.where(mask, my - half * ny, self.py)
        factor = np.where(mask, phys.COLLISION_VELOCITY_FACTOR, 1.0)
        self.pvx, self.pvy, self.bvx, self.bvy = (
            self.pvx * factor,
            self.pvy * factor,
            self.bvx * factor,
            self.bvy * factor,
        )

    def _referee(self):
        self.cycles += 1
        prev_x, prev_y = self.prev_bx, self.prev_by
        goal = goal_crossed(prev_x, prev_y, self.bx, self.by)
        out = ~goal & ((prev_x < 0.0) | (prev_x > phys.PITCH_HALF_LENGTH) | (np.abs(prev_y) > phys.PITCH_HALF_WIDTH))
        timeout = ~goal & ~out & ((self.untouched > phys.UNTOUCHED_TIME) | (self.cycles > phys.FRAMES_PER_TRIAL))
        in_game = ~(goal | out | timeout)
        touch = in_game & (norm(self.bx - self.px, self.by - self.py) <= phys.KICKABLE_AREA)
        self.untouched = np.where(touch, 0, np.where(in_game, self.untouched + 1, self.untouched))
        self.holder |= touch
        self.prev_bx, self.prev_by = self.bx.copy(), self.by.copy()
        status = np.full(self.num_envs, phys.IN_GAME)
        status[goal], status[out], status[timeout] = phys.GOAL, phys.OUT_OF_BOUNDS, phys.OUT_OF_TIME
        return status

    def _update_stamina(self) -> None:
        low = self.stamina <= phys.RECOVER_DEC_THR * phys.STAMINA_MAX
        self.recovery = np.where(low, np.maximum(phys.RECOVER_MIN, self.recovery - phys.RECOVER_DEC), self.recovery)
        low = self.stamina <= phys.EFFORT_DEC_THR * phys.STAMINA_MAX
        self.effort = np.where(low, np.maximum(phys.EFFORT_MIN, self.effort - phys.EFFORT_DEC), self.effort)
        high = (self.stamina >= phys.EFFORT_INC_THR * phys.STAMINA_MAX) & (self.effort < phys.EFFORT_MAX)
        self.effort = np.where(high, np.minimum(phys.EFFORT_MAX, self.effort + phys.EFFORT_INC), self.effort)
        inc = np.minimum(
            np.minimum(self.recovery * phys.STAMINA_INC_MAX, phys.STAMINA_MAX - self.stamina), self.capacity
        )
        self.stamina = self.stamina + inc
        self.capacity = self.capacity - inc

    # --- what the agents see ------------------------------------------------------------------
    def _sense(self) -> None:
        """``seen``: the agents' world model, the state to 6 significant digits (``HFOGame.sense``)."""
        state = np.stack(
            [self.px, self.py, self.pvx, self.pvy, self.body, self.stamina, self.bx, self.by, self.bvx, self.bvy]
        )
        self.seen = fullstate_values(state)

    def _observe(self, idx=slice(None)):
        """Features of the games ``idx`` (all by default), from what their agents see."""
        return low_level_features(
            *self.seen[:, idx], self._agent_kickable()[idx], self.collided_ball[idx], self.collided_post[idx],
            self.last_action_ok[idx], self.profile,
        )  # fmt: skip

    def _infos(self) -> dict:
        every = np.ones(self.num_envs, dtype=bool)
        return {"status": _STATUS_NAMES[self.status], "step": self.steps.copy(), "_status": every, "_step": every}

    def _parse_actions(self, actions):
        """``(a, first parameters, second parameters)`` as arrays of shape (N,); ``ValueError`` if malformed."""
        n = self.num_envs
        expected = f"{ACTION_FORM}, batched: (a[{n}], (dash[{n}, 2], turn[{n}, 1], kick[{n}, 2]))"
        try:
            a_raw, params = actions
            a = np.asarray(a_raw)
            boxes = [np.asarray(p, dtype=np.float64) for p in params]
        except (TypeError, ValueError):
            raise ValueError(f"actions are malformed; expected {expected}") from None
        if a.shape != (n,) or len(boxes) != 3 or any(b.shape != (n, m) for b, m in zip(boxes, PARAM_SIZES)):
            shapes = (a.shape, tuple(b.shape for b in boxes)) if len(boxes) == 3 else a.shape
            raise ValueError(f"actions have shapes {shapes}; expected {expected}")
        if not (np.issubdtype(a.dtype, np.integer) or np.all(a == np.round(a))) or a.min() < 0 or a.max() > 2:
            raise ValueError(f"discrete actions {a.tolist()} must be integers 0 (DASH), 1 (TURN) or 2 (KICK)")
        a = a.astype(np.int64)
        dash, turn = a == phys.DASH, a == phys.TURN
        x0 = np.where(dash, boxes[0][:, 0], np.where(turn, boxes[1][:, 0], boxes[2][:, 0]))
        x1 = np.where(dash, boxes[0][:, 1], boxes[2][:, 1])
        bad = ~np.isfinite(x0) | (~turn & ~np.isfinite(x1))
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise ValueError(f"game {i}: action {int(a[i])} has non-finite parameters ({x0[i]}, {x1[i]})")
        return a, x0, x1


def _per_game_options(options, n: int) -> dict:
    """Reset options as arrays with a leading game axis; each game's values checked as the scalar env's.

    A value may be given once for every game (``(2,)`` or a number) or per game (``(n, 2)`` or ``(n,)``).
    """
    if options is None:
        return {}
    if not isinstance(options, dict):
        parse_reset_options(options)  # raises the scalar env's error
    out = {}
    for key, value in options.items():
        shape = (n,) if key == "body" else (n, 2)
        try:
            arr = np.asarray(value, dtype=np.float64)
        except (TypeError, ValueError):
            arr = None
        if arr is not None and arr.shape == shape:
            for row in arr:
                parse_reset_options({key: row})
        else:
            arr = parse_reset_options({key: value})[key]
        out[key] = np.broadcast_to(arr, shape)
    return out
