"""N games of HFO 1v0 stepped at once with NumPy: the batched twin of ``hfo_physics.HFOGame``.

Every line of the scalar simulation has its array-wide counterpart here, in the same order and with
the same floating-point operations, so that with the actuator noise off the two agree step for step
(``tests/test_hfo_vector.py``). For speed, each action runs on the games that take it, rare branches
(goal posts, the speed caps, backward dashes) only when some game needs them, the state is updated in
place, and the features are computed once per step as contiguous rows (``hfo_features.feature_rows``).

With Numba installed (``pip install pamdp[fast]``) the step runs instead as fused loops over the games
(``hfo_kernel.py``), with the same numbers bit for bit; this NumPy step stays the reference.
"""

from __future__ import annotations

import gymnasium
import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode
from gymnasium.vector.utils import batch_space

from pamdp.envs import hfo_physics as phys
from pamdp.envs.hfo_features import (
    BALL_PROXIMITY,
    KICKABLE,
    PROFILES,
    ball_to_goal_rows,
    constant_rows,
    feature_rows,
    shaped_reward,
)
from pamdp.envs.hfo_interface import (
    ACTION_FORM,
    PARAM_SIZES,
    check_options,
    draw_half_field,
    hfo_action_space,
    parse_reset_options,
)
from pamdp.envs.numba_cache import KernelPickling

_STATUS_NAMES = np.array(phys.STATUS_NAMES)

#: Rows of the state matrix (and of ``seen``): the player's and the ball's coordinates side by side,
#: so that the movement and the features handle both objects in one pass over a ``(2, N)`` block.
_STATE = ("px", "bx", "py", "by", "pvx", "bvx", "pvy", "bvy", "body", "stamina")
_PX, _BX, _PY, _BY, _PVX, _BVX, _PVY, _BVY, _BODY, _STAMINA = range(len(_STATE))
#: Per-object constants of the movement, as columns for the ``(2, N)`` blocks: row 0 the player, row 1 the ball.
_ACCEL_MAX = np.array([[phys.PLAYER_ACCEL_MAX], [phys.BALL_ACCEL_MAX]])
_SPEED_MAX = np.array([[phys.PLAYER_SPEED_MAX], [phys.BALL_SPEED_MAX]])
_DECAY = np.array([[phys.PLAYER_DECAY], [phys.BALL_DECAY]])
_POST_REACH = phys.GOAL_POST_RADIUS + np.array([[phys.PLAYER_SIZE], [phys.BALL_SIZE]])
#: Games per block of the observation's transposition (:meth:`HalfFieldOffenseVectorEnv._observation`).
_OBS_BLOCK = 128


def normalize_angle(deg):
    """Angles in degrees mapped to (-180, 180]."""
    return 180.0 - np.mod(180.0 - deg, 360.0)


def norm(x, y):
    """Lengths of the vectors (x, y), as ``hfo_physics.norm``."""
    return np.sqrt(x * x + y * y)


def _fullstate_tables():
    """Per biased binary exponent b: the 10**k that :func:`hfo_physics.fullstate_value` compares the
    magnitude with, and its two candidate scales, at 2b (below 10**k) and 2b + 1 (at or above)."""
    pow10 = np.array(phys.POW10)
    b = np.arange(2048)
    # frexp's exponent of a normal number is b - 1022; the scalar code's decimal estimate from it:
    exponent = np.floor((b - 1023).astype(float) * phys.LOG10_2).astype(np.int64)
    exponent = np.clip(exponent, -phys.POW10_OFFSET + 6, phys.POW10_OFFSET - 6)
    threshold = pow10[exponent + 1 + phys.POW10_OFFSET]
    scales = np.stack([pow10[5 - exponent + phys.POW10_OFFSET], pow10[4 - exponent + phys.POW10_OFFSET]], axis=1)
    # Positive doubles order as their bit patterns do, so the comparison can run on integers.
    return threshold.view(np.int64), scales.ravel()


_THRESHOLD_BITS, _SCALES = _fullstate_tables()
#: Bit pattern of 1e-200 less one, unsigned: see the end of :func:`fullstate_values`.
_TINY_BITS_LESS_ONE = np.float64(1e-200).view(np.uint64) - np.uint64(1)
_MAGNITUDE_BITS = np.int64(0x7FFFFFFFFFFFFFFF)


def fullstate_values(x, out=None):
    """:func:`hfo_physics.fullstate_value` over a float64 array: 6 significant digits.

    The decimal exponent comes from the binary exponent field by table look-up instead of ``frexp``,
    with the same correction step as the scalar code, so the digits are identical.
    """
    x = np.ascontiguousarray(x, dtype=np.float64)
    magnitude = x.view(np.int64) & _MAGNITUDE_BITS
    biased = magnitude >> 52
    above = magnitude >= _THRESHOLD_BITS[biased]
    biased <<= 1
    biased += above
    scale = _SCALES[biased]
    out = np.multiply(x, scale, out=out)
    np.rint(out, out=out)
    out /= scale
    # Magnitudes below 1e-200 are kept as they are. Zeros (common: objects at rest) come through the
    # scaling unchanged, sign included, so only the nonzero ones are looked for: magnitude - 1 wraps
    # around for zero when read as unsigned.
    magnitude -= 1
    tiny = magnitude.view(np.uint64) < _TINY_BITS_LESS_ONE
    if _any(tiny):
        np.copyto(out, x, where=tiny)
    return out


