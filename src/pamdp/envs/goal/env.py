"""Robot Soccer Goal (Masson, Ranchod & Konidaris, AAAI 2016) and HyAR's Hard Goal as scalar Gymnasium envs.

From ``shared/specs/goal.md``: the Gym port ``cycraig/gym-goal`` (8e142be) with MP-DQN's 17 scaled features.
A player starts beside the ball on the left edge of a half pitch (x in [0, 20], y in [-15, 15]) and must
score past a keeper that guards the goal mouth y in [-7.01, 7.01] on the line x = 20. Actions:

====  ===================  ==============================  =============================================
 a    name                 parameters                      effect
====  ===================  ==============================  =============================================
 0    kick-to              (x, y) in [0, 40] x [-15, 15]   dribble: run to the ball and kick it towards
                                                           (x, x) (y is ignored, a quirk of the port)
                                                           until it is kickable and slow again
 1    shoot-goal-left      y in [-7.01, 7.01]              shoot at (20.4, y) until the episode ends
 2    shoot-goal-right     y in [-7.01, 7.01]              the same as action 1
====  ===================  ==============================  =============================================

Hard Goal (:class:`HardGoalEnv`) keeps action 0 and splits the shot into 2 x 5 actions, each a parameter
in [-1, 1] mapped into a fixed part of the goal mouth by HyAR's formula (:func:`hard_goal_shot`).

A step runs sub-steps of the simulation (``info["substeps"]``) until the action is done. A goal pays 50;
a ball caught by the keeper or out of the field ends the episode with minus its distance to the goal;
the 100th agent step ends it (truncated, without simulating) with the same penalty. Every other step pays
0. ``info["is_success"]`` at the end of an episode says whether it was a goal.

The dynamics are ``dynamics.step`` (compiled), shared with the batched envs in ``batched.py``.
"""

from __future__ import annotations

import gymnasium
import numpy as np
from gymnasium import spaces

import pamdp.envs.goal.dynamics as dyn
from pamdp.envs.goal.render import RENDER_FPS, draw_goal
from pamdp.envs.scalar import ScalarEnv, split_action
from pamdp.envs.vector import split_actions

__all__ = ["GoalEnv", "HardGoalEnv", "hard_goal_shot", "BUFFER_SIZE"]

BUFFER_SIZE = 4096
"""Uniform numbers kept drawn ahead per copy (a sub-step takes at most ``dynamics.SUBSTEP_DRAWS``)."""
KICK_LOW, KICK_HIGH = np.array([0.0, -15.0]), np.array([40.0, 15.0])
"""Kick-to's box, also the float64 bounds its parameters are clipped to (§4.1)."""
HARD_GOAL_INTERVALS = ((-1.0, -0.6), (-0.6, -0.2), (0.2, 0.2), (0.2, 0.6), (0.6, 1.0))
"""HyAR's five parts of the goal mouth, as positions in [-1, 1]; the third is HyAR's typo for
[-0.2, 0.2], so actions 3 and 8 always aim at the same point (§4.2)."""
_SLOPE = np.array([(lo - hi) / 2 for lo, hi in HARD_GOAL_INTERVALS])
_OFFSET = np.array([lo - 1 * m for (lo, _), m in zip(HARD_GOAL_INTERVALS, _SLOPE)])
_SHOT_RANGE, _SHOT_LOW = 14.020000457763672, -7.010000228881836
"""Goal's float32 shoot box, its width computed in float32, through which MP-DQN scales a position."""


def hard_goal_shot(j, p):
    """The goal-line y that Hard Goal's shot into part ``j`` (0..4) with parameter ``p`` aims at, before
    Goal's clip: HyAR's ``q = p * m_j + o_j`` (p = +1 gives the part's lower end; ``p`` is not clipped)
    scaled from [-1, 1] onto Goal's shoot box. Works on arrays."""
    q = p * _SLOPE[j] + _OFFSET[j]
    return (_SHOT_RANGE * (q + 1)) / 2.0 + _SHOT_LOW


