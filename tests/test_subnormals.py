"""``flush_denormal``: every algorithm's gradient updates flush subnormal floats to zero (they are many times
slower in x86 arithmetic, and Adam's decaying moments reach them); the env steps never do, since the Half
Field Offense simulation needs IEEE subnormals (``pamdp.envs.hfo.dynamics.direction_of``)."""

import pytest
import torch
from conftest import ENV, small_config

from pamdp.algos import ALGORITHMS, algorithm_class

# The methods that make an algorithm's gradient updates: "_update" but where named here.
UPDATES = {"patrpo": ["_update_policy", "_fit_baseline"]}
SUBNORMAL = torch.tensor(1e-39, dtype=torch.float32)  # below float32's smallest normal, 1.18e-38
PRODUCT = float(torch.tensor(1.5e-39, dtype=torch.float32))  # SUBNORMAL * 1.5 in IEEE float32


@pytest.mark.parametrize("flush", [True, False])
@pytest.mark.parametrize("name", list(ALGORITHMS))
def test_updates_flush_subnormals_when_asked_and_env_steps_never(name, flush):
    methods = UPDATES.get(name, ["_update"])
    model = algorithm_class(name)(ENV, small_config(name, flush_denormal=flush))
    seen: dict[str, set] = {}

    def spy(key, fn):
        def wrapped(*args):
            seen.setdefault(key, set()).add(float(SUBNORMAL * 1.5))
            return fn(*args)

        return wrapped

    for method in methods:
        setattr(model, method, spy(method, getattr(model, method)))
    model.vec_env.step = spy("env", model.vec_env.step)
    model.learn(200, progress_bar=False)
    expected = {method: {0.0 if flush else PRODUCT} for method in methods}
    assert seen == {**expected, "env": {PRODUCT}}
    assert float(SUBNORMAL * 1.5) == PRODUCT  # and learn() leaves IEEE arithmetic behind
