"""The Platform domain (Masson, Ranchod & Konidaris, AAAI 2016): ``pamdp/Platform-v0``.

- ``physics.py``: the dynamics of one copy, once, compiled by Numba, and their loop over the copies;
- ``env.py``: the domain contract, :class:`Platform`, and its envs :class:`PlatformEnv` (scalar) and
  :class:`PlatformVectorEnv` (batched);
- ``render.py``: the side view and episode GIFs.
"""

from pamdp.envs.platform.env import Platform, PlatformEnv, PlatformVectorEnv, ZeroNoise
from pamdp.envs.platform.render import draw_platform, save_platform_gif

__all__ = ["Platform", "PlatformEnv", "PlatformVectorEnv", "ZeroNoise", "draw_platform", "save_platform_gif"]
