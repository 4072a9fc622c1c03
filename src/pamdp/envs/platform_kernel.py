"""The batched Platform step as one Numba loop: the optional fast backend of
``platform_vector.PlatformVectorEnv`` (``pip install pamdp[fast]``).

The NumPy step pays NumPy's per-call overhead some forty times per sub-step, and its loop runs as long as
the longest copy (~145 sub-steps when one copy hops). Here :func:`run_substeps` runs the whole loop in one
call. Every formula is the NumPy env's (``PlatformVectorEnv._run_substeps``, ``_collide``,
``_on_platform``), operation for operation and in the same order, so the two backends agree bit for bit
(``tests/test_platform_kernel.py``). ``fastmath`` stays off: reassociation or fused multiply-adds would
change the roundings.

Random numbers are never drawn here; they come in as one array, in the order the NumPy step draws them.
In every sub-step the NumPy step draws one Gaussian per copy of its working set for the player's friction,
then one per copy for the enemy (and, before those in the first sub-step, two per jumping copy). The working
set keeps copies that have stopped until a quarter of it has, so how many numbers a sub-step takes depends
on when the other copies stopped. The loop therefore goes over sub-steps, then copies, as NumPy's does, and
keeps the working set as NumPy's would be, only to know where each copy's numbers are.

NumPy's ``normal(0.0, s, size)`` (``Generator``'s and ``RandomState``'s) is ``0.0 + s * z`` with ``z`` the
generator's next standard normals, one after the other whatever the calls' sizes, so the draws of a whole
step are one ``standard_normal(k)``, scaled here. ``k`` is known only once the last copy stops, so the env
draws them in chunks: the kernel stops before a sub-step it has too few numbers for and resumes there once
given more, and at the end the env rewinds its generator to the start of the last chunk and draws again
only the part of it that was used, which leaves the generator where the NumPy step leaves it
(``PlatformVectorEnv._kernel_substeps``).

Numba caches the compiled kernel on disk keyed by this file's modification time and size only, yet the
constants of ``platform`` and ``platform_vector`` are compiled in. So :func:`refresh_cache` keeps a digest
of those modules next to the cache and drops the cached kernel when it changes.
"""

from __future__ import annotations

from pathlib import Path

import numba

from pamdp.envs import numba_cache
from pamdp.envs.platform import (
    AX_MAX,
    AY_MAX,
    DECAY,
    DT,
    ENEMY_NOISE,
    ENEMY_SPEED,
    GRAVITY,
    HOP,
    JUMP_DEV,
    JUMP_DY0,
    LEAP,
    PLATFORM_HEIGHT,
    PLATFORMS,
    PLAYER_H,
    PLAYER_NOISE,
    PLAYER_W,
    RUN,
    RUN_SUBSTEPS,
    VX_GROUND,
    VX_MAX,
    VY_MAX,
    X_GOAL,
)
from pamdp.envs.platform_vector import (
    E1_HI,
    E1_LO,
    E1DX,
    E1X,
    E2_HI,
    E2_LO,
    E2X,
    GAP_MIDDLES,
    GRAVITY_DV,
    PLATFORM_RIGHT,
    PLATFORM_X,
    VX,
    VY,
    X,
    Y,
)

_HOP_DY0, _LEAP_DY0 = JUMP_DY0[HOP], JUMP_DY0[LEAP]
(_P1, _W1), (_P2, _W2), (_P3, _) = PLATFORMS
_GAP_MIDDLE_1, _GAP_MIDDLE_2 = float(GAP_MIDDLES[0]), float(GAP_MIDDLES[1])
# Rows of ``work``, the per-copy constants of one agent step (PlatformVectorEnv's X0, RUN_DV, DY0, TARGET_VX).
WORK_ROWS = 4
_X0, _RUN_DV, _DY0, _TARGET_VX = range(WORK_ROWS)
# Entries of ``cursor``, where the loop stands between calls: sub-steps done, size of the working set,
# copies still moving, numbers of ``draws`` used.
COUNT, SIZE, LIVE, USED = range(4)

DEPENDENCIES = ("platform.py", "platform_vector.py")


