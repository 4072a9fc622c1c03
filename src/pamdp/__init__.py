"""pamdp: deep reinforcement learning in parameterized action spaces.

Importing the package registers its environments with Gymnasium (``pamdp/Platform-v0``,
``pamdp/HalfFieldOffense-v0``) and installs the lookup of the env presets (``pamdp.presets``) into the algorithms'
configs. Algorithms and the callbacks of :mod:`pamdp.callbacks` are importable from here: ``from pamdp import PATRPO,
EvalCallback``.
"""

from importlib import import_module

from pamdp._version import __version__
from pamdp.algos import MODULE_OF as _ALGOS
from pamdp.envs import register_envs
from pamdp.presets import install as _install_presets
from pamdp.spaces import HybridActionSpace

register_envs()
_install_presets()


_CALLBACKS = (
    "BaseCallback",
    "CallbackList",
    "CheckpointCallback",
    "EvalCallback",
    "StopTrainingOnRewardThreshold",
    "WandbCallback",
)

__all__ = ["HybridActionSpace", "register_envs", "__version__", *_ALGOS, *_CALLBACKS]


def __getattr__(name):
    # Algorithms and callbacks import torch; load them on first use: `import pamdp` (and env creation) stays light.
    if name in _ALGOS:
        return getattr(import_module(_ALGOS[name]), name)
    if name in _CALLBACKS:
        return getattr(import_module("pamdp.callbacks"), name)
    raise AttributeError(f"module 'pamdp' has no attribute {name!r}")