class GoalEnv(ScalarEnv):
    """Robot Soccer Goal as a Gymnasium env (see the module docstring for the task).

    Action: ``(a, (p_kick, p_shoot_left, p_shoot_right))``, ``p_kick`` of shape ``(2,)`` and the others
    ``(1,)`` (a plain number is accepted for those); only ``p_a`` is read, clipped into its box. Actions
    that are malformed, or contain NaN or infinite parameters, raise ``ValueError``.

    Observation: 17 float64 features, nominally in [-1, 1] (``dynamics.observe``: the positions,
    velocities and orientations of player, keeper and ball, the unit vector from keeper to ball and where
    the keeper-ball line meets the goal line). The orientation is never wrapped and a ball that left the
    field lies outside, hence the unbounded box.

    Internal state (for tests and plots): :attr:`state`.

    Noise: every number is drawn from ``self.np_random`` (in blocks, used in the spec's order), so
    assigning ``numpy.random.RandomState(S)`` to ``np_random`` after ``reset()`` replays the original
    driven by the same generator; ``reset()`` without a seed keeps the generator.

    Args:
        render_mode: ``None`` or ``"rgb_array"``: :meth:`render` draws the field from above (see
            ``render.draw_goal``) and :meth:`render_substeps` every sub-step of the last step.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": RENDER_FPS}

    observe = staticmethod(dyn.observe)
    obs_size = dyn.OBS_SIZE

    def __init__(self, render_mode: str | None = None):
        obs_space = spaces.Box(-np.inf, np.inf, shape=(dyn.OBS_SIZE,), dtype=np.float64)
        states = np.zeros((1, dyn.STATE_SIZE))  # one row: the batched env's layout at N = 1
        super().__init__(render_mode, self.make_action_space(), obs_space, states, "random", BUFFER_SIZE)
        self._trace = np.empty((256 if render_mode else 0, dyn.TRACE_SIZE))
        self._substeps = 0
        self._started = False

    # -- the actions: Hard Goal changes only these two --------------------------------------------
    @staticmethod
    def make_action_space() -> spaces.Tuple:
        """``Tuple(Discrete(3), Tuple(Box(2), Box(1), Box(1)))``, float32 (§4.1)."""
        shoot = spaces.Box(np.float32(-dyn.HALF_GOAL), np.float32(dyn.HALF_GOAL), shape=(1,), dtype=np.float32)
        return spaces.Tuple((spaces.Discrete(3), spaces.Tuple((_kick_box(), shoot, shoot))))

    @staticmethod
    def shot_y(a: np.ndarray, p: np.ndarray) -> np.ndarray:
        """The goal-line y of shoot action ``a`` with float64 parameter ``p``, before the clip."""
        return p

    # -------------------------------------------------------------------------------------------
    @property
    def state(self) -> dict[str, np.ndarray]:
        """A copy of the internal state: ``player`` and ``keeper`` = [x, y, vx, vy, orientation],
        ``ball`` = [x, y, vx, vy], ``time`` = the agent steps taken this episode."""
        return {k: v[0] for k, v in _state_dict(self._states).items()}

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        streams = self._stream(dyn.RESET_DRAWS)
        streams.cursors[0] = dyn.reset(self._states[0], streams.buffers[0], streams.cursors[0])
        self._substeps = 0
        self._started = True
        return self._observation(), {"substeps": 0}

    def step(self, action):
        if not self._started:
            raise gymnasium.error.ResetNeeded("call reset() before step()")
        a, params = self._check_action(action)
        kick, tx, ty = self.targets(np.array([a]), [np.asarray(p, dtype=np.float64).reshape(1, -1) for p in params])
        streams = self._streams
        streams.follow(0, self.np_random)
        substeps, finished = 0, False
        while not finished:
            streams.refill(dyn.SUBSTEP_DRAWS)
            if 0 < self._trace.shape[0] == substeps:  # a long step: room for more frames
                self._trace = np.concatenate([self._trace, np.empty_like(self._trace)])
            reward, terminated, truncated, substeps, streams.cursors[0], finished = dyn.step(
                self._states[0], kick[0], tx[0], ty[0], streams.buffers[0], streams.cursors[0], substeps, self._trace
            )
        self._substeps = substeps
        info = {"substeps": substeps}
        if terminated or truncated:
            info["is_success"] = bool(terminated and reward == dyn.GOAL_REWARD)
        return self._observation(), reward, terminated, truncated, info

    def _frame(self):
        s = self._states[0]
        return draw_goal(*(s[k] for k in (dyn.PX, dyn.PY, dyn.PHI, dyn.KX, dyn.KY, dyn.PSI, dyn.BX, dyn.BY)))

    def render_substeps(self) -> list[np.ndarray]:
        """With ``render_mode="rgb_array"``: one frame per sub-step of the last step (none after a reset or
        on the time-limit step), the last one equal to :meth:`render`'s. ``pamdp.envs.rendering.record_episode``
        plays these."""
        return self._substep_frames(draw_goal)

    # -- actions ------------------------------------------------------------------------------------
    def _expected(self, n: int | None = None) -> str:
        k = self.action_space[0].n
        if n is None:
            return (
                f"(a, (p_0, ..., p_{k - 1})) with a in 0..{k - 1}, p_0 a finite array of shape (2,) and each "
                "other p a finite number or shape-(1,) array"
            )
        return (
            f"(a, (p_0, ..., p_{k - 1})) with a an int array of shape ({n},) in 0..{k - 1}, p_0 a finite array "
            f"of shape ({n}, 2) and each other p of shape ({n}, 1) or ({n},)"
        )

    def _check_action(self, action) -> tuple[int, list]:
        """Check one action's form; return ``a`` and the parameters as arrays of their box's shape."""
        expected, boxes = self._expected(), self.action_space[1]
        a, params = split_action(action, "Goal", self.action_space[0].n, len(boxes), expected)
        arrays = []
        for i, (p, box) in enumerate(zip(params, boxes)):
            arr = np.asarray(p)
            if arr.shape not in (box.shape, () if box.shape == (1,) else box.shape) or arr.dtype.kind not in "iuf":
                raise ValueError(f"invalid parameter {i} {p!r}; expected {expected}")
            if not np.isfinite(arr).all():
                raise ValueError(f"parameter {i} is {p!r}; expected {expected}")
            arrays.append(arr.reshape(box.shape))
        return a, arrays

    def check_actions(self, actions, n: int) -> tuple[np.ndarray, list]:
        """Check a batch of ``n`` actions (``batch_space`` of the action space); return ``a`` (n,) and the
        parameters as float64 arrays ``(n, size)``."""
        expected = self._expected(n)
        boxes = self.action_space[1]
        a, params = split_actions(actions, "Goal", n, expected, self.action_space[0].n, len(boxes))
        arrays = []
        for i, (p, box) in enumerate(zip(params, boxes)):
            p = np.asarray(p)
            size = box.shape[0]
            if p.shape not in ((n, size), (n,) if size == 1 else (n, size)) or p.dtype.kind not in "iuf":
                raise ValueError(f"invalid parameter {i} of shape {p.shape}: {p!r}; expected {expected}")
            p = p.reshape(n, size).astype(np.float64)
            if not np.isfinite(p).all():
                raise ValueError(f"parameter {i} contains {p[~np.isfinite(p)]}; expected {expected}")
            arrays.append(p)
        return a.astype(np.int64), arrays

    def targets(self, a: np.ndarray, params: list) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Each copy's ``(kick, tx, ty)`` for ``dynamics.step`` from checked actions: kick-to aims at
        ``(x, x)`` with ``x`` clipped into [0, 40] (§4.1), a shot at ``(20.4, y)`` with ``y`` clipped into
        [-7.01, 7.01] after :meth:`shot_y`."""
        rows = np.arange(a.size)
        x = np.clip(params[0][:, 0], KICK_LOW[0], KICK_HIGH[0])
        shots = np.stack([p[:, 0] for p in params[1:]])[np.maximum(a - 1, 0), rows]
        y = np.clip(self.shot_y(a, shots), -dyn.HALF_GOAL, dyn.HALF_GOAL)
        kick = a == dyn.KICK_TO
        return kick, np.where(kick, x, dyn.SHOOT_X), np.where(kick, x, y)


