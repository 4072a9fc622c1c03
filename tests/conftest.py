"""What many test files share: small settings for every algorithm, a three-action space, and readers of what a run
leaves. Helpers are imported by name (``from conftest import small_config``: pytest puts ``tests/`` on ``sys.path``).
"""

from __future__ import annotations

import copy
import csv
import dataclasses
from pathlib import Path

import numpy as np
import torch

from pamdp.algos import algorithm_class
from pamdp.spaces import HybridActionSpace

ENV = "pamdp/Platform-v0"

# Three actions with 1, 2 and 1 parameters in boxes of other bounds than [-1, 1], padded to m = 2: pi_c's padding
# (mask) and the rescaling are exercised.
HYBRID = HybridActionSpace(
    (np.array([-1.0]), np.array([0.0, 0.0]), np.array([-2.0])), (np.array([1.0]), np.array([1.0, 3.0]), np.array([2.0]))
)

# The replay-based algorithms' short epochs: an update from the 100th sample on, a buffer that never fills.
OFF_POLICY_SMALL = {"num_envs": 4, "epoch_steps": 200, "learning_starts": 100, "batch_size": 16, "buffer_size": 5_000}

_SMALL = {
    "num_envs": 4,
    "device": "cpu",
    "hidden_sizes": (16,),
    "vf_hidden_sizes": (16,),
    "vae_hidden_sizes": (16, 16),
    "epoch_steps": 100,
    "learning_starts": 64,
    "warmup_steps": 64,
    "warmup_updates": 10,
    "vae_interval": 50,
    "vae_updates": 5,
    "vae_batch_size": 16,
    "lsc_samples": 64,
    "buffer_size": 2_000,
    "epsilon_steps": 200,
    "n_epochs": 2,
    "minibatch_size": 32,
    "vf_epochs": 1,
    "updates_per_step": 0.25,
}


def small_settings(cls, **extra) -> dict:
    """Settings of algorithm class ``cls`` (or its command-line name) small enough for a few hundred steps in about
    a second, with updates from the first epoch on: 100-sample epochs (a batch of 100 on-policy, replay batches of
    16 after 64 samples off-policy), 16-unit networks; ``extra`` over them. Only the settings ``cls`` has."""
    cls = algorithm_class(cls) if isinstance(cls, str) else cls
    fields = {f.name for f in dataclasses.fields(cls.config_class)}
    on_policy = "gae_lambda" in fields and "learning_starts" not in fields
    values = {**_SMALL, "batch_size": 100 if on_policy else 16, **extra}
    return {k: v for k, v in values.items() if k in fields}


def small_config(cls, **extra):
    """:func:`small_settings` as ``cls``'s config."""
    cls = algorithm_class(cls) if isinstance(cls, str) else cls
    return cls.config_class.from_dict(small_settings(cls, **extra))


def module_bytes(model) -> dict[str, bytes]:
    """Every saved module's state (weights and buffers) as bytes, by module name: equal only when bit-identical."""
    return {
        name: b"".join(t.detach().cpu().contiguous().numpy().tobytes() for t in module.state_dict().values())
        for name, module in model._modules().items()
    }


def progress_rows(run_dir: str | Path) -> list[dict[str, str]]:
    """The rows of a run directory's ``progress.csv``, one an epoch."""
    with open(Path(run_dir) / "progress.csv", newline="") as f:
        return list(csv.DictReader(f))


def assert_update_matches(model, reference_update, updates: int = 30) -> None:
    """``model._update()`` against ``reference_update`` on a copy of the model, ``updates`` times: both draw the
    same batches from their (equal) random streams, so their weights must stay equal to float32 rounding."""
    ref = copy.deepcopy(model)
    for _ in range(updates):
        reference_update(ref)
        model._update()
    for name, module in model._modules().items():
        for (pname, p), q in zip(module.named_parameters(), ref._modules()[name].parameters()):
            torch.testing.assert_close(p, q, atol=2e-6, rtol=1e-4, msg=f"{name}.{pname}")