def dash_direction_rate(direction):
    """Efficiency of dashes ``direction`` degrees off the body (multiples of 45; spec 2.4.3)."""
    d = np.abs(direction)
    side = phys.SIDE_DASH_RATE + (1.0 - phys.SIDE_DASH_RATE) * (1.0 - d / 90.0)
    back = phys.BACK_DASH_RATE - (phys.BACK_DASH_RATE - phys.SIDE_DASH_RATE) * (1.0 - (d - 90.0) / 90.0)
    return np.clip(np.where(d <= 90.0, side, back), 0.0, 1.0)


#: Efficiency of each of the nine dash directions -180, -135, ..., 180.
_DASH_RATES = dash_direction_rate(phys.DASH_ANGLE_STEP * np.arange(-4.0, 5.0))


def _any(mask) -> bool:
    """``mask.any()`` for a boolean array at a third of the cost: ``count_nonzero`` is a plain loop, not
    a ufunc reduction (this env tests a dozen masks a step, most of them all False)."""
    return np.count_nonzero(mask) > 0


def _indices(a):
    """``np.flatnonzero(a)`` for a contiguous array, without its Python-level wrapper (4x faster at N = 1024)."""
    return a.reshape(-1).nonzero()[0]


def _clip(x, lo, hi):
    """``np.clip`` for finite values, without its Python-level overhead."""
    return np.minimum(np.maximum(x, lo), hi)


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


def post_collisions(x, y, vx, vy, reach):
    """:func:`hfo_physics.post_collisions` over arrays, in place: moves ``x, y`` by ``vx, vy`` (bounced off
    the posts) and returns the collision flags. ``reach`` is the post radius plus the object's, a number
    or an array that broadcasts against ``x`` (one per row of objects). The sweep runs only on objects
    near a post."""
    near = np.abs(x)
    near -= phys.POST_X
    np.abs(near, out=near)
    limit = np.abs(vx)
    limit += reach
    near_x = near <= limit
    collided = np.zeros(x.shape, dtype=bool)
    i = _indices(near_x) if _any(near_x) else None
    if i is not None:  # near a post in x: then in y? (few objects, so on their flat indices)
        reach = np.broadcast_to(reach, x.shape).ravel()[i]
        x, y, vx, vy, collided_flat = (v.reshape(-1) for v in (x, y, vx, vy, collided))
        near_y = np.abs(np.abs(y[i]) - phys.POST_Y) <= np.abs(vy[i]) + reach
        i, reach = i[near_y], reach[near_y]
    if i is None or not i.size:
        x += vx
        y += vy
        return collided
    # The sweep below works on the flat indices ``i`` of the objects near a post, each with its reach.
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
        if not _any(hit):
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
    x += vx
    y += vy
    x[i], y[i], vx[i], vy[i], collided_flat[i] = sx + path_x, sy + path_y, svx, svy, hit_any
    return collided