def refresh_cache(directory: Path | None = None) -> bool:
    """Drop this module's cached kernel if :data:`DEPENDENCIES` changed; True if it did (see ``numba_cache``)."""
    return numba_cache.refresh_cache(__file__, DEPENDENCIES, directory)


refresh_cache()  # before the kernel is compiled or loaded from the cache
_jit = numba.njit(cache=True, fastmath=False, nogil=True)


@_jit
def _clip(v, lo, hi):
    return min(max(v, lo), hi)


@_jit
def _on_platform(x, y):
    """``platform_vector._on_platform`` for one copy."""
    over = x <= _P1 + _W1 or (x >= _P2 - PLAYER_W and x <= _P2 + _W2) or x >= _P3 - PLAYER_W
    return over and y == PLATFORM_HEIGHT


@_jit
def _start(idx, a, p, state, work, ws, live, on):
    """The working set and per-copy constants of ``PlatformVectorEnv._run_substeps``; returns the number of
    copies that jump from a platform (two draws each in the first sub-step)."""
    jumpers = 0
    for j in range(idx.size):
        c = idx[j]
        ws[j], live[j] = c, True
        is_run = a[c] == RUN
        dy0 = _LEAP_DY0 if a[c] == LEAP else _HOP_DY0
        work[_X0, c] = state[X, c]
        work[_RUN_DV, c] = _clip(p[c] / DT, -AX_MAX, AX_MAX) * DT * (1.0 if is_run else 0.0)
        work[_DY0, c] = dy0
        work[_TARGET_VX, c] = p[c] / (2.0 * dy0 / GRAVITY + 1.0)
        on[c] = _on_platform(state[X, c], state[Y, c])
        if on[c] and not is_run:
            jumpers += 1
    return jumpers


@_jit
def _collide(state, c):
    """``platform_vector._collide`` for copy ``c``, below the walking surface."""
    x, y = state[X, c], state[Y, c]
    nearest = (1 if _GAP_MIDDLE_1 < x else 0) + (1 if _GAP_MIDDLE_2 < x else 0)  # np.searchsorted(GAP_MIDDLES, x)
    px, right = PLATFORM_X[nearest], PLATFORM_RIGHT[nearest]
    if not (x > px - PLAYER_W and x < right and y > -PLAYER_H):
        return
    new_x = px - PLAYER_W if x < px else right if x > right - PLAYER_W else x
    new_y = -PLAYER_H if y < 0.0 else PLATFORM_HEIGHT if y > PLATFORM_HEIGHT - PLAYER_H else y
    if new_x != x and (new_y == y or abs(x - new_x) < abs(y - new_y)):
        state[X, c] = new_x
    else:
        state[Y, c] = new_y
        state[VY, c] = 0.0
    state[VX, c] = 0.0


