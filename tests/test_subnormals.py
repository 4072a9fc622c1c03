"""``flush_denormal``: every algorithm's gradient updates flush subnormal floats to zero (they are many times
slower in x86 arithmetic, and Adam's decaying moments reach them); the env steps never do, since the Half
Field Offense simulation needs IEEE subnormals (``hfo_features._directions``)."""

import dataclasses

import pytest
import torch

from pamdp import PADDPG, PAPPO, PASVG0, PATRPO, PDQN, HyAR
from pamdp.algos.hyar import HyARConfig
from pamdp.algos.paddpg import PADDPGConfig
from pamdp.algos.pappo import PAPPOConfig
from pamdp.algos.pasvg import PASVG0Config
from pamdp.algos.patrpo import PATRPOConfig
from pamdp.algos.pdqn import PDQNConfig

OFF_POLICY = dict(num_envs=4, epoch_steps=200, learning_starts=100, batch_size=16, buffer_size=5_000)
# (algorithm, a small config, the methods that make its gradient updates)
CASES = {
    "PASVG0": (PASVG0, PASVG0Config(hidden_sizes=(16, 16), **OFF_POLICY), ["_update"]),
    "PADDPG": (PADDPG, PADDPGConfig(hidden_sizes=(16, 16), **OFF_POLICY), ["_update"]),
    "PDQN": (PDQN, PDQNConfig(hidden_sizes=(16,), **OFF_POLICY), ["_update"]),
    "HyAR": (
        HyAR,
        HyARConfig(
            num_envs=4,
            embed_dim=3,
            latent_dim=2,
            hidden_sizes=(16,),
            vae_hidden_sizes=(16,),
            epoch_steps=200,
            warmup_steps=150,
            warmup_updates=5,
            vae_interval=50,
            vae_updates=2,
            batch_size=16,
            vae_batch_size=16,
            lsc_samples=100,
            buffer_size=5_000,
            updates_per_step=0.25,
        ),  # fmt: skip
        ["_update"],
    ),
    "PATRPO": (
        PATRPO,
        PATRPOConfig(hidden_sizes=(16,), batch_size=200, num_envs=4),
        ["_update_policy", "_fit_baseline"],
    ),
    "PAPPO": (PAPPO, PAPPOConfig(hidden_sizes=(16,), batch_size=200, minibatch_size=100, num_envs=4), ["_update"]),
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
