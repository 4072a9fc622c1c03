"""N copies of Platform stepped at once with NumPy: ``gymnasium.make_vec("pamdp/Platform-v0", num_envs=N)``.

The physics is the scalar env's (``platform.py``, spec §7), written over arrays. One agent step runs a
different number of sub-steps in every copy (20 for run, until landing for a jump, fewer if the episode
ends), so the sub-step loop keeps only the copies that are still moving: each iteration updates the
*active* copies' state, and copies that have stopped are written back and dropped from the working
set. The loop therefore runs as long as the longest copy (~145 sub-steps for a hop) while the work done
is proportional to the total number of sub-steps (~72 per copy for a random policy).

With the noise switched off (``venv.np_random = ZeroNoise()`` after ``reset()``), every copy follows the
scalar env bit for bit. With noise on the statistics are the same, but the draws are batched and in a
different order, so individual trajectories differ from a scalar env driven by the same generator.

With Numba installed (``pip install pamdp[fast]``) the sub-step loop runs instead as one compiled loop
(``platform_kernel.py``), with the same numbers bit for bit; this NumPy loop stays the reference.
"""

from __future__ import annotations

import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from pamdp.envs.hfo_vector import _pick_backend
from pamdp.envs.numba_cache import KernelPickling
from pamdp.envs.platform import (
    AX_MAX,
    AY_MAX,
    DECAY,
    DT,
    ENEMY_BOUNDS,
    ENEMY_NOISE,
    ENEMY_SPEED,
    GRAVITY,
    HOP,
    JUMP_DEV,
    JUMP_DY0,
    LEAP,
    PARAM_MAX,
    PLATFORM_HEIGHT,
    PLATFORMS,
    PLAYER_H,
    PLAYER_NOISE,
    PLAYER_W,
    RUN,
    RUN_SUBSTEPS,
    VX_GROUND,
    VX_MAX,
    VY_MAX,
    X_GOAL,
    PlatformEnv,
    ZeroNoise,
    draw_platform,
    platform_observation,
)

# Rows of the (8, N) state array: gathering and scattering the whole state is then one indexing operation,
# and the two enemies' positions (rows 4:6) and speeds (rows 6:8) are (2, N) views updated together.
X, Y, VX, VY, E1X, E2X, E1DX, E2DX = range(8)
STATE_ROWS = 8
ENEMY_X = slice(E1X, E2X + 1)
# Extra rows of the sub-step loop's working set: per-copy constants of the current agent step.
X0, RUN_DV, DY0, TARGET_VX = range(STATE_ROWS, STATE_ROWS + 4)
INITIAL_STATE = np.array([0.0, PLATFORM_HEIGHT, 0.0, 0.0, 230.0, 730.0, -ENEMY_SPEED, -ENEMY_SPEED])
GRAVITY_DV = -GRAVITY * DT
"""The airborne ACCEL(0, -g) changes vy by exactly this (ay = -g is inside its clip range)."""
PARAM_HIGH = np.array(PARAM_MAX)
(E1_LO, E1_HI), (E2_LO, E2_HI) = ENEMY_BOUNDS
PLATFORM_X = np.array([px for px, _ in PLATFORMS])
PLATFORM_RIGHT = np.array([px + w for px, w in PLATFORMS])
GAP_MIDDLES = (PLATFORM_RIGHT[:-1] + PLATFORM_X[1:]) / 2.0


def _clip(v: np.ndarray, lo: float, hi: float) -> None:
    """In-place clip; ``np.clip``'s dispatch costs more than the two ufuncs on Platform-sized batches."""
    np.minimum(np.maximum(v, lo, out=v), hi, out=v)


def _collide(w: np.ndarray, below: np.ndarray) -> None:
    """§7.7 for the copies ``below`` the walking surface: DECOLLIDE from the platform they overlap, if any.

    The reference tries the platforms in turn; since the gaps are far wider than the player, a player
    overlaps at most one, so each copy's candidate is the platform nearest to its x.
    """
    xs, ys = w[X, below], w[Y, below]
    nearest = np.searchsorted(GAP_MIDDLES, xs)
    px, right = PLATFORM_X[nearest], PLATFORM_RIGHT[nearest]
    hits = (xs > px - PLAYER_W) & (xs < right) & (ys > -PLAYER_H)
    if not hits.any():
        return
    below, xs, ys, px, right = below[hits], xs[hits], ys[hits], px[hits], right[hits]
    new_x = np.where(xs < px, px - PLAYER_W, np.where(xs > right - PLAYER_W, right, xs))
    new_y = np.where(ys < 0.0, -PLAYER_H, np.where(ys > PLATFORM_HEIGHT - PLAYER_H, PLATFORM_HEIGHT, ys))
    # DECOLLIDE moves x if y needs no move or x moves less (and x needs moving); otherwise it moves y.
    move_x = (new_x != xs) & ((new_y == ys) | (np.abs(xs - new_x) < np.abs(ys - new_y)))
    w[X, below] = np.where(move_x, new_x, xs)
    w[Y, below] = np.where(move_x, ys, new_y)
    w[VY, below] = np.where(move_x, w[VY, below], 0.0)
    w[VX, below] = 0.0  # DECOLLIDE zeroes vx if it moves x, and §7.7 zeroes it after any collision


