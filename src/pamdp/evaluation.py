"""Greedy (or stochastic) evaluation of a trained model over many episodes, on the batched env."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from pamdp.algos.vector_env import make_vector_env

if TYPE_CHECKING:
    from pamdp.algos.base import Algorithm

__all__ = ["evaluate"]


def evaluate(
    model: Algorithm,
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
    env reports ``info["status"]`` (Half Field Offense), also ``goal_rate`` and ``mean_steps_to_goal``
    (``None`` when no goal was scored).
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
    statuses: list[str] = []
    ep_return, ep_length = np.zeros(num_envs), np.zeros(num_envs, dtype=np.int64)
    done_count = np.zeros(num_envs, dtype=np.int64)
    prev_done = np.zeros(num_envs, dtype=bool)
    obs, _ = env.reset(seed=seed)
    try:
        while np.any(done_count < quota):
            action = model.predict(obs, deterministic=deterministic)
            obs, reward, terminated, truncated, info = env.step(action)
            valid = ~prev_done
            ep_return += np.where(valid, reward, 0.0)
            ep_length += valid
            done = (terminated | truncated) & valid
            for i in np.flatnonzero(done):
                if done_count[i] < quota[i]:
                    returns.append(float(ep_return[i]))
                    lengths.append(int(ep_length[i]))
                    if "status" in info:
                        statuses.append(str(info["status"][i]))
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
    if statuses:
        goals = np.array([s == "GOAL" for s in statuses])
        result["goal_rate"] = float(goals.mean())
        result["mean_steps_to_goal"] = float(np.mean(np.array(lengths)[goals])) if goals.any() else None
    return result