@_jit
def run_substeps(idx, a, p, state, draws, work, ws, live, on, cursor, rewards, terminated, substeps):
    """``PlatformVectorEnv._run_substeps`` for the copies ``idx``: sub-step them until each stops and write
    their results into ``rewards``, ``terminated`` and ``substeps`` (all indexed by copy, as ``a``, ``p`` and
    the columns of ``state``).

    ``draws`` holds standard normals, used from the start in the NumPy step's order. Returns True once
    every copy has stopped (``cursor[USED]`` numbers used), False if it needs more numbers: call it again
    with ``draws`` extended and the other arguments as they are. Kept between such calls: ``cursor`` (4,
    zeros at the start of a step), ``work`` (``WORK_ROWS``, N), the working set ``ws`` (N, its first
    ``cursor[SIZE]`` entries are copies), which of its entries are still moving, ``live`` (N,), and which
    copies stand on a platform, ``on`` (N,).
    """
    count, n, n_live, used = cursor[COUNT], cursor[SIZE], cursor[LIVE], cursor[USED]
    jumpers = 0
    if count == 0:  # also when resumed before the first sub-step: nothing has moved yet
        jumpers = _start(idx, a, p, state, work, ws, live, on)
        n = n_live = idx.size
    while n_live:
        if used + 2 * jumpers + 2 * n > draws.size:
            cursor[COUNT], cursor[SIZE], cursor[LIVE], cursor[USED] = count, n, n_live, used
            return False
        count += 1
        # Where the sub-step's draws are: jumper k's two at jump_at + k and jump_at + jumpers + k, then one
        # per working-set position for the friction, then one per position for the enemy.
        jump_at, friction_at = used, used + 2 * jumpers
        enemy_at = friction_at + n
        used = enemy_at + n
        k = stopped = 0
        for j in range(n):
            if not live[j]:
                continue
            c = ws[j]
            x, y, vx, vy = state[X, c], state[Y, c], state[VX, c], state[VY, c]
            on_c = on[c]
            is_run = a[c] == RUN

            # §7.2-3
            dvx = work[_RUN_DV, c] * (1.0 if on_c else 0.0)
            dvy = GRAVITY_DV * (0.0 if on_c else 1.0)
            if count == 1 and on_c and not is_run:
                jump_dy0 = work[_DY0, c]
                dx = _clip(work[_TARGET_VX, c] - vx, -AX_MAX, VY_MAX - jump_dy0)
                n0 = -abs(0.0 + JUMP_DEV * draws[jump_at + k])
                n1 = -abs(0.0 + JUMP_DEV * draws[jump_at + jumpers + k])
                k += 1
                dvx = _clip((dx + n0) / DT, -AX_MAX, AX_MAX) * DT
                dvy = _clip((jump_dy0 + n1) / DT, -AY_MAX, AY_MAX) * DT
            vx += dvx
            vy += dvy
            vx -= abs(0.0 + PLAYER_NOISE * draws[friction_at + j])
            vx = _clip(vx, 0.0, VX_MAX)
            vy = _clip(vy, -VY_MAX, VY_MAX)
            vx = min(vx, VX_MAX - (VX_MAX - VX_GROUND) * (1.0 if on_c else 0.0))

            # §7.4-5
            enemy2 = x > _P2
            x += vx * DT
            x = _clip(x, 0.0, X_GOAL)
            y += vy * DT
            vx *= DECAY
            state[X, c], state[Y, c], state[VX, c], state[VY, c] = x, y, vx, vy

            # §7.6 on the active enemy
            row = E2X if enemy2 else E1X
            drow = row + (E1DX - E1X)
            ex, edx = state[row, c], state[drow, c]
            lo = E1_LO + (E2_LO - E1_LO) * (1.0 if enemy2 else 0.0)
            hi = E1_HI + (E2_HI - E1_HI) * (1.0 if enemy2 else 0.0)
            edx *= 1.0 - 2.0 * (1.0 if ex <= lo or ex >= hi else 0.0)
            edx += 0.0 + ENEMY_NOISE * draws[enemy_at + j]
            edx = _clip(edx, -ENEMY_SPEED, ENEMY_SPEED)
            ex += edx * DT
            ex = min(max(ex, lo), hi)
            state[row, c], state[drow, c] = ex, edx

            # §7.7
            if y < PLATFORM_HEIGHT:
                _collide(state, c)
                x, y = state[X, c], state[Y, c]

            # §7.8-9 and the §6 stop rule
            fell = y < PLATFORM_HEIGHT
            near = abs(x - state[E1X, c]) < PLAYER_W or abs(x - state[E2X, c]) < PLAYER_W
            hit = near and y > PLATFORM_HEIGHT - PLAYER_H and y < PLATFORM_HEIGHT + PLAYER_H
            done = fell or hit or x >= X_GOAL
            on[c] = _on_platform(x, y)
            if done or (on[c] and not is_run) or (count == RUN_SUBSTEPS and is_run):
                rewards[c] = (x - work[_X0, c]) / X_GOAL
                terminated[c] = done
                substeps[c] = count
                live[j] = False
                stopped += 1
        jumpers = 0
        n_live -= stopped
        if stopped and n_live <= 0.75 * n:  # NumPy drops the stopped copies from its working set
            m = 0
            for j in range(n):
                if live[j]:
                    ws[m], live[m] = ws[j], True
                    m += 1
            n = n_live
    cursor[COUNT], cursor[SIZE], cursor[LIVE], cursor[USED] = count, n, n_live, used
    return True
