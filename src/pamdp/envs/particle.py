"""HyAR's particle world, the plane of Catch Point and Hard Move, compiled by Numba.

Written once from HyAR's code (``TJU-DRL-LAB/AI-Optimizer``; Li et al., ICLR 2022) (section numbers in
comments refer to them). One agent, pushed by a force, moves on an unbounded plane towards a fixed target
point; nothing in a step is random. :func:`catch_point_step` and :func:`hard_move_step` advance one copy by
one agent step; :func:`catch_point_copies` / :func:`hard_move_copies` loop them over the copies (the scalar
env's one copy included).

A copy's state is a float64 row of :data:`STATE_SIZE` numbers (:data:`AX` ... :data:`FAILS`), updated in
place. The only random numbers are the reset's four uniforms: the original's ``np.random.uniform(-1, 1, 2)``
for the agent, then again for the target; ``uniform(a, b)`` is ``a + (b - a) * u`` with ``u`` the next
``random()`` of the same generator, bit for bit (``RandomState`` and ``Generator`` alike), so
:func:`reset` reads four such numbers from a buffer of ``random()`` draws (``pamdp.envs.vector``).

All arithmetic is float64, in the specs' order, with ``fastmath`` off (reassociation or fused
multiply-adds would change the roundings). Everything the compiled functions read is defined in this file:
Numba's on-disk cache is keyed on this file alone.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from gymnasium import spaces

from pamdp.envs.rendering import Canvas
from pamdp.envs.vector import Domain

# --- §1 constants -----------------------------------------------------------------------------------
DT = 0.1
DAMPING = 0.25
"""The velocity is multiplied by ``1 - DAMPING`` = 0.75 before each push."""
MASS = 1.0
FORCE_GAIN = 2.0
CATCH_RADIUS = 0.2
RADIUS_SQUARED = CATCH_RADIUS**2
"""Catch Point's catch and Hard Move's arrival test ``d2 <= 0.2 ** 2`` (0.04000000000000001, not 0.04)."""
BONUS = 20.0
"""Reward of a success: ``-(d2 - 20)``."""
MAX_FAILED_CATCHES = 11
"""Catch Point: with this many failed catches the next step rewards 0 and ends the episode."""
MOVE, CATCH = 0, 1
"""Catch Point's two discrete actions."""

# --- the state of one copy --------------------------------------------------------------------------
AX, AY, VX, VY, GX, GY, FAILS = range(7)
"""Agent position, agent velocity, target position, failed catches (Catch Point only; a whole number)."""
STATE_SIZE = 7
OBS_SIZE = 4
RESET_DRAWS = 4
"""Uniform draws per reset (agent x, y, then target x, y); a step draws none."""

jit = numba.njit(cache=True, fastmath=False, nogil=True)


@jit
def reset(state, draws, cursor):
    """Start an episode (catch_point.md §5): agent and target uniform in [-1, 1]^2, agent first, at rest.
    ``draws[cursor:]`` holds at least :data:`RESET_DRAWS` ``random()`` numbers; returns the next cursor."""
    state[AX] = -1.0 + 2.0 * draws[cursor]
    state[AY] = -1.0 + 2.0 * draws[cursor + 1]
    state[GX] = -1.0 + 2.0 * draws[cursor + 2]
    state[GY] = -1.0 + 2.0 * draws[cursor + 3]
    state[VX] = state[VY] = state[FAILS] = 0.0
    return cursor + RESET_DRAWS


@jit
def push(state, fx, fy):
    """Integrate one step under the force ``(fx, fy)`` (catch_point.md §4) and return the squared distance
    to the target after it, as products (not ``** 2``)."""
    vx = state[VX] * (1.0 - DAMPING) + (fx / MASS) * DT
    vy = state[VY] * (1.0 - DAMPING) + (fy / MASS) * DT
    state[VX], state[VY] = vx, vy
    state[AX] += vx * DT
    state[AY] += vy * DT
    dx = state[AX] - state[GX]
    dy = state[AY] - state[GY]
    return dx * dx + dy * dy


