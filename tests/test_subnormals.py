"""``flush_denormal``: every algorithm's gradient updates flush subnormal floats to zero (they are many times
slower in x86 arithmetic, and Adam's decaying moments reach them); the env steps never do, since the Half
Field Offense simulation needs IEEE subnormals (``pamdp.envs.hfo.dynamics.direction_of``)."""

import dataclasses

import pytest
import test_hyar
import test_paddpg
import test_pappo
import test_pasvg
import test_patrpo
import test_pdqn
import torch

from pamdp import PADDPG, PAPPO, PASVG0, PATRPO, PDQN, HyAR

# (algorithm, the small config of its own tests, the methods that make its gradient updates)
CASES = {
    "PASVG0": (PASVG0, test_pasvg.SMALL, ["_update"]),
    "PADDPG": (PADDPG, test_paddpg.SMALL, ["_update"]),
    "PDQN": (PDQN, test_pdqn.SMALL, ["_update"]),
    "HyAR": (HyAR, test_hyar.SMALL, ["_update"]),
    "PATRPO": (PATRPO, test_patrpo.SMALL, ["_update_policy", "_fit_baseline"]),
    "PAPPO": (PAPPO, test_pappo.SMALL, ["_update"]),
}
SUBNORMAL = torch.tensor(1e-39, dtype=torch.float32)  # below float32's smallest normal, 1.18e-38
PRODUCT = float(torch.tensor(1.5e-39, dtype=torch.float32))  # SUBNORMAL * 1.5 in IEEE float32


@pytest.mark.parametrize("flush", [True, False])
@pytest.mark.parametrize("name", list(CASES))
def test_updates_flush_subnormals_when_asked_and_env_steps_never(name, flush):
    cls, config, methods = CASES[name]
    model = cls("pamdp/Platform-v0", dataclasses.replace(config, flush_denormal=flush))
    seen: dict[str, set] = {}

    def spy(key, fn):
        def wrapped(*args):
            seen.setdefault(key, set()).add(float(SUBNORMAL * 1.5))
            return fn(*args)

        return wrapped

    for method in methods:
        setattr(model, method, spy(method, getattr(model, method)))
    model.vec_env.step = spy("env", model.vec_env.step)
    model.learn(400, progress_bar=False)
    expected = {method: {0.0 if flush else PRODUCT} for method in methods}
    assert seen == {**expected, "env": {PRODUCT}}
    assert float(SUBNORMAL * 1.5) == PRODUCT  # and learn() leaves IEEE arithmetic behind
