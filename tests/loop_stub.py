"""What a family loop reads of an algorithm, around fixed functions: for testing the loops alone."""

from types import SimpleNamespace

import numpy as np
import torch

from pamdp.spaces import HybridActionSpace


def stub_algorithm(config, env, explore, update) -> SimpleNamespace:
    """An algorithm as :class:`~pamdp.algos.offpolicy.OffPolicyLoop` sees it: ``config``, the vector env ``env``,
    its spaces, the CPU, a seeded NumPy stream, and ``explore``/``update`` as ``_explore``/``_update``."""
    return SimpleNamespace(
        config=config,
        hybrid=HybridActionSpace.from_gym(env.single_action_space),
        obs_dim=env.single_observation_space.shape[0],
        device=torch.device("cpu"),
        vec_env=env,
        np_rng=np.random.default_rng(0),
        num_timesteps=0,
        _explore=explore,
        _update=update,
        _epoch_stats=lambda step: {},
    )
