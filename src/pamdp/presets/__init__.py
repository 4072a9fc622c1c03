"""Presets: an algorithm's named settings, its own and those chosen by the env, behind one lookup.

An algorithm's config has its own presets (``PDQNConfig.presets()``: ``paper``, ``tuned``); an env may choose one of
them or define a new one over them (:mod:`pamdp.presets.domains`, with each value's source). :func:`choose` answers
for the Python API, the command line and the runner alike:

- ``PDQNConfig.preset("hfo")`` is ``pamdp train pdqn --preset hfo``'s config;
- ``PDQN("pamdp/HalfFieldOffense-v0")`` trains with the preset ``pamdp train pdqn --env pamdp/HalfFieldOffense-v0``
  picks (the env's where it has one, else :data:`DEFAULT_PRESET`), and says which in ``model.preset``;
- a preset made for another env (``hfo`` on Platform) is used as asked, with a ``UserWarning`` naming both envs,
  which ``pamdp train`` also records in ``run.json``.

The algorithms' package knows no env: ``import pamdp`` installs :func:`choose` (:func:`install`) into
:class:`~pamdp.algos.settings.AlgoConfig` (:func:`~pamdp.algos.settings.install_preset_lookup`), so
``Config.preset`` reaches the env presets without ``pamdp.algos`` importing this package. This package imports the
registry and the settings (no torch); the table of env presets on first use (it reads Goal's env module).
"""

from __future__ import annotations

import dataclasses

from pamdp.algos import ALGORITHMS
from pamdp.algos.settings import AlgoConfig, install_preset_lookup

__all__ = ["DEFAULT_PRESET", "Choice", "choose", "default_preset", "install", "preset_config", "preset_names"]

DEFAULT_PRESET = "tuned"
"""The preset of a run on an env that chooses none, where the algorithm has it (else its first)."""


@dataclasses.dataclass(frozen=True)
class Choice:
    """A preset chosen for a run: its name, its config and, for a preset made for another env, the warning."""

    name: str
    config: AlgoConfig
    warning: str | None = None


def _algo_of(config_class) -> str | None:
    """The command-line name of the algorithm whose module defines ``config_class`` (``None`` for another)."""
    return next((name for name, e in ALGORITHMS.items() if e.module == config_class.__module__), None)


def preset_names(config_class) -> list[str]:
    """Every preset ``config_class`` takes: its own, then those that envs define."""
    from pamdp.presets.domains import domain_presets_of

    own = list(config_class.presets())
    return own + [name for name in domain_presets_of(_algo_of(config_class)) if name not in own]


def default_preset(config_class, env_id: str | None = None, env_kwargs: dict | None = None) -> str:
    """The preset a run gets when none is named: the env's (for the env's arguments ``env_kwargs``) where it has
    one, else :data:`DEFAULT_PRESET` where the algorithm has it, else its first."""
    from pamdp.presets.domains import domain_preset

    chosen = domain_preset(_algo_of(config_class), env_id, env_kwargs)
    if chosen is not None:
        return chosen.name
    presets = config_class.presets()
    return DEFAULT_PRESET if DEFAULT_PRESET in presets else next(iter(presets))


def choose(config_class, name: str | None = None, env_id: str | None = None, env_kwargs: dict | None = None) -> Choice:
    """Preset ``name`` of ``config_class`` (``None``: :func:`default_preset` for ``env_id`` and ``env_kwargs``).

    ``name`` is one of the config's own presets or one an env defines (its base with its overrides); an unknown name
    is a ``ValueError`` naming the valid ones. One made for other envs than ``env_id`` (given) carries a warning.
    """
    from pamdp.presets.domains import domain_presets_of, envs_named_by

    if name is None:
        name = default_preset(config_class, env_id, env_kwargs)
    algo = _algo_of(config_class)
    table = config_class.presets()
    if name in table:
        config = table[name]
    else:
        derived = domain_presets_of(algo).get(name)
        if derived is None:
            names = ", ".join(preset_names(config_class))
            raise ValueError(f"unknown preset {name!r} for {config_class.__name__}; expected one of {names}")
        config = config_class.from_dict(derived.settings, base=table[derived.base])
    made_for = envs_named_by(algo, name)
    warning = None
    if env_id is not None and made_for and env_id not in made_for:
        warning = (
            f"preset {name!r} of {config_class.__name__} was made for {', '.join(made_for)}, not {env_id}; "
            "it is used as asked"
        )
    return Choice(name, config, warning)


def preset_config(config_class, name: str, env_id: str | None = None, env_kwargs: dict | None = None):
    """The config of preset ``name`` (:func:`choose`'s, without its warning)."""
    return choose(config_class, name, env_id, env_kwargs).config


def _lookup(config_class, name, env_id, env_kwargs) -> tuple[str, AlgoConfig, str | None]:
    choice = choose(config_class, name, env_id, env_kwargs)
    return choice.name, choice.config, choice.warning


def install() -> None:
    """Answer ``Config.preset`` and ``Config.for_env`` with :func:`choose` (``import pamdp`` calls it)."""
    install_preset_lookup(_lookup)