class HardGoalEnv(GoalEnv):
    """HyAR's Hard Goal: :class:`GoalEnv` with its shot split into 10 actions (§4.2).

    Action: ``(a, (p_kick, p_1, ..., p_10))``: ``a = 0`` is Goal's kick-to; ``a`` in 1..5 (and the same
    shots again as 6..10) shoots into part ``j = (a - 1) % 5`` of the goal mouth, with ``p`` in [-1, 1]
    (see :func:`hard_goal_shot`).
    """

    @staticmethod
    def make_action_space() -> spaces.Tuple:
        """``Tuple(Discrete(11), Tuple(Box(2), Box(1) x 10))``, float32: kick-to's box, then [-1, 1]."""
        shoot = spaces.Box(np.float32(-1.0), np.float32(1.0), shape=(1,), dtype=np.float32)
        return spaces.Tuple((spaces.Discrete(11), spaces.Tuple((_kick_box(),) + (shoot,) * 10)))

    @staticmethod
    def shot_y(a: np.ndarray, p: np.ndarray) -> np.ndarray:
        return hard_goal_shot((np.maximum(a, 1) - 1) % 5, p)


def _kick_box() -> spaces.Box:
    return spaces.Box(KICK_LOW.astype(np.float32), KICK_HIGH.astype(np.float32), dtype=np.float32)


def _state_dict(states: np.ndarray) -> dict[str, np.ndarray]:
    """Named parts of state rows, one row per copy."""
    return {
        "player": states[:, dyn.PX : dyn.PHI + 1].copy(),
        "keeper": states[:, dyn.KX : dyn.PSI + 1].copy(),
        "ball": states[:, dyn.BX : dyn.BVY + 1].copy(),
        "time": states[:, dyn.TIME].astype(np.int64),
    }
