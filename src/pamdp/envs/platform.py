"""Platform (Masson, Ranchod & Konidaris, AAAI 2016), written from ``shared/specs/platform.md``.

The agent is a box that must cross three platforms, separated by two gaps, to reach the right edge
(``x = 1035``) while avoiding two enemies that patrol platforms 1 and 2. Every agent step is a
*parameterised action* ``(a, p)``:

====  ======  ===============  ==========================================================
 a    name    parameter range  effect
====  ======  ===============  ==========================================================
 0    run     [0, 30]          20 physics sub-steps, each adding ``p`` to vx (ground cap 70)
 1    hop     [0, 720]         jump with vy = 35 aiming at horizontal speed ``p / 8.14``
 2    leap    [0, 430]         jump with vy = 25 aiming at horizontal speed ``p / 6.10``
====  ======  ===============  ==========================================================

A jump lasts until the player is standing on a platform again (or the episode ends), so one agent
step runs a variable number of sub-steps (``info["substeps"]``, ~72 on average for a random policy).

The reward of a step is the horizontal progress ``(x_end - x_start) / 1035`` so the episode return is
the fraction of the course covered (exactly 1.0 at the goal). Falling into a gap or touching an
enemy ends the episode (``terminated``); the 200-step limit of the registration is ``truncated``.

Section numbers in comments (``§7.6``) refer to the spec. The arithmetic is float64 throughout and
every Gaussian draw goes through ``self.np_random.normal`` in the spec's §9 order, so replacing
``env.unwrapped.np_random`` by ``numpy.random.RandomState(S)`` after ``reset()`` replays the reference
implementation bit for bit, and :class:`ZeroNoise` gives the noise-free dynamics.

The batched version, :class:`PlatformVectorEnv`, lives in ``platform_vector.py`` and is re-exported here.
"""

from __future__ import annotations

import math
import numbers
import os
from collections.abc import Callable

import gymnasium
import numpy as np
from gymnasium import spaces

from pamdp.envs.rendering import Canvas, record_episode

__all__ = [
    "PlatformEnv",
    "ZeroNoise",
    "platform_observation",
    "draw_platform",
    "save_platform_gif",
]

# --- §1 geometry (pixels, y up; positions are lower-left corners) -----------------------------------
PLATFORM_HEIGHT = 40.0
"""Every platform spans y in [0, 40], so an entity standing on one has y == 40 exactly."""
PLATFORMS = ((0.0, 250.0), (475.0, 275.0), (985.0, 50.0))
"""``(x, width)`` of the three platforms; the gaps are 225 and 235 wide."""
X_GOAL = 1035.0
"""Right edge of the last platform: reaching it ends the episode with return 1."""
PLAYER_W, PLAYER_H = 20.0, 30.0
"""Player and enemies are 20 x 30 boxes."""
ENEMY_BOUNDS = ((0.0, 230.0), (475.0, 730.0))
"""Patrol interval ``[L, R] = [P.x, P.x + width - 20]`` of enemy 1 (platform 1) and enemy 2 (platform 2)."""

# --- §2 constants -----------------------------------------------------------------------------------
DT = 0.05
GRAVITY = 9.8
DECAY = 0.99
VX_MAX = 100.0
VY_MAX = 200.0
VX_GROUND = 70.0
AX_MAX = (VX_MAX - VX_GROUND) / DT
"""600: caps any single impulse to +-30 in vx (computed as the reference does, so clips compare equal)."""
AY_MAX = VY_MAX / DT
ENEMY_SPEED = 30.0
ENEMY_NOISE = 0.5 * DT
PLAYER_NOISE = 0.5 * DT
JUMP_DEV = 1.0
RUN, HOP, LEAP = 0, 1, 2
JUMP_DY0 = {HOP: 35.0, LEAP: 25.0}
"""Vertical take-off speed of each jump."""
PARAM_MAX = (30.0, 720.0, 430.0)
"""Upper bound of each action's parameter box (the lower bound is 0)."""
RUN_SUBSTEPS = 20
"""The reference counts 1.0 down by dt while > 0: exactly 20 sub-steps."""