class HalfFieldOffenseVectorEnv(KernelPickling, gymnasium.vector.VectorEnv):
    """``num_envs`` HFO 1v0 games in NumPy, with Gymnasium's next-step autoreset.

    Takes the keyword arguments of :class:`pamdp.envs.hfo.HalfFieldOffenseEnv`. Actions are the
    ``batch_space`` of the scalar action space: ``(a[N], (dash[N, 2], turn[N, 1], kick[N, 2]))``.
    A game that ended on the previous step is reset instead of stepped (its action is ignored) and
    returns its first observation with reward 0. ``infos`` holds ``status`` (strings) and ``step``
    per game. ``reset(options=...)`` takes the scalar env's options, applied to every game (each
    value may also be given per game, with a leading axis of size N).

    ``backend``: ``"numba"`` steps with the fused kernels of ``hfo_kernel.py`` (three times as fast at
    N = 1024, eight at N = 64: ``benchmarks/hfo_speed.md``; needs ``pip install pamdp[fast]``),
    ``"numpy"`` with NumPy alone, ``"auto"`` with Numba when it imports. Both give the same numbers bit
    for bit, random draws included.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 10, "autoreset_mode": AutoresetMode.NEXT_STEP}

    # Per-game arrays of shape (N,), made by _allocate in loops (declared here for readers and type checkers).
    # The physical state, rows of self._state: positions, velocities, body angle and stamina.
    px: np.ndarray
    bx: np.ndarray
    py: np.ndarray
    by: np.ndarray
    pvx: np.ndarray
    bvx: np.ndarray
    pvy: np.ndarray
    bvy: np.ndarray
    body: np.ndarray
    stamina: np.ndarray
    # Ball position a cycle ago and the stamina model's effort, recovery and capacity.
    prev_bx: np.ndarray
    prev_by: np.ndarray
    effort: np.ndarray
    recovery: np.ndarray
    capacity: np.ndarray
    # Flags: the agent holds the ball, kicked it, its action was legal, collisions, the kickable bonus paid.
    holder: np.ndarray
    kicked: np.ndarray
    last_action_ok: np.ndarray
    collided_ball: np.ndarray
    collided_post: np.ndarray
    bonus_paid: np.ndarray
    # Scratch arrays handed to the Numba kernels (kick draws, placements).
    _kick_heading: np.ndarray
    _kick_length: np.ndarray
    _kick_angle: np.ndarray
    _overlap_angle: np.ndarray
    _place_angle: np.ndarray

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
        backend: str = "auto",
    ):
        check_options(profile, body_reset)
        self.backend = _pick_backend(backend)
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
        self._allocate()  # the first episode faces the goal (body 0), later ones carry over
        self._kernel_setup()
        self._needs_reset = np.ones(self.num_envs, dtype=bool)
        self._started = False

    # --- Gymnasium API ------------------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        if seed is not None:
            self.body[:] = 0.0  # a new server run, as in the scalar env
        placement = _per_game_options(options, self.num_envs)
        self._place(np.ones(self.num_envs, dtype=bool), placement)
        self._sense()
        self._observe()
        self._needs_reset[:] = False
        self._started = True
        if self._kernel is not None:  # the kernels' memory of the features the next reward reads
            self._memory[:2] = self._rows[[KICKABLE, BALL_PROXIMITY]]
            self._memory[2] = self._to_goal
        return self._observation(), self._infos()

    def step(self, actions):
        if not self._started:
            raise gymnasium.error.ResetNeeded("call reset() before step()")
        a, params = self._parse_actions(actions)
        resetting = self._needs_reset
        if self._kernel is not None:
            return self._kernel_step(a, params, resetting)
        self._act(a, params, ~resetting)
        status = self._advance()
        self.steps += 1
        # The games that ended last step start anew now, before the agents' view and the features:
        # one pass of each covers all.
        any_resetting = _any(resetting)
        if any_resetting:
            self._place(resetting, {})
        self._sense()
        # Two feature buffers in turn: the previous step's rows are the reward's "before".
        prev, self._rows, self._spare_rows = self._rows, self._spare_rows, self._rows
        prev_to_goal = self._to_goal
        self._observe()
        goal = status == phys.GOAL
        terminal = status != phys.IN_GAME
        reward, paid = shaped_reward(prev, self._rows, self.holder, ~self.bonus_paid, goal, prev_to_goal, self._to_goal)
        # Quirks of H&S's code (see HalfFieldOffenseEnv): only the goal bonus on these transitions.
        plain = (terminal & (not self.terminal_deltas)) | ((self.steps == 1) & (not self.first_step_reward))
        if any_resetting:
            plain |= resetting
        if _any(plain):
            np.copyto(reward, np.where(goal, 5.0, 0.0), where=plain)
            paid &= ~plain
        self.bonus_paid |= paid
        timeout = status == phys.OUT_OF_TIME
        terminated = goal | (status == phys.OUT_OF_BOUNDS) | (timeout & self.timeout_terminal)
        truncated = timeout & (not self.timeout_terminal)
        if any_resetting:
            reward[resetting] = 0.0
            terminated[resetting] = truncated[resetting] = False
            status[resetting] = phys.IN_GAME
        self.status = status
        self._needs_reset = terminated | truncated
        return self._observation(), reward, terminated, truncated, self._infos()

    def render(self):
        if self.render_mode != "rgb_array":
            return None
        return tuple(
            draw_half_field(self.px[i], self.py[i], self.body[i], self.bx[i], self.by[i]) for i in range(self.num_envs)
        )

    def _kernel_step(self, a, params, resetting):
        """:meth:`step` with the fused kernels: the random draws here, in the NumPy step's order and
        amounts, the arithmetic in ``hfo_kernel``."""
        kernel, n, rng = self._kernel, self.num_envs, self.np_random
        active = ~resetting
        dash, turn, kick = params
        if self.player_rand and _any(active & (a == phys.TURN)):
            rng.random(out=self._turn_draws)
        kicking = active & (a == phys.KICK) & self._kickable
        if _any(kicking):
            i = _indices(kicking)
            # NumPy's arctan2 (SIMD) can differ from the C library's in the last bit: taken here
            dx, dy = self.bx[i] - self.px[i], self.by[i] - self.py[i]
            self._kick_heading[i] = np.degrees(np.arctan2(dy, dx))
            if self.kick_rand:
                self._kick_length[:] = rng.uniform(0.0, 1.0, n)
                self._kick_angle[:] = rng.uniform(-np.pi, np.pi, n)
        if self.player_rand:
            rng.random(out=self._noise_draws)
        coincide = kernel.act_and_move(
            a, dash, turn, kick, active, self._kickable, self._state, self.seen, self.effort, self.player_rand,
            self.kick_rand, self._turn_draws, self._kick_heading, self._kick_length, self._kick_angle,
            self._noise_draws, self._kernel_rand, self.kicked, self.last_action_ok, self.collided_post,
            self.collided_ball,
        )  # fmt: skip
        if coincide:
            self._overlap_angle[:] = rng.uniform(-np.pi, np.pi, n)
        k = np.count_nonzero(resetting)
        place_u = rng.random((k, 5)) if k else self._no_placements
        body_u = rng.random(k) if k and self.body_reset == "uniform" else self._no_draws
        if k and kernel.placements_coincide(place_u):
            self._place_angle[:] = rng.uniform(-np.pi, np.pi, n)
        obs = np.empty((n, self.profile.n_features), dtype=np.float32)
        reward, terminated, truncated = np.empty(n), np.empty(n, dtype=bool), np.empty(n, dtype=bool)
        kernel.finish_step(
            self._state, self._state_bits, self.seen, self.effort, self.recovery, self.capacity, self.prev_bx,
            self.prev_by, self.holder, self.untouched, self.cycles, self.steps, self.status, self.collided_ball,
            self.collided_post, self.kicked, self.last_action_ok, self.bonus_paid, self._kickable, self._trig_body,
            self._cos_body, self._sin_body, self._memory, self._overlap_angle, resetting, place_u, body_u,
            self.body_reset == "uniform", self._place_angle, self._kernel_profile, self._kernel_flags, obs, reward,
            terminated, truncated,
        )  # fmt: skip
        self._needs_reset = terminated | truncated
        return obs, reward, terminated, truncated, self._infos()

    def _kernel_setup(self) -> None:
        """The kernels' module and buffers (``backend="numba"``), or ``_kernel = None``."""
        self._kernel = None
        if self.backend != "numba":
            return
        from pamdp.envs import hfo_kernel

        n, profile = self.num_envs, self.profile
        self._kernel = hfo_kernel
        self._state_bits = self._state.view(np.int64)  # for the agents' view: rounding by the exponent bits
        self._kernel_rand = self._rand.ravel().copy()
        self._kernel_profile = np.array(
            [profile.n_features, -profile.max_dist / 2.0, -0.5 * profile.oob_x, -0.5 * profile.oob_y]
        )
        self._kernel_flags = np.array([self.timeout_terminal, self.terminal_deltas, self.first_step_reward])
        self._memory = np.zeros((3, n))
        for name in ("_kick_heading", "_kick_length", "_kick_angle", "_overlap_angle", "_place_angle"):
            setattr(self, name, np.zeros(n))
        self._no_placements, self._no_draws = np.zeros((0, 5)), np.zeros(0)

    # --- episode start ------------------------------------------------------------------------
    def _place(self, mask, placement: dict) -> None:
        """Start new episodes in the games of ``mask`` (draws as ``HFOGame.draw_placement``/``place``)."""
        idx = _indices(mask)
        k = idx.size
        u = self.np_random.random((k, 5))
        bx = phys.BALL_X_MAX * u[:, 0]
        by = -phys.BALL_Y_MAX + 2.0 * phys.BALL_Y_MAX * u[:, 1]
        offsets = phys.START_OFFSETS[np.minimum((10.0 * u[:, 2]).astype(int), 9)]
        px = _clip(bx + phys.START_SPREAD * (u[:, 3] + offsets[:, 0]), phys.START_X_MIN, phys.PITCH_HALF_LENGTH)
        py = _clip(by + phys.START_SPREAD * (u[:, 4] + offsets[:, 1]), -phys.BALL_Y_MAX, phys.BALL_Y_MAX)
        body = self.body[idx]
        if self.body_reset == "uniform":
            body = normalize_angle(360.0 * self.np_random.random(k) - 180.0)
        if "ball" in placement:
            bx, by = placement["ball"][idx, 0], placement["ball"][idx, 1]
        if "player" in placement:
            px, py = placement["player"][idx, 0], placement["player"][idx, 1]
        if "body" in placement:
            body = normalize_angle(placement["body"][idx])
        self.px[idx], self.py[idx], self.pvx[idx], self.pvy[idx] = px, py, 0.0, 0.0
        self.bx[idx], self.by[idx], self.bvx[idx], self.bvy[idx] = bx, by, 0.0, 0.0
        self.body[idx] = body
        self.stamina[idx], self.effort[idx], self.recovery[idx] = phys.STAMINA_MAX, 1.0, 1.0
        self.capacity[idx] = phys.STAMINA_CAPACITY
        close = norm(bx - px, by - py) < phys.TOUCH_DISTANCE
        if _any(close):  # rare: pushed apart, so the positions are read back
            overlap = np.zeros(self.num_envs, dtype=bool)
            overlap[idx] = close
            self._resolve_overlap(overlap)
            px, py, bx, by = self.px[idx], self.py[idx], self.bx[idx], self.by[idx]
        self.prev_bx[idx], self.prev_by[idx] = bx, by
        near = norm(bx - px, by - py) <= phys.KICKABLE_AREA
        self.holder[idx] = near
        self.untouched[idx] = np.where(near, 0, phys.COUNTERS_AT_FIRST_OBSERVATION)
        self.cycles[idx] = phys.COUNTERS_AT_FIRST_OBSERVATION
        self.collided_ball[idx] = self.collided_post[idx] = False
        self.last_action_ok[idx] = self.kicked[idx] = False
        self.steps[idx] = 0
        self.bonus_paid[idx] = False
        self.status[idx] = phys.IN_GAME  # the agents' view (_sense) is left to the caller

    def _bind_views(self) -> None:
        """The attributes that are views of ``_state`` and ``_accel``: bound at allocation and again after a copy
        (``copy.deepcopy`` and pickling copy each view on its own, which would cut it off the state)."""
        n = self.num_envs
        for name, row in zip(_STATE, self._state):
            setattr(self, name, row)
        # (2, N) blocks of the movement: positions x and y, velocities x and y (views of the state).
        self._xy = self._state[_PX : _BY + 1].reshape(2, 2, n)
        self._v = self._state[_PVX : _BVY + 1].reshape(2, 2, n)
        (self.pax, self.bax), (self.pay, self.bay) = self._accel
        if getattr(self, "_kernel", None) is not None:
            self._state_bits = self._state.view(np.int64)  # for the agents' view: rounding by the exponent bits

    def __setstate__(self, state: dict) -> None:
        super().__setstate__(state)
        self._bind_views()

    def _allocate(self) -> None:
        n = self.num_envs
        # The state's attributes are rows of one matrix, updated in place, which the agents' view rounds.
        self._state = np.zeros((len(_STATE), n))
        # Accelerations accumulated this cycle, x and y, player (row 0) and ball (row 1).
        self._accel = np.zeros((2, 2, n))
        self._bind_views()
        self._rand = np.array([[self.player_rand], [self.ball_rand]])
        self._noise_draws = np.zeros((4, n))
        self._turn_draws = np.zeros(n)
        for name in ("prev_bx", "prev_by", "effort", "recovery", "capacity"):
            setattr(self, name, np.zeros(n))
        for name in ("holder", "kicked", "last_action_ok", "collided_ball", "collided_post", "bonus_paid"):
            setattr(self, name, np.zeros(n, dtype=bool))
        self.untouched = np.zeros(n, dtype=np.int64)
        self.cycles = np.zeros(n, dtype=np.int64)
        self.steps = np.zeros(n, dtype=np.int64)
        self.status = np.zeros(n, dtype=np.int64)
        self.seen = np.zeros((len(_STATE), n))
        # The body's cosine and sine change only when it turns: kept with the angle they belong to.
        self._trig_body = np.full(n, np.nan)
        self._cos_body, self._sin_body = np.zeros(n), np.zeros(n)
        # Two feature buffers in turn, their constant rows written once; the observation is transposed
        # from them through ``_blocks`` (see _observation).
        self._rows, self._spare_rows = (constant_rows(np.zeros((self.profile.n_features, n))) for _ in range(2))
        self._blocks = np.zeros((n // _OBS_BLOCK, self.profile.n_features, _OBS_BLOCK), dtype=np.float32)
        self._feature_scratch = np.zeros((5, 12, n))
        self._to_goal = np.zeros(n)

    # --- agent-side processing and server-side commands (spec 2.3, 2.4) -------------------------
    def _agent_kickable(self):
        limit = np.where(self.kicked, phys.KICKABLE_AREA, phys.AGENT_KICKABLE_AREA)
        seen = self.seen
        return norm(seen[_BX] - seen[_PX], seen[_BY] - seen[_PY]) <= limit

    def _act(self, a, params, active) -> None:
        """Apply the agents' DASH / TURN / KICK to the ``active`` games (``HFOGame.act``)."""
        dash, turn = active & (a == phys.DASH), active & (a == phys.TURN)
        kick = active & (a == phys.KICK) & self._kickable  # the test of the features just observed
        self._accel.fill(0.0)
        dash_params, turn_params, kick_params = params
        # The speed the agents see, which both the dashes and the turns read: once for every game.
        seen_speed = norm(self.seen[_PVX], self.seen[_PVY])
        i = _indices(dash)
        if i.size:
            self._dash(dash_params[:, 0], dash_params[:, 1], i, seen_speed[i])
        i = _indices(turn)
        if i.size:
            self._turn(turn_params[:, 0], i, seen_speed[i])
        if _any(kick):  # rare with random actions: not worth the indices unless some game kicks
            self._kick(kick_params[:, 0], kick_params[:, 1], _indices(kick))
        self.kicked = kick
        self.last_action_ok = dash | turn | kick

    def _dash(self, power, direction, i, seen_speed) -> None:
        """DASH in the games ``i`` (indices): each array below holds those games only."""
        power = _clip(power[i], -100.0, 100.0)
        steps = np.rint(_clip(direction[i], -180.0, 180.0) / phys.DASH_ANGLE_STEP)
        direction = phys.DASH_ANGLE_STEP * steps
        rate = _DASH_RATES[steps.astype(np.int64) + 4]
        effort = self.effort[i]
        available = self.seen[_STAMINA, i] + phys.EXTRA_STAMINA
        if not _any(power < 0.0):  # the action space's dashes; negative power dashes backwards
            power = np.minimum(power, available)
        else:
            power = np.where(
                power >= 0.0, np.minimum(power, available), np.where(-2.0 * power > available, -available / 2.0, power)
            )
        accel_rate = rate * effort * phys.DASH_POWER_RATE
        accel = np.abs(power * accel_rate)
        capped = (seen_speed + accel > phys.PLAYER_SPEED_MAX) & (accel_rate > 0.0)
        if _any(capped):  # librcsc's speed-cap conservation; never binding with player_decay 0.4
            seen = self.seen.take(i, axis=1)  # one gather of every row is cheaper than three
            svx, svy, s_body = seen[_PVX], seen[_PVY], seen[_BODY]
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
        any_backward = _any(backward)
        stamina = self.stamina[i]
        need = np.minimum(
            np.where(backward, -2.0 * power, power) if any_backward else power, stamina + phys.EXTRA_STAMINA
        )
        self.stamina[i] = np.maximum(0.0, stamina - need)
        power = np.where(backward, -need / 2.0, need) if any_backward else need
        accel = np.abs(effort * power * rate * phys.DASH_POWER_RATE)
        phi = self.body[i] + direction
        phi += np.where(backward, 180.0, 0.0) if any_backward else 0.0
        np.radians(phi, out=phi)
        self.pax[i] = accel * np.cos(phi)
        self.pay[i] = accel * np.sin(phi)

    def _turn(self, direction, i, seen_speed) -> None:
        direction = direction[i]
        moment = round_command(_clip(direction * (1.0 + phys.INERTIA_MOMENT * seen_speed), -180.0, 180.0))
        inertia = 1.0 + phys.INERTIA_MOMENT * norm(self.pvx[i], self.pvy[i])
        noise = 1.0
        if self.player_rand:  # drawn for every game, as the stream of draws is part of a seed's results
            # U(-rand, rand) as NumPy's generator draws it, low + (high - low) * u, without the argument
            # checks of Generator.uniform (a third of this method's time at N = 1024)
            u = self._turn_draws
            self.np_random.random(out=u)
            noise = u[i] * (2.0 * self.player_rand)
            noise += -self.player_rand
            noise += 1.0
        self.body[i] = normalize_angle(self.body[i] + noise * moment / inertia)

    def _kick(self, power, direction, i) -> None:
        power = round_command(_clip(power[i], 0.0, 100.0))
        direction = _clip(direction[i], -180.0, 180.0)
        body, bvx, bvy = self.body[i], self.bvx[i], self.bvy[i]
        dx, dy = self.bx[i] - self.px[i], self.by[i] - self.py[i]
        dist = norm(dx, dy)
        dir_diff = np.abs(normalize_angle(np.degrees(np.arctan2(dy, dx)) - body)) / 180.0
        gap = (dist - phys.TOUCH_DISTANCE) / phys.KICKABLE_MARGIN
        effective = power * phys.KICK_POWER_RATE * (1.0 - 0.25 * dir_diff - 0.25 * gap)
        phi = np.radians(body + direction)
        kx, ky = effective * np.cos(phi), effective * np.sin(phi)
        if self.kick_rand:
            pos_rate = 0.5 + 0.25 * (dir_diff + gap)
            speed_rate = 0.5 + 0.5 * norm(bvx, bvy) / (phys.BALL_SPEED_MAX * phys.BALL_DECAY)
            max_noise = self.kick_rand * (power / 100.0) * (pos_rate + speed_rate)
            length = self.np_random.uniform(0.0, 1.0, self.num_envs)[i] * max_noise
            angle = self.np_random.uniform(-np.pi, np.pi, self.num_envs)[i]
            kx, ky = kx + length * np.cos(angle), ky + length * np.sin(angle)
        sent = dist <= phys.KICKABLE_AREA
        self.bax[i[sent]] = kx[sent]
        self.bay[i[sent]] = ky[sent]

    # --- one simulation cycle (spec 2.5) ----------------------------------------------------------
    def _advance(self):
        self.collided_post = self._move()[0]
        dist = norm(self.bx - self.px, self.by - self.py)
        self.collided_ball = dist < phys.TOUCH_DISTANCE
        if _any(self.collided_ball):
            self._resolve_overlap(self.collided_ball)
            dist = norm(self.bx - self.px, self.by - self.py)
        status = self._referee(dist)
        self._update_stamina()
        return status  # the agents' view (_sense) is taken by the caller, after placing new episodes

    def _move(self):
        """Spec 2.5.1 for the player and the ball at once, in place, on ``(2, N)`` blocks (row 0 the
        player, row 1 the ball); returns the post-collision flags, same shape."""
        x, y, vx, vy = self._xy[0], self._xy[1], self._v[0], self._v[1]
        ax, ay = self._accel
        # Flat indices into the (2, N) blocks: only these accelerate, the rest keep their velocity.
        i = _indices((ax != 0.0) | (ay != 0.0))
        if i.size:  # the limits rarely bind; where they don't, the factor 1 changes nothing
            obj = i // self.num_envs  # 0 for the player, 1 for the ball
            flat_vx, flat_vy = vx.reshape(-1), vy.reshape(-1)
            ax, ay = ax.reshape(-1)[i], ay.reshape(-1)[i]
            a = norm(ax, ay)
            accel_max = _ACCEL_MAX.ravel()[obj]
            over = a > accel_max
            if _any(over):
                shrink = np.where(over, accel_max / np.where(a > 0.0, a, 1.0), 1.0)
                ax, ay = ax * shrink, ay * shrink
            svx, svy = flat_vx[i] + ax, flat_vy[i] + ay
            speed = norm(svx, svy)
            speed_max = _SPEED_MAX.ravel()[obj]
            over = speed > speed_max
            if _any(over):
                shrink = np.where(over, speed_max / np.where(speed > 0.0, speed, 1.0), 1.0)
                svx *= shrink
                svy *= shrink
            flat_vx[i], flat_vy[i] = svx, svy
        if self.player_rand:  # the ball's noise is on or off with the player's
            # Drawn for every game, in the scalar env's order: the player's length and angle, then the ball's.
            draws = self._noise_draws
            self.np_random.random(out=draws)  # the same stream as one call per row
            length = draws[0::2] * self._rand
            length *= norm(vx, vy)
            for obj in range(2):  # only moving objects need the angle's cosine and sine
                self._add_noise(vx[obj], vy[obj], length[obj], draws[2 * obj + 1])
        collided = post_collisions(x, y, vx, vy, _POST_REACH)
        vx *= _DECAY
        vy *= _DECAY
        return collided

    def _add_noise(self, vx, vy, length, u) -> None:
        """Adds the vectors of ``length`` at angle U(-pi, pi) (from the uniform draws ``u``) to the
        velocities ``vx, vy`` of one kind of object, in place, where ``length`` is not 0."""
        moving = np.count_nonzero(length)
        if 2 * moving > length.size:  # most of them (players always, after the first dash): whole rows
            # U(-pi, pi) as NumPy's generator draws it: low + (high - low) * u
            angle = u * (2.0 * np.pi)
            angle += -np.pi
            where = True if moving == length.size else length != 0.0  # a masked add leaves -0.0 as it is
            np.add(vx, length * np.cos(angle), out=vx, where=where)
            np.add(vy, length * np.sin(angle), out=vy, where=where)
        elif moving:  # a few of them (balls, mostly at rest): on their indices
            i = _indices(length)
            angle = u[i] * (2.0 * np.pi)
            angle += -np.pi
            length = length[i]
            vx[i] += length * np.cos(angle)
            vy[i] += length * np.sin(angle)

    def _resolve_overlap(self, mask) -> None:
        dx, dy = self.bx - self.px, self.by - self.py
        dist = norm(dx, dy)
        angle = self.np_random.uniform(-np.pi, np.pi, self.num_envs) if _any(mask & (dist == 0.0)) else 0.0
        safe = np.where(dist > 0.0, dist, 1.0)
        nx = np.where(dist > 0.0, dx / safe, np.cos(angle))
        ny = np.where(dist > 0.0, dy / safe, np.sin(angle))
        mx, my = 0.5 * (self.bx + self.px), 0.5 * (self.by + self.py)
        half = 0.5 * phys.TOUCH_DISTANCE + phys.CONTACT_EPSILON
        np.copyto(self.bx, mx + half * nx, where=mask)
        np.copyto(self.by, my + half * ny, where=mask)
        np.copyto(self.px, mx - half * nx, where=mask)
        np.copyto(self.py, my - half * ny, where=mask)
        for v in (self.pvx, self.pvy, self.bvx, self.bvy):
            np.multiply(v, phys.COLLISION_VELOCITY_FACTOR, out=v, where=mask)

    def _referee(self, dist):
        """HFO's referee (``HFOGame._referee``); ``dist`` is the player-ball distance after the cycle."""
        self.cycles += 1
        prev_x, prev_y = self.prev_bx, self.prev_by
        crossing = self.bx > phys.GOAL_LINE_X
        goal = goal_crossed(prev_x, prev_y, self.bx, self.by) if _any(crossing) else crossing
        out = (prev_x < 0.0) | (prev_x > phys.PITCH_HALF_LENGTH) | (np.abs(prev_y) > phys.PITCH_HALF_WIDTH)
        out &= ~goal
        timeout = (self.untouched > phys.UNTOUCHED_TIME) | (self.cycles > phys.FRAMES_PER_TRIAL)
        ended = goal | out
        timeout &= ~ended
        ended |= timeout
        in_game = ~ended
        touch = in_game & (dist <= phys.KICKABLE_AREA)
        self.untouched += in_game
        self.untouched[touch] = 0
        self.holder |= touch
        np.copyto(self.prev_bx, self.bx)
        np.copyto(self.prev_by, self.by)
        status = np.zeros(self.num_envs, dtype=np.int64)
        if _any(ended):
            status[goal], status[out], status[timeout] = phys.GOAL, phys.OUT_OF_BOUNDS, phys.OUT_OF_TIME
        return status

    def _update_stamina(self) -> None:
        stamina, effort, recovery = self.stamina, self.effort, self.recovery
        low = stamina <= phys.RECOVER_DEC_THR * phys.STAMINA_MAX
        if _any(low):
            np.copyto(recovery, np.maximum(phys.RECOVER_MIN, recovery - phys.RECOVER_DEC), where=low)
        low = stamina <= phys.EFFORT_DEC_THR * phys.STAMINA_MAX
        if _any(low):
            np.copyto(effort, np.maximum(phys.EFFORT_MIN, effort - phys.EFFORT_DEC), where=low)
        high = effort < phys.EFFORT_MAX
        if _any(high):
            high &= stamina >= phys.EFFORT_INC_THR * phys.STAMINA_MAX
            np.copyto(effort, np.minimum(phys.EFFORT_MAX, effort + phys.EFFORT_INC), where=high)
        inc = np.subtract(phys.STAMINA_MAX, stamina)
        np.minimum(recovery * phys.STAMINA_INC_MAX, inc, out=inc)
        np.minimum(inc, self.capacity, out=inc)
        stamina += inc
        self.capacity -= inc

    # --- what the agents see ------------------------------------------------------------------
    def _sense(self) -> None:
        """``seen``: the agents' world model, the state to 6 significant digits (``HFOGame.sense``)."""
        fullstate_values(self._state, out=self.seen)

    def _observe(self) -> None:
        """Features of every game from what its agent sees, into ``_rows``; also the agents' kickable
        test and the ball-to-goal term of the reward."""
        seen = self.seen
        self._kickable = kickable = self._agent_kickable()
        # cos and sin of the body angle, recomputed only where the seen angle changed (turns, resets)
        turned = _indices(self._trig_body != seen[_BODY])
        if turned.size:
            theta = seen[_BODY, turned]
            self._trig_body[turned] = theta
            theta = np.radians(theta)
            self._cos_body[turned], self._sin_body[turned] = np.cos(theta), np.sin(theta)
        feature_rows(
            seen[_PX], seen[_PY], seen[_BX], seen[_BY], seen[_PVX:_BVX + 1], seen[_PVY:_BVY + 1], seen[_STAMINA],
            self._cos_body, self._sin_body, kickable, self.collided_ball, self.collided_post, self.last_action_ok,
            self.profile, self._rows, self._feature_scratch, constants=False,
        )  # fmt: skip
        self._to_goal = ball_to_goal_rows(self._rows)

    def _observation(self) -> np.ndarray:
        """The ``(N, n_features)`` float32 observation, transposed from the feature rows in two passes
        that each read and write memory in order: first every block of ``_OBS_BLOCK`` games, all rows,
        to ``_blocks`` (contiguous runs of the rows, cast to float32), then each block, small enough
        for the L1 cache, to its games' rows of the observation. A third faster than one strided copy.
        The games past the last whole block (all of them when N < _OBS_BLOCK) take one strided copy."""
        n, n_features = self.num_envs, self.profile.n_features
        rows, blocks = self._rows, self._blocks
        obs = np.empty((n, n_features), dtype=np.float32)
        whole = blocks.shape[0] * _OBS_BLOCK
        if whole:
            runs = rows[:, :whole].reshape(n_features, -1, _OBS_BLOCK).transpose(1, 0, 2)
            np.copyto(blocks, runs, casting="same_kind")
            np.copyto(obs[:whole].reshape(-1, _OBS_BLOCK, n_features), blocks.transpose(0, 2, 1))
        if whole < n:
            np.copyto(obs[whole:], rows[:, whole:].T, casting="same_kind")
        return obs

    def _infos(self) -> dict:
        every = np.ones(self.num_envs, dtype=bool)
        return {"status": _STATUS_NAMES[self.status], "step": self.steps.copy(), "_status": every, "_step": every}

    def _expected_actions(self) -> str:
        """The form of a batch of actions, for error messages (formatted only when one is raised)."""
        n = self.num_envs
        return f"{ACTION_FORM}, batched: (a[{n}], (dash[{n}, 2], turn[{n}, 1], kick[{n}, 2]))"

    def _parse_actions(self, actions):
        """``(a, (dash, turn, kick))`` as float64 arrays of shapes (N,), (N, 2), (N, 1), (N, 2);
        ``ValueError`` if malformed, or if a game's chosen action has non-finite parameters."""
        n = self.num_envs
        try:
            a_raw, params = actions
            a = np.asarray(a_raw)
            boxes = [np.asarray(p, dtype=np.float64) for p in params]
        except (TypeError, ValueError):
            raise ValueError(f"actions are malformed; expected {self._expected_actions()}") from None
        if a.shape != (n,) or len(boxes) != 3 or any(b.shape != (n, m) for b, m in zip(boxes, PARAM_SIZES)):
            shapes = (a.shape, tuple(b.shape for b in boxes)) if len(boxes) == 3 else a.shape
            raise ValueError(f"actions have shapes {shapes}; expected {self._expected_actions()}")
        if not (a.dtype.kind in "iu" or np.all(a == np.round(a))) or _any((a < 0) | (a > 2)):  # not 2 reductions
            raise ValueError(f"discrete actions {a.tolist()} must be integers 0 (DASH), 1 (TURN) or 2 (KICK)")
        a = a.astype(np.int64, copy=False)
        dash, turn, kick = boxes
        # A finite sum means every parameter is finite (an overflow only sends us to the exact check).
        if np.isfinite(dash.sum() + turn.sum() + kick.sum()):
            return a, boxes
        x0 = np.choose(a, (dash[:, 0], turn[:, 0], kick[:, 0]))
        x1 = np.choose(a, (dash[:, 1], kick[:, 1], kick[:, 1]))
        bad = ~np.isfinite(x0) | ((a != phys.TURN) & ~np.isfinite(x1))  # a turn has no second parameter
        if _any(bad):
            i = int(_indices(bad)[0])
            raise ValueError(f"game {i}: action {int(a[i])} has non-finite parameters ({x0[i]}, {x1[i]})")
        return a, boxes


def _pick_backend(backend: str) -> str:
    """``"numpy"`` or ``"numba"`` for the constructor's ``backend`` argument."""
    if backend not in ("auto", "numpy", "numba"):
        raise ValueError(f"backend={backend!r}; expected 'auto', 'numpy' or 'numba'")
    if backend == "numpy":
        return backend
    try:
        import numba  # noqa: F401
    except ImportError as err:
        if backend == "numba":
            raise ImportError("backend='numba' needs Numba: pip install pamdp[fast]") from err
        return "numpy"
    return "numba"


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
