"""The recordings of the original domains in ``tests/data``, replayed with the protocol of
``shared/specs/domain_traces/README.md``: the domains' tests share it and add their own checks."""

import json
from pathlib import Path

import gymnasium
import numpy as np

DATA = Path(__file__).parent / "data"


def load_cases(*names: str) -> list[dict]:
    """The cases of the recordings ``tests/data/<name>`` (each a JSON list of cases), in order."""
    return [case for name in names for case in json.loads((DATA / name).read_text())]


def params_for(space, a, values) -> tuple:
    """The parameter tuple of ``space`` with action ``a``'s box set to ``values``, the others zero."""
    params = [np.zeros(box.shape, box.dtype) for box in space[1]]
    params[a] = np.asarray(values, dtype=space[1][a].dtype).reshape(space[1][a].shape)
    return tuple(params)


def replay(case: dict, check=None) -> tuple[int, int]:
    """Replay ``case`` from a fresh env driven by ``RandomState(seed)``: every observation and reward within
    1e-12 of the recording, the flags exact; then ``check(rec, env, info, where)`` asserts the domain's own
    (``env`` unwrapped, ``where`` names the record). Returns (records bit-identical in observation and
    reward, records), resets counted as records with reward 0."""
    env = gymnasium.make(case["env_id"], **case["env_kwargs"])
    env.reset(seed=0)
    env.unwrapped.np_random = np.random.RandomState(case["seed"])
    identical = records = 0
    for rec in case["trace"]:
        if rec.get("event") == "end":
            break
        where = f"seed {case['seed']}, t={rec['t']}"
        if rec.get("event") == "reset":
            obs, info = env.reset()
            reward = rec_reward = 0.0
        else:
            a = rec["act_index"]
            obs, reward, terminated, truncated, info = env.step((a, params_for(env.action_space, a, rec["param"])))
            rec_reward = rec["reward"]
            assert (terminated, truncated) == (rec["terminal"], rec["truncated"]), where
        np.testing.assert_allclose(obs, rec["obs"], rtol=0, atol=1e-12, err_msg=where)
        assert abs(reward - rec_reward) <= 1e-12, where
        if check is not None:
            check(rec, env.unwrapped, info, where)
        identical += bool(np.array_equal(obs, rec["obs"]) and reward == rec_reward)
        records += 1
    return identical, records
