"""Greedy (or stochastic) evaluation of a trained model over many episodes, on the batched env.

Training's greedy evaluations call it (``Algorithm.learn(eval_every=...)``), so it imports no algorithm, not even
for its types: a model is any :class:`~pamdp.algos.base.Algorithm`.
"""

from __future__ import annotations

import numpy as np

from pamdp.algos.logger import success_summary, successes
from pamdp.algos.vector_env import info_action_masks, make_vector_env

__all__ = ["evaluate"]


def evaluate(
    model,
    episodes: int = 1000,
    seed: int = 0,
    deterministic: bool = True,
    num_envs: int = 50,
    env_id: str | None = None,
    env_kwargs: dict | None = None,
) -> dict[str, float]:
    """Play ``episodes`` whole episodes and summarise them.

    Each of the ``num_envs`` copies plays a fixed share of the episodes, so that short episodes are not
    over-represented. Returns ``mean_return``, ``std_return``, ``mean_length`` and ``episodes``; when the
    env reports ``info["is_success"]`` at an episode's end (a goal on Half Field Offense and Goal, a target
    reached or caught on the others), also ``success_rate`` and ``mean_steps_to_success`` (``None`` when no
    episode succeeded), over the episodes that reported it.
    """
    if episodes < 1:
        raise ValueError(f"episodes = {episodes!r}; expected an integer >= 1")
    env_id = env_id or model.env_id
    if env_id is None:
        raise ValueError("the model's env is not registered; pass env_id= to evaluate it")
    num_envs = min(num_envs, episodes)
    env = make_vector_env(env_id, num_envs, model.env_kwargs if env_kwargs is None else env_kwargs)
    quota = np.array([episodes // num_envs + (i < episodes % num_envs) for i in range(num_envs)])
    returns: list[float] = []
    lengths: list[int] = []
    succeeded: list[bool | None] = []
    ep_return, ep_length = np.zeros(num_envs), np.zeros(num_envs, dtype=np.int64)
    done_count = np.zeros(num_envs, dtype=np.int64)
    prev_done = np.zeros(num_envs, dtype=bool)
    obs, info = env.reset(seed=seed)
    masked = model.config.action_mask  # the env's info["action_mask"], as in training
    try:
        while np.any(done_count < quota):
            mask = info_action_masks(info, num_envs, model.hybrid.n_actions) if masked else None
            action = model.predict(obs, deterministic=deterministic, action_mask=mask)
            obs, reward, terminated, truncated, info = env.step(action)
            valid = ~prev_done
            ep_return += np.where(valid, reward, 0.0)
            ep_length += valid
            done = (terminated | truncated) & valid
            for i, success in zip(np.flatnonzero(done), successes(info, done)):
                if done_count[i] < quota[i]:
                    returns.append(float(ep_return[i]))
                    lengths.append(int(ep_length[i]))
                    succeeded.append(success)
                    done_count[i] += 1
            ep_return[done], ep_length[done] = 0.0, 0
            prev_done = done
    finally:
        env.close()
    result = {
        "mean_return": float(np.mean(returns)),
        "std_return": float(np.std(returns)),
        "mean_length": float(np.mean(lengths)),
        "episodes": len(returns),
    }
    summary = success_summary(lengths, succeeded)
    if summary is not None:
        result["success_rate"], result["mean_steps_to_success"] = summary
    return result
