"""Goal and Hard Goal as one pamdp domain: its contract and its envs (the task: ``pamdp.envs.goal``). Actions,
observations, ``state``, ``info`` and the noise's exact replay: ``docs/environments.md``, "Robot Soccer Goal and
Hard Goal" and "Each domain's batched actions, ``state`` and ``info``"."""

from __future__ import annotations

import numpy as np
from gymnasium import spaces

import pamdp.envs.goal.dynamics as dyn
from pamdp.envs.goal.dynamics import hard_goal_shot
from pamdp.envs.goal.render import RENDER_FPS, draw_goal
from pamdp.envs.scalar import env_classes
from pamdp.envs.vector import Domain, column, every_copy, hybrid_space, split_actions

__all__ = ["Goal", "GoalEnv", "HardGoalEnv", "GoalVectorEnv", "HardGoalVectorEnv", "hard_goal_shot"]

_DRAWN = (dyn.PX, dyn.PY, dyn.PHI, dyn.KX, dyn.KY, dyn.PSI, dyn.BX, dyn.BY)


class Goal(Domain):
    name = "Goal"
    render_fps = RENDER_FPS
    state_size = dyn.STATE_SIZE
    reset_draws = dyn.RESET_DRAWS
    step_draws = dyn.SUBSTEP_DRAWS  # at least one sub-step's numbers; a step is resumed after a top-up
    buffer_size = scalar_buffer_size = 4096

    def __init__(self, hard: bool = False):
        self.hard = bool(hard)
        lo, hi, k = (-1.0, 1.0, 10) if self.hard else (-dyn.HALF_GOAL, dyn.HALF_GOAL, 2)
        self.action_space = hybrid_space((dyn.KICK_LOW, dyn.KICK_HIGH, 2), *[(lo, hi, 1)] * k)
        self.observation_space = spaces.Box(-np.inf, np.inf, shape=(dyn.OBS_SIZE,), dtype=np.float64)
        self.trace = np.empty((256, dyn.TRACE_SIZE))  # the scalar env's sub-steps, grown for a long step
        self.substeps = 0

    def state(self, states):
        return {
            "player": states[:, dyn.PX : dyn.PHI + 1].copy(),
            "keeper": states[:, dyn.KX : dyn.PSI + 1].copy(),
            "ball": states[:, dyn.BX : dyn.BVY + 1].copy(),
            "time": states[:, dyn.TIME].astype(np.int64),
        }

    def parse(self, actions, n):
        """Each copy's ``(kick, tx, ty)`` for ``dynamics.step_copies`` (see ``dynamics.targets``)."""
        k = self.action_space[0].n
        expected = (
            f"(a, (p_0, ..., p_{k - 1})) with a an int array of shape ({n},) in 0..{k - 1}, p_0 a finite array "
            f"of shape ({n}, 2) and each other p of shape ({n}, 1) or ({n},)"
        )
        a, params = split_actions(actions, self.name, n, expected, k, k)
        boxes = enumerate(zip(params, self.action_space[1]))
        columns = [column(p, n, i, expected, box.shape[0], finite=True).astype(np.float64) for i, (p, box) in boxes]
        return dyn.targets(a.astype(np.int64), columns, self.hard)

    def reset(self, env, mask, options, seeded, obs):
        dyn.reset_copies(env._states, mask, env.streams.buffers, env.streams.cursors)
        self.substeps = 0
        dyn.observe(env._states, obs)
        return every_copy(env.num_envs, substeps=np.zeros(env.num_envs, dtype=np.int64))

    def step(self, env, parsed, resetting, obs, rewards, terminated, truncated):
        """A copy whose numbers run out mid-step stops; its numbers are topped up and the copies still pending
        resume (a shot can take more numbers than a copy keeps drawn ahead)."""
        (kick, tx, ty), n, streams = parsed, env.num_envs, env.streams
        dyn.reset_copies(env._states, resetting, streams.buffers, streams.cursors)
        substeps, pending = np.zeros(n, dtype=np.int64), ~resetting
        trace = self.trace if n == 1 and env.render_mode else self.trace[:0]  # no rows: no record
        while dyn.step_copies(
            env._states, kick, tx, ty, pending, streams.buffers, streams.cursors, substeps, rewards, terminated,
            truncated, trace,
        ):  # fmt: skip
            streams.refill(dyn.SUBSTEP_DRAWS)
            if 0 < trace.shape[0] == substeps[0]:  # a long step: room for more frames
                self.trace = trace = np.concatenate([trace, np.empty_like(trace)])
        self.substeps = int(substeps[0])
        infos = every_copy(n, substeps=substeps)
        infos["is_success"], infos["_is_success"] = terminated & (rewards == dyn.GOAL_REWARD), terminated | truncated
        dyn.observe(env._states, obs)
        return infos

    def frame(self, env, i):
        return draw_goal(*(env._states[i, k] for k in _DRAWN))

    def substep_frames(self, env):
        return [draw_goal(*row) for row in self.trace[: self.substeps]]


GoalEnv, GoalVectorEnv = env_classes(Goal, __name__, "GoalEnv", "GoalVectorEnv")
HardGoalEnv, HardGoalVectorEnv = env_classes(Goal, __name__, "HardGoalEnv", "HardGoalVectorEnv", hard=True)
