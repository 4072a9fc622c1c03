"""The Platform domain (Masson, Ranchod & Konidaris, AAAI 2016): ``pamdp/Platform-v0``.

- ``physics.py``: the dynamics of one copy, once, compiled by Numba (spec: ``shared/specs/platform.md``);
- ``env.py``: the scalar env, :class:`PlatformEnv`;
- ``batched.py``: N copies in one compiled loop, :class:`PlatformVectorEnv`;
- ``render.py``: the side view and episode GIFs.
"""

from pamdp.envs.platform.batched import PlatformVectorEnv
from pamdp.envs.platform.env import PlatformEnv, ZeroNoise
from pamdp.envs.platform.render import draw_platform, save_platform_gif

__all__ = ["PlatformEnv", "PlatformVectorEnv", "ZeroNoise", "draw_platform", "save_platform_gif"]
