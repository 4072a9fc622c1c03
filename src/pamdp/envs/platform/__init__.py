"""The Platform domain (Masson, Ranchod & Konidaris, AAAI 2016; the Gym port
``cycraig/gym-platform``): ``pamdp/Platform-v0``.

- ``physics.py``: the dynamics of one copy, once, compiled by Numba, and their loop over the copies;
- ``env.py``: the domain contract, :class:`Platform`, and its envs :class:`PlatformEnv` (scalar) and
  :class:`PlatformVectorEnv` (batched);
- ``render.py``: the side view and episode GIFs.

The agent is a box that must cross three platforms, separated by two gaps, to reach the right edge
(``x = 1035``) while avoiding two enemies that patrol platforms 1 and 2. Every agent step is a
*parameterised action* ``(a, p)``:

====  ======  ===============  ==========================================================
 a    name    parameter range  effect
====  ======  ===============  ==========================================================
 0    run     [0, 30]          20 physics sub-steps, each adding ``p`` to vx (ground cap 70)
 1    hop     [0, 720]         jump with vy = 35 aiming at horizontal speed ``p / 8.14``
 2    leap    [0, 430]         jump with vy = 25 aiming at horizontal speed ``p / 6.10``
====  ======  ===============  ==========================================================

A jump lasts until the player is standing on a platform again (or the episode ends), so one agent
step runs a variable number of sub-steps (``info["substeps"]``, ~72 on average for a random policy).
The reward of a step is the horizontal progress ``(x_end - x_start) / 1035`` so the episode return is
the fraction of the course covered (exactly 1.0 at the goal). Falling into a gap or touching an
enemy ends the episode (``terminated``); the 200-step limit of the registration is ``truncated``.
"""

from pamdp.envs.platform.env import Platform, PlatformEnv, PlatformVectorEnv, ZeroNoise
from pamdp.envs.platform.render import draw_platform, save_platform_gif

__all__ = ["Platform", "PlatformEnv", "PlatformVectorEnv", "ZeroNoise", "draw_platform", "save_platform_gif"]