def _on_platform(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """§7.1 over a batch. x is always inside [0, 1035], so each platform's test is one comparison less."""
    (p1, w1), (p2, w2), (p3, _) = PLATFORMS
    over = (x <= p1 + w1) | ((x >= p2 - PLAYER_W) & (x <= p2 + w2)) | (x >= p3 - PLAYER_W)
    return over & (y == PLATFORM_HEIGHT)


class PlatformVectorEnv(KernelPickling, VectorEnv):
    """``num_envs`` independent Platform episodes, stepped together.

    Actions are batched like ``batch_space`` of the scalar action space: ``(a, (p_run, p_hop, p_leap))``
    with ``a`` an integer array of shape ``(N,)`` and each ``p`` of shape ``(N, 1)`` (``(N,)`` is
    accepted too); :meth:`pamdp.spaces.HybridActionSpace.to_env_batch` produces this format. Observations
    are ``(N, 9)`` float64; ``info["substeps"]`` is an ``(N,)`` int array (0 for a copy that was reset).

    Episodes auto-reset in Gymnasium's default *next-step* mode: the step that ends an episode returns its
    last observation with ``terminated`` or ``truncated`` set; the next ``step`` ignores that copy's action,
    resets it, and returns the reset observation with reward 0 and both flags false.

    Noise: one generator, ``self.np_random``, drives all copies; ``reset(seed=s)`` re-seeds it. Assign
    ``ZeroNoise()`` (or any object with a NumPy-style ``normal(loc, scale, size)``) after ``reset()`` to
    replace it, e.g. for the noise-free dynamics.

    Args:
        num_envs: number of copies N.
        max_episode_steps: episodes are truncated after this many agent steps (the registration's 200;
            ``make_vec`` passes it in). ``None`` never truncates.
        render_mode: ``None`` or ``"rgb_array"``; :meth:`render` then returns one frame per copy.
        backend: ``"numba"`` runs the sub-steps in the compiled loop of ``platform_kernel.py`` (needs
            ``pip install pamdp[fast]``), ``"numpy"`` with NumPy alone, ``"auto"`` with Numba when it imports.
            Both give the same numbers bit for bit, and leave ``np_random`` in the same state. The Numba loop
            reads NumPy generators' streams (``Generator``, ``RandomState``) or :class:`ZeroNoise`; with any
            other noise source a step runs the NumPy loop. ``gymnasium.make_vec(..., backend=...)`` passes
            it in.
    """

    metadata = {
        "render_modes": ["rgb_array"],
        "render_fps": PlatformEnv.metadata["render_fps"],
        "autoreset_mode": AutoresetMode.NEXT_STEP,
    }

    def __init__(
        self,
        num_envs: int = 1,
        max_episode_steps: int | None = 200,
        render_mode: str | None = None,
        backend: str = "auto",
    ):
        self.backend = _pick_backend(backend)
        if isinstance(num_envs, bool) or not isinstance(num_envs, (int, np.integer)) or num_envs < 1:
            raise ValueError(f"num_envs must be a positive integer, got {num_envs!r}")
        if max_episode_steps is not None and (
            not isinstance(max_episode_steps, (int, np.integer)) or max_episode_steps < 1
        ):
            raise ValueError(f"max_episode_steps must be a positive integer or None, got {max_episode_steps!r}")
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode={render_mode!r} is not supported; expected one of "
                f"{[None, *self.metadata['render_modes']]}"
            )
        self.num_envs = int(num_envs)
        self.max_episode_steps = max_episode_steps
        self.render_mode = render_mode
        single = PlatformEnv()
        self.single_action_space = single.action_space
        self.single_observation_space = single.observation_space
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)

        self._state = np.repeat(INITIAL_STATE[:, None], self.num_envs, axis=1)
        self._elapsed = np.zeros(self.num_envs, dtype=np.int64)
        self._autoreset = np.zeros(self.num_envs, dtype=bool)
        self._kernel_setup()

    @property
    def state(self) -> dict[str, np.ndarray]:
        """A copy of the state, batched like the scalar env's: ``player`` (N, 4), ``enemies`` (N, 2, 2)."""
        s = self._state
        return {
            "player": s[[X, Y, VX, VY]].T.copy(),
            "enemies": np.stack([s[[E1X, E1DX]].T, s[[E2X, E2DX]].T], axis=1),
        }

    # -- Gymnasium API --------------------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        """Reset all copies, or with ``options={"reset_mask": mask}`` only those where ``mask`` is true."""
        if seed is not None and not isinstance(seed, (int, np.integer)):
            raise ValueError(f"seed must be one int (one generator drives all copies), got {seed!r}")
        super().reset(seed=seed)
        mask = np.ones(self.num_envs, dtype=bool)
        if options is not None and "reset_mask" in options:
            mask = np.asarray(options["reset_mask"])
            if mask.shape != (self.num_envs,) or mask.dtype != np.bool_:
                raise ValueError(f"reset_mask must be a bool array of shape ({self.num_envs},), got {mask!r}")
        self._state[:, mask] = INITIAL_STATE[:, None]
        self._elapsed[mask] = 0
        self._autoreset[mask] = False
        return self._observations(), self._info(np.zeros(self.num_envs, dtype=np.int64))

    def step(self, actions):
        a, p = self._parse_actions(actions)
        resetting = self._autoreset
        stepping = ~resetting
        self._state[:, resetting] = INITIAL_STATE[:, None]
        self._elapsed[resetting] = 0

        rewards = np.zeros(self.num_envs)
        terminated = np.zeros(self.num_envs, dtype=bool)
        substeps = np.zeros(self.num_envs, dtype=np.int64)
        idx = np.flatnonzero(stepping)
        if idx.size and not self._kernel_substeps(idx, a, p, rewards, terminated, substeps):
            self._run_substeps(idx, a[idx], p[idx], rewards, terminated, substeps)

        self._elapsed[stepping] += 1
        truncated = np.zeros(self.num_envs, dtype=bool)
        if self.max_episode_steps is not None:
            truncated = stepping & (self._elapsed >= self.max_episode_steps)
        self._autoreset = terminated | truncated
        return self._observations(), rewards, terminated, truncated, self._info(substeps)

    def render(self):
        if self.render_mode != "rgb_array":
            return None
        s = self._state
        return tuple(draw_platform(s[X, i], s[Y, i], s[E1X, i], s[E2X, i]) for i in range(self.num_envs))

    # -- dynamics -------------------------------------------------------------------------------
    def _run_substeps(self, idx, a, p, rewards, terminated, substeps) -> None:
        """§6 for the copies ``idx``: sub-step them until each stops; write results into the out-arrays."""
        normal = self.np_random.normal
        # The working set: the state rows of the copies still moving, plus their per-step constants (start
        # x, run impulse, jump take-off speed dy0, jump target speed p / T with T = 2 dy0 / g + 1) so that
        # dropping stopped copies is one `compress` of one array.
        is_run = a == RUN
        dy0 = np.where(a == LEAP, JUMP_DY0[LEAP], JUMP_DY0[HOP])
        w = np.empty((STATE_ROWS + 4, idx.size))  # C order: the enemy update indexes it flat
        w[:STATE_ROWS] = self._state[:, idx]
        w[X0] = w[X]
        w[RUN_DV] = np.clip(p / DT, -AX_MAX, AX_MAX) * DT * is_run
        w[DY0] = dy0
        w[TARGET_VX] = p / (2.0 * dy0 / GRAVITY + 1.0)
        n = idx.size
        e1x_at = E1X * n + np.arange(n)  # flat index of enemy 1's x in the working set
        on = _on_platform(w[X], w[Y])
        live = np.ones(n, dtype=bool)  # working-set copies still moving (stopped ones are dropped lazily)
        n_live, count = n, 0
        while n_live:
            count += 1
            x, y, vx, vy = w[X], w[Y], w[VX], w[VY]

            # §7.2-3: one ACCEL per copy (run impulse, jump take-off, or gravity), then the ground cap.
            # Multiplying by the boolean `on` adds exactly 0.0 to the copies it does not concern.
            dvx = w[RUN_DV] * on
            dvy = GRAVITY_DV * ~on
            # A jump copy stands on a platform only in its first sub-step: afterwards it is in the air until
            # it lands, which stops it. (Copies that stopped but are still in the working set do not matter.)
            jumping = np.flatnonzero(on & ~is_run) if count == 1 else ()
            if len(jumping):
                jump_dy0 = w[DY0, jumping]
                dx = np.clip(w[TARGET_VX, jumping] - vx[jumping], -AX_MAX, VY_MAX - jump_dy0)
                n0, n1 = -np.abs(normal(0.0, JUMP_DEV, size=(2, jumping.size)))
                dvx[jumping] = np.clip((dx + n0) / DT, -AX_MAX, AX_MAX) * DT
                dvy[jumping] = np.clip((jump_dy0 + n1) / DT, -AY_MAX, AY_MAX) * DT
            vx += dvx
            vy += dvy
            vx -= np.abs(normal(0.0, PLAYER_NOISE, size=n))
            _clip(vx, 0.0, VX_MAX)  # = clip to +-VX_MAX, then vx >= 0
            _clip(vy, -VY_MAX, VY_MAX)
            np.minimum(vx, VX_MAX - (VX_MAX - VX_GROUND) * on, out=vx)  # cap 70 on the ground, else 100

            # §7.4-5: only the enemy of the player's half (decided before the player moves) moves.
            enemy2 = x > PLATFORMS[1][0]
            x += vx * DT
            _clip(x, 0.0, X_GOAL)
            y += vy * DT
            vx *= DECAY

            # §7.6 on the active enemy, gathered from row E1X or E2X (E1DX or E2DX) of the flat working set.
            flat = w.reshape(-1)
            at_x = e1x_at + enemy2 * n
            at_dx = at_x + (E1DX - E1X) * n
            ex, edx = flat[at_x], flat[at_dx]
            lo, hi = E1_LO + (E2_LO - E1_LO) * enemy2, E1_HI + (E2_HI - E1_HI) * enemy2
            edx *= 1.0 - 2.0 * ((ex <= lo) | (ex >= hi))  # turn round unless strictly inside (lo, hi)
            edx += normal(0.0, ENEMY_NOISE, size=n)
            _clip(edx, -ENEMY_SPEED, ENEMY_SPEED)
            ex += edx * DT
            np.minimum(np.maximum(ex, lo, out=ex), hi, out=ex)
            flat[at_x], flat[at_dx] = ex, edx

            # §7.7: only a player below the walking surface can overlap a platform.
            below = np.flatnonzero(y < PLATFORM_HEIGHT)
            if below.size:
                _collide(w, below)

            # §7.8-9 and the §6 stop rule (run: 20 sub-steps; jump: standing on a platform again).
            fell = y < PLATFORM_HEIGHT
            near = np.abs(x - w[ENEMY_X]) < PLAYER_W
            hit = (near[0] | near[1]) & (y > PLATFORM_HEIGHT - PLAYER_H) & (y < PLATFORM_HEIGHT + PLAYER_H)
            done = fell | hit | (x >= X_GOAL)
            on = _on_platform(x, y)
            stop = done | (on & ~is_run)
            if count == RUN_SUBSTEPS:
                stop |= is_run
            stop &= live
            if stop.any():
                out = idx[stop]
                # At the goal x == 1035 exactly, so this is also the goal reward (1035 - x0) / 1035.
                rewards[out] = (x[stop] - w[X0, stop]) / X_GOAL
                terminated[out] = done[stop]
                substeps[out] = count
                self._state[:, out] = w[:STATE_ROWS, stop]
                live &= ~stop
                n_live -= out.size
                # Stopped copies keep being simulated (harmlessly, their results are already out) until
                # a quarter of the working set has stopped: dropping them copies the whole working set.
                if n_live <= 0.75 * n:
                    w, idx, is_run, on = w.compress(live, axis=1), idx[live], is_run[live], on[live]
                    n, live = n_live, np.ones(n_live, dtype=bool)
                    e1x_at = E1X * n + np.arange(n)

    def _kernel_substeps(self, idx, a, p, rewards, terminated, substeps) -> bool:
        """:meth:`_run_substeps` in ``platform_kernel`` (``a`` and ``p`` for every copy). False, having done
        nothing, with the NumPy backend or if ``np_random`` is no NumPy generator, whose stream the kernel reads.

        The kernel takes the step's draws as one array of standard normals, whose length is known only at
        the end: drawn in chunks, the last of which is drawn again up to the last number used after
        rewinding the generator, so that it ends where the NumPy loop leaves it.
        """
        if self._kernel is None:
            return False
        rng = self.np_random
        if isinstance(rng, ZeroNoise):
            draw, snapshot, rewind = np.zeros, lambda: None, lambda saved: None
        elif isinstance(rng, np.random.Generator):
            bits = rng.bit_generator
            draw, snapshot, rewind = (
                rng.standard_normal,
                lambda: bits.state,
                lambda saved: setattr(bits, "state", saved),
            )
        elif isinstance(rng, np.random.RandomState):
            draw, snapshot, rewind = rng.standard_normal, rng.get_state, rng.set_state
        else:
            return False
        # The first chunk is 3/4 of the last step's draws, the later ones 1/8: the last chunk is drawn twice,
        # and each chunk after the first costs a call and a snapshot, as much as drawing several hundred numbers.
        guess = self._draws_guess
        saved, start = snapshot(), 0
        draws = draw(max(3 * guess // 4, 2 * idx.size))
        cursor = np.zeros(4, dtype=np.int64)
        run = self._kernel.run_substeps
        while not run(idx, a, p, self._state, draws, *self._kernel_scratch, cursor, rewards, terminated, substeps):
            saved, start = snapshot(), draws.size
            draws = np.concatenate([draws, draw(max(guess // 8, 2 * idx.size, 1024))])
        used = int(cursor[self._kernel.USED])
        if used < draws.size:
            rewind(saved)
            draw(used - start)
        self._draws_guess = used
        return True

    def _kernel_setup(self) -> None:
        """The kernel's module and scratch space (``backend="numba"``), or ``_kernel = None``."""
        self._kernel = None
        if self.backend != "numba":
            return
        from pamdp.envs import platform_kernel

        n = self.num_envs
        self._kernel = platform_kernel
        self._kernel_scratch = (
            np.empty((platform_kernel.WORK_ROWS, n)),
            np.empty(n, dtype=np.int64),
            np.empty(n, dtype=bool),
            np.empty(n, dtype=bool),
        )
        self._draws_guess = 0

    def _observations(self) -> np.ndarray:
        s = self._state
        enemy2 = s[X] > PLATFORMS[1][0]
        return platform_observation(s[X], s[VX], np.where(enemy2, s[E2X], s[E1X]), np.where(enemy2, s[E2DX], s[E1DX]))

    @staticmethod
    def _info(substeps: np.ndarray) -> dict:
        # Every copy reports its sub-steps (0 after a reset), hence an all-true "_substeps" mask.
        return {"substeps": substeps, "_substeps": np.ones(substeps.shape, dtype=bool)}

    # -- validation -----------------------------------------------------------------------------
    def _parse_actions(self, actions) -> tuple[np.ndarray, np.ndarray]:
        """Check a batch of actions; return ``a`` (N,) and the chosen, clipped parameters ``p`` (N,) float64."""
        n = self.num_envs
        expected = (
            f"(a, (p_run, p_hop, p_leap)) with a an int array of shape ({n},) in 0..2 and each p a finite "
            f"array of shape ({n}, 1) or ({n},)"
        )
        if not isinstance(actions, (tuple, list)) or len(actions) != 2:
            raise ValueError(f"invalid batch of Platform actions {actions!r}; expected {expected}")
        a = np.asarray(actions[0])
        if a.shape != (n,) or a.dtype.kind not in "iu":
            raise ValueError(f"invalid discrete actions {actions[0]!r}; expected {expected}")
        bad = (a < 0) | (a > 2)
        if bad.any():
            raise ValueError(f"discrete actions {a[bad]} at indices {np.flatnonzero(bad)}; expected {expected}")
        params = actions[1]
        if not isinstance(params, (tuple, list)) or len(params) != 3:
            raise ValueError(f"invalid parameters {params!r}; expected {expected}")
        columns = []
        for i, p in enumerate(params):
            p = np.asarray(p)
            if p.shape not in ((n,), (n, 1)) or p.dtype.kind not in "iuf":
                raise ValueError(f"invalid parameter {i} of shape {p.shape}: {p!r}; expected {expected}")
            p = p.reshape(n).astype(np.float64)
            if not np.isfinite(p).all():
                raise ValueError(f"parameter {i} contains {p[~np.isfinite(p)]}; expected {expected}")
            columns.append(p)
        chosen = np.stack(columns)[a, np.arange(n)]
        return a, np.clip(chosen, 0.0, PARAM_HIGH[a])
