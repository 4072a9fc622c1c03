"""Learning algorithms for parameterized action spaces, sharing one API (``base.py``), and their registry.

:data:`ALGORITHMS` is the one list of algorithms: the command line takes from it each algorithm's name, its
one-line help and its default budget, and from the algorithm's config its presets, with those chosen by env
in ``domain_presets.py`` (:func:`preset_names`, :func:`preset_config`; :func:`default_preset` names the one a
run gets). A new algorithm needs one entry here. Modules are imported on first use only:
they import torch, and ``import pamdp`` stays light.
"""

from __future__ import annotations

import dataclasses
from importlib import import_module

__all__ = [
    "ALGORITHMS",
    "AlgoEntry",
    "MODULE_OF",
    "DEFAULT_PRESET",
    "algorithm_class",
    "class_named",
    "default_preset",
    "preset_names",
    "preset_config",
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


def _algo_of(config_class) -> str | None:
    """The command-line name of the algorithm whose module defines ``config_class`` (``None`` for another)."""
    return next((name for name, e in ALGORITHMS.items() if e.module == config_class.__module__), None)


def preset_names(config_class) -> list[str]:
    """Every preset ``config_class`` takes: its own, then those that envs choose (``domain_presets.py``)."""
    from pamdp.algos.domain_presets import domain_presets_of

    own = list(config_class.presets())
    return own + [name for name in domain_presets_of(_algo_of(config_class)) if name not in own]


def preset_config(config_class, name: str):
    """The config of preset ``name``: one of the config's own, or an env's (its base with its overrides)."""
    from pamdp.algos.domain_presets import domain_presets_of

    table = config_class.presets()
    if name in table:
        return table[name]
    derived = domain_presets_of(_algo_of(config_class)).get(name)
    if derived is None:
        names = ", ".join(preset_names(config_class))
        raise ValueError(f"unknown preset {name!r} for {config_class.__name__}; expected one of {names}")
    return config_class.from_dict(derived.settings, base=table[derived.base])


def default_preset(config_class, env_id: str | None = None, env_kwargs: dict | None = None) -> str:
    """The preset a run gets when none is named: the env's (``domain_presets.py``, for the env's arguments
    ``env_kwargs``) where it has one, else ``tuned`` where the algorithm has it, else its first."""
    from pamdp.algos.domain_presets import domain_preset

    chosen = domain_preset(_algo_of(config_class), env_id, env_kwargs)
    if chosen is not None:
        return chosen.name
    presets = config_class.presets()
    return DEFAULT_PRESET if DEFAULT_PRESET in presets else next(iter(presets))
