"""Platform (Masson, Ranchod & Konidaris, AAAI 2016) as a scalar Gymnasium env, from ``shared/specs/platform.md``.

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

The dynamics are ``physics.step`` (compiled), shared with the batched env ``batched.PlatformVectorEnv``.
"""

from __future__ import annotations

import numpy as np
from gymnasium import spaces

import pamdp.envs.platform.physics as physics
from pamdp.envs.platform.render import RENDER_FPS, draw_platform
from pamdp.envs.scalar import ScalarEnv, number, split_action

__all__ = ["PlatformEnv", "ZeroNoise", "platform_action_space", "parse_action", "BUFFER_SIZE"]

BUFFER_SIZE = 2048
"""Standard normals kept drawn ahead per copy (a step takes ~150, at most ``physics.MAX_DRAWS``)."""


class ZeroNoise:
    """A stand-in for a generator whose standard normals are all zero: the noise-free dynamics.

    Assign it after ``reset()``: ``env.unwrapped.np_random = ZeroNoise()`` for the scalar env,
    ``venv.np_randoms = [ZeroNoise()] * venv.num_envs`` for the batched one. A seeded ``reset(seed=...)``
    installs fresh generators again.
    """

    def standard_normal(self, size=None):
        return 0.0 if size is None else np.zeros(size)


def platform_action_space() -> spaces.Tuple:
    """``Tuple(Discrete(3), Tuple(Box(1), Box(1), Box(1)))`` with boxes [0, 30], [0, 720], [0, 430] (§3)."""
    boxes = tuple(spaces.Box(np.float32(0.0), np.float32(hi), shape=(1,), dtype=np.float32) for hi in physics.PARAM_MAX)
    return spaces.Tuple((spaces.Discrete(3), spaces.Tuple(boxes)))


class PlatformEnv(ScalarEnv):
    """The Platform domain as a Gymnasium env (see the module docstring for the task).

    Action: ``(a, (p_run, p_hop, p_leap))`` with ``a`` in {0, 1, 2} and each ``p`` an array of shape
    ``(1,)`` (a plain number is accepted too); only ``p_a`` is read, after clipping into its box.
    Actions that are malformed, or contain NaN or infinite parameters, raise ``ValueError``.

    Observation: the 9 features of ``physics.observe``, float64 in ``[0, 1]``. The reference's
    observation is ``(s, k)`` with ``k`` the sub-steps of the last step; here ``k`` is
    ``info["substeps"]`` (0 after reset).

    Internal state (read it for tests and plots, not to control the env): ``player`` =
    ``[x, y, vx, vy]`` and ``enemies`` = ``[[x1, dx1], [x2, dx2]]`` via :attr:`state`.

    Noise: the step draws standard normals from ``self.np_random`` in blocks and uses them in the
    order of the spec's §9, so the numbers it consumes are exactly its generator's stream. Assign
    ``numpy.random.RandomState(S)`` to ``np_random`` after ``reset()`` to replay the reference
    implementation driven by the same generator, bit for bit, or :class:`ZeroNoise` for the noise-free
    dynamics (the numbers drawn ahead from the previous generator are dropped); ``reset(seed=...)``
    installs a fresh generator.

    Args:
        render_mode: ``None`` or ``"rgb_array"``: :meth:`render` draws the course now (see
            ``render.draw_platform``) and :meth:`render_substeps` every sub-step of the last step.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": RENDER_FPS}

    observe = staticmethod(physics.observe)
    obs_size = physics.OBS_SIZE

    def __init__(self, render_mode: str | None = None):
        obs_space = spaces.Box(0.0, 1.0, shape=(physics.OBS_SIZE,), dtype=np.float64)
        states = physics.INITIAL_STATE[None].copy()  # one row: the batched env's layout at N = 1
        super().__init__(render_mode, platform_action_space(), obs_space, states, "standard_normal", BUFFER_SIZE)
        self._trace = np.empty((physics.MAX_SUBSTEPS if render_mode else 0, physics.TRACE_SIZE))
        self._substeps = 0

    @property
    def state(self) -> dict[str, np.ndarray]:
        """A copy of the internal state: ``player`` = [x, y, vx, vy], ``enemies`` = [[x, dx], [x, dx]]."""
        s = self._states[0]
        return {"player": s[physics.X : physics.VY + 1].copy(), "enemies": s[physics.E1X :].reshape(2, 2).copy()}

    # -- Gymnasium API --------------------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        self._states[0] = physics.INITIAL_STATE
        self._substeps = 0
        return self._observation(), {"substeps": 0}

    def step(self, action):
        a, p = parse_action(action)
        streams = self._stream(physics.MAX_DRAWS)
        reward, terminated, substeps, streams.cursors[0] = physics.step(
            self._states[0], a, p, streams.buffers[0], streams.cursors[0], self._trace
        )
        self._substeps = substeps
        return self._observation(), reward, terminated, False, {"substeps": substeps}

    def _frame(self):
        s = self._states[0]
        return draw_platform(s[physics.X], s[physics.Y], s[physics.E1X], s[physics.E2X])

    def render_substeps(self) -> list[np.ndarray]:
        """With ``render_mode="rgb_array"``: one frame per sub-step of the last step (none after a reset),
        the last one equal to :meth:`render`'s. ``pamdp.envs.rendering.record_episode`` plays these."""
        return self._substep_frames(draw_platform)


def parse_action(action) -> tuple[int, float]:
    """Check one Platform ``action``; return ``(a, p)``: ``p`` is ``p_a`` clipped into its box, a float64."""
    expected = "(a, (p_run, p_hop, p_leap)) with a in {0, 1, 2} and each p a finite number or shape-(1,) array"
    a, params = split_action(action, "Platform", 3, 3, expected)
    values = [number(p, i, expected) for i, p in enumerate(params)]
    return a, min(max(values[a], 0.0), physics.PARAM_MAX[a])