@jit
def catch_point_step(state, a, theta):
    """One Catch Point step (catch_point.md §3-4): ``a`` is :data:`MOVE` (push in direction ``theta``,
    radians from +y towards +x, not wrapped) or :data:`CATCH`. Returns ``(reward, terminated, caught)``."""
    if a == MOVE:
        fx, fy = 0.0 + math.sin(theta) * FORCE_GAIN, 0.0 + math.cos(theta) * FORCE_GAIN
    else:
        fx, fy = 0.0, 0.0
    d2 = push(state, fx, fy)
    caught = False
    if state[FAILS] < MAX_FAILED_CATCHES:  # the budget test uses the count before this step's catch
        if a == CATCH and d2 <= RADIUS_SQUARED:  # tested after this step's (force-free) move
            reward = -(d2 - BONUS)
            caught = True
        else:
            if a == CATCH:
                state[FAILS] += 1.0
            reward = -d2
    else:
        reward = 0.0
    # HyAR's scripts end an episode by the reward's value: r > 4 is a catch, r == 0 the spent budget.
    return reward, reward > 4.0 or reward == 0.0, caught


@jit
def hard_move_step(state, mx, my, p):
    """One Hard Move step (hard_move.md §2-3) with the chosen pattern's motion ``(mx, my)`` and its
    parameter ``p`` (not clipped). Returns ``(reward, terminated)``: terminated on reaching the target."""
    d2 = push(state, 0.0 + (mx * p) * FORCE_GAIN, 0.0 + (my * p) * FORCE_GAIN)
    reward = -(d2 - BONUS) if d2 <= RADIUS_SQUARED else -d2
    return reward, reward > 4.0


@jit
def catch_point_copies(states, a, theta, resetting, draws, cursors, obs, rewards, terminated, caught):
    """One step of every copy: those with ``resetting[i]`` start an episode (:func:`reset`, reading their
    own ``draws[i]`` at ``cursors[i]``), the others take :func:`catch_point_step` with ``a[i]`` and
    ``theta[i]``; then every copy's observation goes into ``obs``. The actions are checked before anything
    changes: returns the first copy whose ``a`` is neither move nor catch or whose ``theta`` is not
    finite, else -1. One compiled call per batched step: each call costs as much as a few hundred copies."""
    n = states.shape[0]
    for i in range(n):
        if not (a[i] == MOVE or a[i] == CATCH) or not math.isfinite(theta[i]):
            return i
    for i in range(n):
        if resetting[i]:
            cursors[i] = reset(states[i], draws[i], cursors[i])
        else:
            rewards[i], terminated[i], caught[i] = catch_point_step(states[i], a[i], theta[i])
    observe(states, obs)
    return -1


@jit
def hard_move_copies(states, a, p, motions, resetting, draws, cursors, obs, rewards, terminated):
    """:func:`catch_point_copies` for Hard Move: copy ``i`` that is not resetting takes
    :func:`hard_move_step` with ``motions[a[i]]`` and ``p[i]`` (both checked by the parser)."""
    for i in range(states.shape[0]):
        if resetting[i]:
            cursors[i] = reset(states[i], draws[i], cursors[i])
        else:
            rewards[i], terminated[i] = hard_move_step(states[i], motions[a[i], 0], motions[a[i], 1], p[i])
    observe(states, obs)


@jit
def reset_copies(states, mask, draws, cursors):
    """:func:`reset` every copy ``i`` with ``mask[i]``, reading its own ``draws[i]`` at ``cursors[i]``."""
    for i in range(states.shape[0]):
        if mask[i]:
            cursors[i] = reset(states[i], draws[i], cursors[i])


@jit
def observe(states, out):
    """Each copy's observation ``[Vx, Vy, Gx - Ax, Gy - Ay]`` into the rows of ``out``."""
    for i in range(states.shape[0]):
        s = states[i]
        out[i, 0], out[i, 1] = s[VX], s[VY]
        out[i, 2], out[i, 3] = s[GX] - s[AX], s[GY] - s[AY]


