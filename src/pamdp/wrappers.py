"""Action wrappers that turn a hybrid action space into an ordinary one, for mainstream RL libraries.

The two classic ways of applying a standard algorithm to a parameterized action space, as baselines:

- :class:`FlattenHybridAction` (*continualization*): one ``Box(-1, 1, (K + sum_a m_a,))``, K action scores
  followed by every action's parameters; the executed action is the argmax of the scores with its own
  parameters. This is PADDPG's action representation, and lets continuous-action algorithms (SAC, TD3, PPO
  with a Gaussian policy, e.g. from Stable-Baselines3) run on ``pamdp/Platform-v0`` and
  ``pamdp/HalfFieldOffense-v0``.
- :class:`DiscretizeHybridAction` (*discretization*): one ``Discrete(sum_a bins^m_a)``, every action with
  its parameters on a grid of ``bins`` values per dimension, for discrete-action algorithms (DQN).

Both wrap a scalar Gymnasium env whose action space is ``Tuple(Discrete(K), Tuple(Box(m_0,), ...))``::

    env = FlattenHybridAction(gymnasium.make("pamdp/Platform-v0"))
    env.action_space          # Box(-1.0, 1.0, (6,), float32): 3 scores, then run, hop and leap parameters

The wrapped env's own action is always available as ``env.hybrid_action(action)``.
"""

from __future__ import annotations

import itertools

import gymnasium
import numpy as np
from gymnasium import spaces

from pamdp.spaces import HybridActionSpace

__all__ = ["FlattenHybridAction", "DiscretizeHybridAction"]


class FlattenHybridAction(gymnasium.ActionWrapper, gymnasium.utils.RecordConstructorArgs):
    """A hybrid action space as ``Box(-1, 1, (K + sum_a m_a,))``: K scores, then each action's parameters.

    An action vector ``v`` executes ``a = argmax(v[:K])`` (the first on ties) with parameters
    ``v[K + o_a : K + o_a + m_a]`` (``o_a = m_0 + ... + m_{a-1}``), mapped affinely from ``[-1, 1]`` to action
    ``a``'s box; values outside ``[-1, 1]`` are clipped. The other actions' parameters are ignored.
    """

    def __init__(self, env: gymnasium.Env):
        gymnasium.utils.RecordConstructorArgs.__init__(self)
        gymnasium.ActionWrapper.__init__(self, env)
        self.hybrid = HybridActionSpace.from_gym(env.action_space)
        k = self.hybrid.n_actions
        self.action_space = spaces.Box(-1.0, 1.0, (k + self.hybrid.total_param_size,), np.float32)
        self._offsets = k + self.hybrid.param_offsets

    def hybrid_action(self, action) -> tuple:
        """The wrapped env's action ``(a, (p_0, ..., p_{K-1}))`` for a flat action vector."""
        v = np.asarray(action, dtype=np.float64)
        if v.shape != self.action_space.shape:
            raise ValueError(
                f"action of shape {v.shape}; expected {self.action_space.shape} (K scores, then parameters)"
            )
        if not np.all(np.isfinite(v)):
            raise ValueError(f"action {v} has non-finite entries; expected finite values in [-1, 1]")
        k = self.hybrid.n_actions
        a = int(np.argmax(v[:k]))
        x = np.zeros(self.hybrid.max_param_size)
        m = self.hybrid.param_sizes[a]
        x[:m] = v[self._offsets[a] : self._offsets[a] + m]
        return self.hybrid.to_env(a, x)

    def action(self, action):
        return self.hybrid_action(action)


class DiscretizeHybridAction(gymnasium.ActionWrapper, gymnasium.utils.RecordConstructorArgs):
    """A hybrid action space as ``Discrete(sum_a bins^m_a)``: each action with its parameters on a grid.

    Each parameter dimension takes ``bins`` evenly spaced values from its low to its high bound (both
    included; the centre with ``bins = 1``). Indices enumerate action 0's grid points first, then action 1's,
    and so on; within an action, the last parameter varies fastest. An action without parameters
    (``m_a = 0``) has one index.
    """

    def __init__(self, env: gymnasium.Env, bins: int = 5):
        gymnasium.utils.RecordConstructorArgs.__init__(self, bins=bins)
        gymnasium.ActionWrapper.__init__(self, env)
        if isinstance(bins, bool) or not isinstance(bins, (int, np.integer)) or bins < 1:
            raise ValueError(f"bins = {bins!r}; expected an integer >= 1 (values per parameter dimension)")
        self.bins = int(bins)
        self.hybrid = HybridActionSpace.from_gym(env.action_space)
        grid = np.linspace(-1.0, 1.0, self.bins) if self.bins > 1 else np.zeros(1)
        table: list[tuple[int, np.ndarray]] = []
        for a, m in enumerate(self.hybrid.param_sizes):
            for point in itertools.product(grid, repeat=m):
                x = np.zeros(self.hybrid.max_param_size)
                x[:m] = point
                table.append((a, x))
        self._table = table
        self.action_space = spaces.Discrete(len(table))

    def hybrid_action(self, action) -> tuple:
        """The wrapped env's action ``(a, (p_0, ..., p_{K-1}))`` for a grid index."""
        i = int(action)
        if i != action or not 0 <= i < len(self._table):
            raise ValueError(f"action {action!r}; expected an integer in 0..{len(self._table) - 1}")
        a, x = self._table[i]
        return self.hybrid.to_env(a, x)

    def action(self, action):
        return self.hybrid_action(action)
