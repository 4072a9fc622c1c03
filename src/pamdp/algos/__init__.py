"""Learning algorithms for parameterized action spaces, sharing one API (``base.py``), and their registry.

:data:`ALGORITHMS` is the one list of algorithms: the command line takes from it each algorithm's name, its
one-line help and its default budget, and from the algorithm's config its presets (:func:`default_preset`
names the one a run gets). A new algorithm needs one entry here. Modules are imported on first use only:
they import torch, and ``import pamdp`` stays light.
"""

from __future__ import annotations

import dataclasses
from importlib import import_module

__all__ = ["ALGORITHMS", "AlgoEntry", "MODULE_OF", "DEFAULT_PRESET", "algorithm_class", "class_named", "default_preset"]


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
}
"""Command-line name -> :class:`AlgoEntry`."""

MODULE_OF = {entry.class_name: entry.module for entry in ALGORITHMS.values()}
"""Class name -> its module, e.g. ``"PATRPO" -> "pamdp.algos.patrpo"``."""

DEFAULT_PRESET = "tuned"


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


def default_preset(config_class) -> str:
    """The preset a run gets when none is named: ``tuned`` where the algorithm has one, else its first."""
    presets = config_class.presets()
    return DEFAULT_PRESET if DEFAULT_PRESET in presets else next(iter(presets))