# --- what both domains' contracts share ------------------------------------------------------------
class ParticleDomain(Domain):
    """The part of Catch Point's and Hard Move's contracts that is the plane's: the state row, the observation,
    the resets (four uniforms each, 256 episodes' worth drawn at a time per copy, none ahead in the scalar env)
    and the last actions their pictures show. A subclass adds its actions, its step and its ``info``."""

    render_fps = 10
    """One frame per agent step (dt = 0.1 s) plays an episode in real time."""
    state_size = STATE_SIZE
    reset_draws = scalar_buffer_size = RESET_DRAWS
    buffer_size = RESET_DRAWS * 256

    def __init__(self):
        self.observation_space = spaces.Box(-np.inf, np.inf, shape=(OBS_SIZE,), dtype=np.float64)

    def initial_states(self, n):
        self.last_actions, self.last_params = np.full(n, -1, dtype=np.int64), np.zeros(n)  # for the pictures
        return np.zeros((n, STATE_SIZE))

    def reset(self, env, mask, options, seeded, obs):
        reset_copies(env._states, mask, env.streams.buffers, env.streams.cursors)
        self.last_actions[mask] = -1
        observe(env._states, obs)
        return self.infos(env)

    def infos(self, env, stepped=None, success=None) -> dict:
        """The batched ``info`` of a reset (``stepped`` None) or a step."""
        return {} if stepped is None else {"is_success": success, "_is_success": stepped}

    def stepped(self, env, resetting, a, p, success) -> dict:
        """The end of a step: the actions ``(a, p)`` the pictures show (none where a copy was reset) and the batched
        ``info`` (as Gymnasium's vector envs merge the scalar envs' infos: a copy that was reset reports nothing)."""
        if env.render_mode is not None:
            self.last_actions[:], self.last_params[:] = np.where(resetting, -1, a), p
        return self.infos(env, ~resetting, success)

    def shown_action(self, i: int) -> int | None:
        """Copy ``i``'s last action, None after a reset."""
        return None if self.last_actions[i] < 0 else int(self.last_actions[i])


# --- the top view both domains draw ----------------------------------------------------------------
VIEW = 2.0
"""The pictures show the square [-2, 2]^2 (agent and target start in [-1, 1]^2)."""
PIXELS_PER_UNIT = 80
RENDER_SIZE = int(2 * VIEW * PIXELS_PER_UNIT)


def to_pixels(x: float, y: float) -> tuple[float, float]:
    """World (y up, origin in the centre) to image pixels (y down)."""
    return (x + VIEW) * PIXELS_PER_UNIT, (VIEW - y) * PIXELS_PER_UNIT


def draw_plane(state: np.ndarray) -> Canvas:
    """A canvas with the plane of one copy (its state row): the start square [-1, 1]^2 and the target
    (green, with its 0.2 ring). The domains draw their marks on it, then :func:`draw_agent`."""
    canvas = Canvas(RENDER_SIZE, RENDER_SIZE, background=(245, 245, 240))
    (x0, y0), (x1, y1) = to_pixels(-1.0, 1.0), to_pixels(1.0, -1.0)
    for xa, ya, xb, yb in ((x0, y0, x1, y0), (x1, y0, x1, y1), (x1, y1, x0, y1), (x0, y1, x0, y0)):
        canvas.line(xa, ya, xb, yb, (200, 200, 200))
    gx, gy = to_pixels(state[GX], state[GY])
    canvas.circle(gx, gy, CATCH_RADIUS * PIXELS_PER_UNIT, (40, 160, 60), outline=2.0)
    canvas.circle(gx, gy, 4.0, (40, 160, 60))
    return canvas


def draw_agent(canvas: Canvas, state: np.ndarray) -> None:
    """The agent of one copy: a blue disc with its velocity as a line (drawn at twice its value, the
    distance covered in two seconds at that speed), or a hollow ring on the border of the picture where
    the agent is out of view."""
    margin = 6.0 / PIXELS_PER_UNIT
    ax, ay = (min(max(v, -VIEW + margin), VIEW - margin) for v in (state[AX], state[AY]))
    px, py = to_pixels(ax, ay)
    if (ax, ay) != (state[AX], state[AY]):
        canvas.circle(px, py, 6.0, (40, 80, 220), outline=2.0)
        return
    vx, vy = to_pixels(ax + 2.0 * state[VX], ay + 2.0 * state[VY])
    canvas.line(px, py, vx, vy, (40, 80, 220), width=2.0)
    canvas.circle(px, py, 6.0, (40, 80, 220))
