"""Learning algorithms for parameterized action spaces, sharing one API (see ``base.py``)."""

from importlib import import_module

# Command-line name -> "module:Class", the one list of algorithms. Modules are imported on first use only:
# they import torch, and `import pamdp` stays light.
ALGORITHMS = {
    "patrpo": "pamdp.algos.patrpo:PATRPO",
    "pappo": "pamdp.algos.pappo:PAPPO",
    "pasvg0": "pamdp.algos.pasvg:PASVG0",
    "paddpg": "pamdp.algos.paddpg:PADDPG",
    "pdqn": "pamdp.algos.pdqn:PDQN",
    "hyar": "pamdp.algos.hyar:HyAR",
}
MODULE_OF = {target.partition(":")[2]: target.partition(":")[0] for target in ALGORITHMS.values()}
"""Class name -> its module, e.g. ``"PATRPO" -> "pamdp.algos.patrpo"``."""


def class_named(name: str):
    """The algorithm class called ``name`` (``"PATRPO"``), imported on first use; ``None`` if none is."""
    return getattr(import_module(MODULE_OF[name]), name) if name in MODULE_OF else None
