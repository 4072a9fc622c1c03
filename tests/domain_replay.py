"""What the domains' tests share: the recordings of the original domains in ``tests/data`` replayed with the
protocol of ``shared/specs/domain_traces/README.md``, a batched step against scalar envs', refused actions."""

import json
from pathlib import Path

import gymnasium
import numpy as np
import pytest

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
    """Replay ``case`` driven by ``RandomState(seed)``: observations and rewards within 1e-12 of the recording,
    flags exact, then ``check(rec, env.unwrapped, info, where)``. Returns (records bit-identical in
    observation and reward, records); a reset is a record with reward 0."""
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


def assert_same_step(got, want, where: str, keys=None) -> None:
    """A batched step's ``(obs, rewards, terminated, truncated, infos)`` equal to ``want``'s (a
    ``SyncVectorEnv`` of scalar envs): the four arrays and the infos ``keys`` (default: all of ``want``'s)."""
    for k in range(4):
        np.testing.assert_array_equal(got[k], want[k], err_msg=f"{where}, output {k}")
    for key in want[4] if keys is None else keys:
        np.testing.assert_array_equal(got[4][key], want[4][key], err_msg=f"{where}, {key}")


def assert_refused(env, action, *words: str) -> None:
    """``env.step(action)`` raises ``ValueError`` with each of ``words`` in its message."""
    with pytest.raises(ValueError) as err:
        env.step(action)
    assert all(w in str(err.value) for w in words), str(err.value)
