"""Learning algorithms for parameterized action spaces, sharing one API (``base.py``), and their registry.

:data:`ALGORITHMS` is the one list of algorithms: the command line takes from it each algorithm's name, its
one-line help and its default budget; :func:`load_model` loads a model whichever of them wrote it. A new algorithm
needs one entry here. Modules are imported on first use only: they import torch, and ``import pamdp`` stays light.
The algorithms know no env: the presets that envs choose are ``pamdp.presets``'.
"""

from __future__ import annotations

import dataclasses
import os
from importlib import import_module

__all__ = [
    "ALGORITHMS",
    "AlgoEntry",
    "MODULE_OF",
    "algorithm_class",
    "class_named",
    "load_model",
]


@dataclasses.dataclass(frozen=True)
class AlgoEntry:
    """One algorithm of the registry."""

    target: str
    """``"module:Class"``, imported on first use."""
    help: str
    """One line for ``pamdp train --help``."""
    total_steps: int
    """The budget of ``pamdp train`` without ``--total-steps``."""

    @property
    def module(self) -> str:
        return self.target.partition(":")[0]

    @property
    def class_name(self) -> str:
        return self.target.partition(":")[2]


ALGORITHMS: dict[str, AlgoEntry] = {
    "patrpo": AlgoEntry(
        "pamdp.algos.patrpo:PATRPO", "PATRPO: TRPO of the hierarchical policy with the chain-rule KL", 500_000
    ),
    "pappo": AlgoEntry(
        "pamdp.algos.pappo:PAPPO", "PAPPO: PPO's clipped surrogate on the hierarchical policy (H-PPO style)", 300_000
    ),
    "pasvg0": AlgoEntry(
        "pamdp.algos.pasvg:PASVG0", "PASVG(0): Gumbel-Softmax stochastic value gradients with replay", 1_000_000
    ),
    "paddpg": AlgoEntry(
        "pamdp.algos.paddpg:PADDPG", "PADDPG: Hausknecht & Stone's parameterized-action DDPG (the baseline)", 1_000_000
    ),
    "pdqn": AlgoEntry(
        "pamdp.algos.pdqn:PDQN", "P-DQN (Xiong et al.); with --multi-pass true, MP-DQN (Bester et al.)", 200_000
    ),
    "hyar": AlgoEntry(
        "pamdp.algos.hyar:HyAR", "HyAR-TD3 (Li et al.): TD3 in a learned latent space of hybrid actions", 200_000
    ),
    "hsac": AlgoEntry(
        "pamdp.algos.hsac:HybridSAC", "Hybrid SAC (Delalleau et al.): soft actor-critic, flat or hierarchical", 300_000
    ),
}
"""Command-line name -> :class:`AlgoEntry`."""

MODULE_OF = {entry.class_name: entry.module for entry in ALGORITHMS.values()}
"""Class name -> its module, e.g. ``"PATRPO" -> "pamdp.algos.patrpo"``."""


def algorithm_class(name: str):
    """The class behind an algorithm's command-line name, or ``None`` if this install lacks its module."""
    if name not in ALGORITHMS:
        raise ValueError(f"unknown algorithm {name!r}; expected one of {', '.join(ALGORITHMS)}")
    entry = ALGORITHMS[name]
    try:
        return getattr(import_module(entry.module), entry.class_name)
    except ModuleNotFoundError as exc:
        if exc.name == entry.module:
            return None
        raise


def class_named(name: str):
    """The algorithm class called ``name`` (``"PATRPO"``), imported on first use; ``None`` if none is."""
    return getattr(import_module(MODULE_OF[name]), name) if name in MODULE_OF else None


def load_model(path: str | os.PathLike, env=None, device: str | None = None):
    """Load any pamdp model (file or run directory), whichever of the registered algorithms wrote it, onto
    ``device`` (as :meth:`Algorithm.load <pamdp.algos.base.Algorithm.load>` chooses it by default)."""
    from pamdp.algos.checkpoints import read_checkpoint

    payload = read_checkpoint(path)
    name = payload["algo"]
    cls = class_named(name)
    if cls is None:
        raise ValueError(f"{path} was written by unknown algorithm {name!r}; expected one of {', '.join(MODULE_OF)}")
    return cls._from_payload(payload, env, device)
