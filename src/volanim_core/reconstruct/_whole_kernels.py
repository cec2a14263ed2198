"""numba kernel of the one-piece proof (whole.py): a small sphere's voxels, each tested exactly.

    touches_any  for each small sphere not yet joined: has it no voxel, or a voxel 26-adjacent to (or
                 inside) a voxel of one of its candidate partners in the joined group? -- the kernels'
                 own predicate, ``fl(fl(dx^2 + dy^2) + dz^2) < r^2`` in float64, so "a voxel" is
                 exactly the fill's voxel
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def _inside(x, y, z, c, r2):
    dx, dy, dz = x - c[0], y - c[1], z - c[2]
    return (dx * dx + dy * dy) + dz * dz < r2


@njit(cache=True)
def _next_to(x, y, z, centres, r2s, partners, in_main):
    """Is voxel (x, y, z), or one of its 26 neighbours, a voxel of a partner in the joined group?"""
    for h in partners:
        if h < 0 or not in_main[h]:
            continue
        for a in range(-1, 2):
            for b in range(-1, 2):
                for e in range(-1, 2):
                    if _inside(x + e, y + b, z + a, centres[h], r2s[h]):
                        return True
    return False


@njit(cache=True)
def _joins(c, r2, centres, r2s, partners, in_main):
    """0: a voxel of the sphere (centre ``c``, ``r2``) is next to the joined group's; 1: it has voxels, none
    next to it; 2: it has no voxel."""
    reach = np.sqrt(r2) + 1e-7
    found = 2
    for z in range(int(np.floor(c[2] - reach)), int(np.ceil(c[2] + reach)) + 1):
        for y in range(int(np.floor(c[1] - reach)), int(np.ceil(c[1] + reach)) + 1):
            for x in range(int(np.floor(c[0] - reach)), int(np.ceil(c[0] + reach)) + 1):
                if _inside(x, y, z, c, r2):
                    if _next_to(x, y, z, centres, r2s, partners, in_main):
                        return 0
                    found = 1
    return found


@njit(cache=True)
def touches_any(centres, r2s, small, partners, in_main, state):
    """For each ``small[k]`` whose ``state[k]`` is 0 (not joined): 2 when it has no voxel at all, 1 when one of
    its voxels is next to a voxel of a partner ``h`` (``partners[k]``, -1: none) with ``in_main[h]`` -- then
    ``in_main`` of it is set too, so a chain of small spheres joins within one call when listed tip last.
    Returns how many it joined (or found empty)."""
    found = 0
    for k in range(len(small)):
        if state[k] != 0:
            continue
        s = small[k]
        got = _joins(centres[s], r2s[s], centres, r2s, partners[k], in_main)
        if got == 0:
            state[k] = 1
            in_main[s] = True
            found += 1
        elif got == 2:
            state[k] = 2
            found += 1
    return found
