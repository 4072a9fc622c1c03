"""Greedy (or stochastic) evaluation of a trained model over many episodes, on the batched env.

Training's greedy evaluations call it (``Algorithm.learn(eval_every=...)``), so it imports no algorithm, not even
for its types: a model is any :class:`~pamdp.algos.base.Algorithm`.
"""

from __future__ import annotations

import numpy as np

from pamdp.envs.backends import make_vector_env
from pamdp.envs.stepping import VectorStepper, success_summary

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
    episode succeeded), over the episodes that reported it; when it reports ``info["status"]`` (Half Field
    Offense's GOAL, CAPTURED_BY_DEFENSE, ...), also ``endings``, each status's share of those episodes.
    """
    integer = isinstance(episodes, (int, np.integer)) and not isinstance(episodes, (bool, np.bool_))
    if not (integer or isinstance(episodes, (float, np.floating)) and float(episodes).is_integer()) or episodes < 1:
        raise ValueError(f"episodes = {episodes!r}; expected an integer >= 1")
    episodes = int(episodes)
    env_id = env_id or model.env_id
    if env_id is None:
        raise ValueError("the model's env is not registered; pass env_id= to evaluate it")
    num_envs = min(num_envs, episodes)
    env = make_vector_env(env_id, num_envs, model.env_kwargs if env_kwargs is None else env_kwargs)
    quota = np.array([episodes // num_envs + (i < episodes % num_envs) for i in range(num_envs)])
    returns: list[float] = []
    lengths: list[int] = []
    succeeded: list[bool | None] = []
    endings: dict[str, int] = {}
    done_count = np.zeros(num_envs, dtype=np.int64)
    # the env's info["action_mask"], as in training
    stepper = VectorStepper(env, model.hybrid.n_actions, model.config.action_mask, seed)
    try:
        while np.any(done_count < quota):
            step = stepper.step(model.predict(stepper.obs, deterministic=deterministic, action_mask=stepper.masks))
            status, reported = step.info.get("status"), step.info.get("_status")  # HFO's endings, where given
            for i, ret, length, success in zip(step.ended, step.returns, step.lengths, step.successes):
                if done_count[i] < quota[i]:
                    returns.append(float(ret))
                    lengths.append(int(length))
                    succeeded.append(success)
                    done_count[i] += 1
                    if status is not None and (reported is None or reported[i]):
                        endings[str(status[i])] = endings.get(str(status[i]), 0) + 1
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
    if endings:
        result["endings"] = {name: count / sum(endings.values()) for name, count in sorted(endings.items())}
    return result