# --- §4 observation scaling -------------------------------------------------------------------------
OBS_SHIFT = np.array([20.0, 0.0, 0.0, 30.0, 0.0, 0.0, 0.0, 0.0, 0.0])
OBS_SCALE = np.array([1055.0, 100.0, 1035.0, 60.0, 275.0, 275.0, 235.0, 1035.0, 1.0])
# (wd1, wd2, gap, pos, diff) while the player is before platform 2, on/over platform 2, on platform 3.
PLATFORM_FEATURES = np.array(
    [
        [250.0, 275.0, 225.0, 0.0, 0.0],
        [275.0, 50.0, 235.0, 475.0, 0.0],
        [50.0, 0.0, 0.0, 985.0, 0.0],
    ]
)


def platform_observation(player_x, player_vx, enemy_x, enemy_dx) -> np.ndarray:
    """The 9 scaled features of §4 for one state (scalars) or a batch (arrays of shape ``(N,)``).

    ``enemy_x`` and ``enemy_dx`` are those of the *active* enemy: enemy 2 if ``player_x > 475`` else
    enemy 1. The platform features switch at x = 475 and x = 985 (with ``<``, so a player who lands on
    platform 2 at 455 < x < 475 still sees platform 1's features, as in the reference).
    """
    player_x = np.asarray(player_x, dtype=np.float64)
    section = (player_x >= PLATFORMS[1][0]).astype(np.intp) + (player_x >= PLATFORMS[2][0])
    raw = np.concatenate(
        [np.stack([player_x, player_vx, enemy_x, enemy_dx], axis=-1), PLATFORM_FEATURES[section]], axis=-1
    )
    return (raw + OBS_SHIFT) / OBS_SCALE


class ZeroNoise:
    """A stand-in for ``np_random`` whose ``normal()`` returns zeros: the noise-free dynamics.

    Assign it after ``reset()`` (``env.unwrapped.np_random = ZeroNoise()``), for the scalar and the
    batched env alike; a seeded ``reset(seed=...)`` replaces it by a fresh generator again.
    """

    def normal(self, loc=0.0, scale=1.0, size=None):
        return 0.0 * loc if size is None else np.zeros(size)


# A player (20 wide) stands on platform P if P.x - 20 <= x <= P.x + width; x never leaves [0, 1035].
_P1_RIGHT = PLATFORMS[0][0] + PLATFORMS[0][1]
_P2_LEFT, _P2_RIGHT = PLATFORMS[1][0] - PLAYER_W, PLATFORMS[1][0] + PLATFORMS[1][1]
_P3_LEFT = PLATFORMS[2][0] - PLAYER_W


def _on_platform(x: float, y: float) -> bool:
    """§7.1: standing exactly on top of some platform (exact float equality, as the reference)."""
    return y == PLATFORM_HEIGHT and (x <= _P1_RIGHT or _P2_LEFT <= x <= _P2_RIGHT or x >= _P3_LEFT)


def _clip(v: float, lo: float, hi: float) -> float:
    return lo if v < lo else hi if v > hi else v


def _decollide(x: float, y: float, vx: float, vy: float, px: float, w: float) -> tuple[float, ...]:
    """§7 DECOLLIDE: push the player out of platform ``(px, w)`` along the axis of least overlap.

    Returns the new ``(x, y, vx, vy)``. Platforms span y in [0, 40]; the player's y is in (-30, 40) here.
    """
    new_x = px - PLAYER_W if x < px else px + w if x > px + w - PLAYER_W else x
    new_y = -PLAYER_H if y < 0.0 else PLATFORM_HEIGHT if y > PLATFORM_HEIGHT - PLAYER_H else y
    if new_x == x:
        return x, new_y, vx, 0.0
    if new_y == y:
        return new_x, y, 0.0, vy
    if abs(x - new_x) < abs(y - new_y):
        return new_x, y, 0.0, vy
    return x, new_y, vx, 0.0


class PlatformEnv(gymnasium.Env):
    """The Platform domain as a Gymnasium env (see the module docstring for the task).

    Action: ``(a, (p_run, p_hop, p_leap))`` with ``a`` in {0, 1, 2} and each ``p`` an array of shape
    ``(1,)`` (a plain number is accepted too); only ``p_a`` is read, after clipping into its box.
    Actions that are malformed, or contain NaN or infinite parameters, raise ``ValueError``.

    Observation: the 9 features of :func:`platform_observation`, float64 in ``[0, 1]``. The reference's
    observation is ``(s, k)`` with ``k`` the sub-steps of the last step; here ``k`` is
    ``info["substeps"]`` (0 after reset).

    Internal state (read it for tests and plots, not to control the env): ``player`` =
    ``[x, y, vx, vy]`` and ``enemies`` = ``[[x1, dx1], [x2, dx2]]`` via :attr:`state`.

    Noise: every Gaussian draw is ``self.np_random.normal(...)``. After ``reset()``, assign
    ``numpy.random.RandomState(S)`` to replay the reference implementation driven by the same generator,
    or :class:`ZeroNoise` for the noise-free dynamics; ``reset(seed=...)`` installs a fresh generator.

    Args:
        render_mode: ``None`` or ``"rgb_array"`` (a side view of the course, see :func:`draw_platform`).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(self, render_mode: str | None = None):
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode={render_mode!r} is not supported; expected one of "
                f"{[None, *self.metadata['render_modes']]}"
            )
        self.render_mode = render_mode
        self.action_space = spaces.Tuple(
            (
                spaces.Discrete(3),
                spaces.Tuple(
                    tuple(spaces.Box(np.float32(0.0), np.float32(hi), shape=(1,), dtype=np.float32) for hi in PARAM_MAX)
                ),
            )
        )
        self.observation_space = spaces.Box(0.0, 1.0, shape=(9,), dtype=np.float64)
        self._set_initial_state()

    # -- state ----------------------------------------------------------------------------------
    def _set_initial_state(self) -> None:
        # §5: deterministic; all randomness is in the dynamics.
        self.x, self.y, self.vx, self.vy = 0.0, PLATFORM_HEIGHT, 0.0, 0.0
        self.e1x, self.e1dx = 230.0, -ENEMY_SPEED
        self.e2x, self.e2dx = 730.0, -ENEMY_SPEED

    @property
    def state(self) -> dict[str, np.ndarray]:
        """A copy of the internal state: ``player`` = [x, y, vx, vy], ``enemies`` = [[x, dx], [x, dx]]."""
        return {
            "player": np.array([self.x, self.y, self.vx, self.vy]),
            "enemies": np.array([[self.e1x, self.e1dx], [self.e2x, self.e2dx]]),
        }

    def _observation(self) -> np.ndarray:
        if self.x > PLATFORMS[1][0]:
            return platform_observation(self.x, self.vx, self.e2x, self.e2dx)
        return platform_observation(self.x, self.vx, self.e1x, self.e1dx)

    # -- Gymnasium API --------------------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        self._set_initial_state()
        return self._observation(), {"substeps": 0}

    def step(self, action):
        a, p = self._parse_action(action)
        # The state lives in local variables during the sub-step loop: attribute access and helper calls
        # would double the cost of a sub-step, and a step runs ~72 of them.
        x, y, vx, vy = self.x, self.y, self.vx, self.vy
        e1x, e1dx, e2x, e2dx = self.e1x, self.e1dx, self.e2x, self.e2dx
        normal = self.np_random.normal
        x0 = x
        if a != RUN:
            dy0 = JUMP_DY0[a]
            T = 2.0 * dy0 / GRAVITY + 1.0  # roughly the flight time, so p / T is a horizontal speed
        substeps = 0
        while True:  # §6
            substeps += 1

            # §7.1-2: the action acts while the player stands on a platform; in the air, gravity does.
            on_platform = y == PLATFORM_HEIGHT and (x <= _P1_RIGHT or _P2_LEFT <= x <= _P2_RIGHT or x >= _P3_LEFT)
            if not on_platform:
                ax, ay = 0.0, -GRAVITY
            elif a == RUN:
                ax, ay = p / DT, 0.0
            else:  # JUMP(p, dy0, dev): the take-off impulse, only reachable within +-30 of vx.
                dx = _clip(p / T - vx, -AX_MAX, VY_MAX - dy0)
                n0, n1 = -np.abs(normal(0.0, JUMP_DEV, size=2))  # §9 draw 1
                ax, ay = (dx + float(n0)) / DT, (dy0 + float(n1)) / DT
            # ACCEL(ax, ay): bounded acceleration for one sub-step, minus a |Gaussian| friction on vx.
            vx += _clip(ax, -AX_MAX, AX_MAX) * DT
            vy += _clip(ay, -AY_MAX, AY_MAX) * DT
            vx -= abs(normal(0.0, PLAYER_NOISE))  # §9 draw 2
            vx = max(_clip(vx, -VX_MAX, VX_MAX), 0.0)
            vy = _clip(vy, -VY_MAX, VY_MAX)
            if on_platform:  # §7.3
                vx = _clip(vx, 0.0, VX_GROUND)

            # §7.4-5: only the enemy of the player's half (decided before the player moves) moves.
            enemy2_active = x > PLATFORMS[1][0]
            x = _clip(x + vx * DT, 0.0, X_GOAL)
            y += vy * DT
            vx *= DECAY

            # §7.6: the enemy turns round at the ends of its platform, with a little noise on its speed.
            if enemy2_active:
                lo, hi = ENEMY_BOUNDS[1]
                ex, edx = e2x, e2dx
            else:
                lo, hi = ENEMY_BOUNDS[0]
                ex, edx = e1x, e1dx
            if not lo < ex < hi:
                edx = -edx
            edx += normal(0.0, ENEMY_NOISE)  # §9 draw 3
            edx = _clip(edx, -ENEMY_SPEED, ENEMY_SPEED)
            ex = _clip(ex + edx * DT, lo, hi)
            if enemy2_active:
                e2x, e2dx = ex, edx
            else:
                e1x, e1dx = ex, edx

            # §7.7: landing on (or bumping into) a platform; either way horizontal speed is lost. Only a
            # player below the walking surface can overlap a platform.
            if y < PLATFORM_HEIGHT:
                for px, w in PLATFORMS:
                    if px - PLAYER_W < x < px + w and -PLAYER_H < y < PLATFORM_HEIGHT:
                        x, y, vx, vy = _decollide(x, y, vx, vy, px, w)
                        vx = 0.0

            # §7.8-9. At the goal x == 1035 exactly, so this is also the goal reward (1035 - x0) / 1035.
            reward = (x - x0) / X_GOAL
            fell = y < PLATFORM_HEIGHT
            hit = (abs(x - e1x) < PLAYER_W or abs(x - e2x) < PLAYER_W) and (
                PLATFORM_HEIGHT - PLAYER_H < y < PLATFORM_HEIGHT + PLAYER_H
            )
            done = fell or hit or x >= X_GOAL
            # §6: run lasts 20 sub-steps; a jump lasts until the player stands on a platform again.
            if done or (substeps == RUN_SUBSTEPS if a == RUN else _on_platform(x, y)):
                break

        self.x, self.y, self.vx, self.vy = x, y, vx, vy
        self.e1x, self.e1dx, self.e2x, self.e2dx = e1x, e1dx, e2x, e2dx
        return self._observation(), reward, done, False, {"substeps": substeps}

    def render(self):
        if self.render_mode == "rgb_array":
            return draw_platform(self.x, self.y, self.e1x, self.e2x)
        return None

    # -- validation -----------------------------------------------------------------------------
    @staticmethod
    def _parse_action(action) -> tuple[int, float]:
        """Check ``action`` and return ``(a, p)``: ``p`` is ``p_a`` clipped into its box, as a float64."""
        expected = "(a, (p_run, p_hop, p_leap)) with a in {0, 1, 2} and each p a finite number or shape-(1,) array"
        if not isinstance(action, (tuple, list)) or len(action) != 2:
            raise ValueError(f"invalid Platform action {action!r}; expected {expected}")
        a, params = action
        if isinstance(a, np.ndarray) and a.shape == ():
            a = a.item()
        if isinstance(a, bool) or not isinstance(a, numbers.Integral) or not 0 <= a <= 2:
            raise ValueError(f"invalid discrete action {a!r}; expected {expected}")
        if not isinstance(params, (tuple, list)) or len(params) != 3:
            raise ValueError(f"invalid parameters {params!r}; expected {expected}")
        values = []
        for i, p in enumerate(params):
            arr = np.asarray(p)
            if arr.shape not in ((), (1,)) or arr.dtype.kind not in "iuf":
                raise ValueError(f"invalid parameter {i} {p!r}; expected {expected}")
            v = float(arr.reshape(()))
            if not math.isfinite(v):
                raise ValueError(f"parameter {i} is {v}; expected {expected}")
            values.append(v)
        a = int(a)
        return a, _clip(values[a], 0.0, PARAM_MAX[a])


# --- rendering ------------------------------------------------------------------------------------
RENDER_SCALE = 0.6
RENDER_WIDTH, RENDER_HEIGHT = int((X_GOAL + PLAYER_W) * RENDER_SCALE), int(200 * RENDER_SCALE)


def draw_platform(player_x: float, player_y: float, enemy1_x: float, enemy2_x: float) -> np.ndarray:
    """A ``(120, 633, 3)`` uint8 side view: grey platforms, red enemies, blue player, green goal line."""
    canvas = Canvas(RENDER_WIDTH, RENDER_HEIGHT, background=(235, 242, 250))
    s, h = RENDER_SCALE, RENDER_HEIGHT

    def box(x, y, w, hgt, color):  # world (y up) to image (y down)
        canvas.rect(x * s, h - (y + hgt) * s, (x + w) * s, h - y * s, color)

    for px, w in PLATFORMS:
        box(px, 0.0, w, PLATFORM_HEIGHT, (110, 110, 110))
    canvas.line(X_GOAL * s, 0, X_GOAL * s, h, (40, 170, 60), width=2)
    for ex in (enemy1_x, enemy2_x):
        box(ex, PLATFORM_HEIGHT, PLAYER_W, PLAYER_H, (210, 50, 50))
    box(player_x, player_y, PLAYER_W, PLAYER_H, (40, 80, 220))
    return canvas.image


def save_platform_gif(
    path: str | os.PathLike = "platform.gif",
    policy: Callable[[np.ndarray], object] | None = None,
    seed: int | None = None,
) -> tuple[str, float]:
    """Play one ``pamdp/Platform-v0`` episode (random actions if ``policy`` is None) into a GIF.

    Returns the GIF's path and the episode's return.
    """
    env = gymnasium.make("pamdp/Platform-v0", render_mode="rgb_array")
    try:
        return record_episode(env, policy, path, seed=seed, fps=PlatformEnv.metadata["render_fps"])
    finally:
        env.close()


def __getattr__(name: str):
    # ``PlatformVectorEnv`` lives in platform_vector.py, which imports this module's constants; resolving it
    # lazily keeps ``pamdp.envs.platform:PlatformVectorEnv`` (the registration's entry point) importable
    # without a circular import.
    if name == "PlatformVectorEnv":
        from pamdp.envs.platform_vector import PlatformVectorEnv

        return PlatformVectorEnv
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
