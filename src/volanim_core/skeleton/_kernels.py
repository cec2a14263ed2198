"""numba kernels for skeletonization: 3-4-5 chamfer DT and thinness.

Arrays here are C-ordered ``[z, y, x]`` views (the transpose of our
``[x, y, z]`` F-ordered volumes), so the innermost loop runs along x, the
file's fastest axis, and raster order equals file order.
"""

from __future__ import annotations

import numpy as np
from numba import njit

INF345 = np.int32(2**30)


@njit(cache=True, inline="always")
def _relax(d, z, y, x, side):
    """``d[z, y, x]`` lowered through the 13 neighbours on one side of it in raster order
    (``side`` -1: before, +1: after); face, edge and corner steps cost 3, 4 and 5, and
    outside the volume is background."""
    nz, ny, nx = d.shape
    best = d[z, y, x]
    for dz in range(-1, 2):
        for dy in range(-1, 2):
            for dx in range(-1, 2):
                if (9 * dz + 3 * dy + dx) * side <= 0:  # the raster-order sign of the offset
                    continue
                zz, yy, xx = z + dz, y + dy, x + dx
                k = abs(dz) + abs(dy) + abs(dx)
                w = 3 if k == 1 else (4 if k == 2 else 5)
                if zz < 0 or zz >= nz or yy < 0 or yy >= ny or xx < 0 or xx >= nx:
                    v = w
                else:
                    v = d[zz, yy, xx] + w
                if v < best:
                    best = v
    return best


@njit(cache=True)
def chamfer345(mask):
    """Exact 3-4-5 chamfer distance to the nearest background voxel centre.

    Two raster passes over ``mask[z, y, x]`` (non-zero = object); voxels
    outside the array count as background (distance 0 there).
    """
    nz, ny, nx = mask.shape
    d = np.empty((nz, ny, nx), np.int32)
    for z in range(nz):
        for y in range(ny):
            for x in range(nx):
                d[z, y, x] = INF345 if mask[z, y, x] else 0
    for z in range(nz):  # forward: the 13 neighbours before (z, y, x) in raster order
        for y in range(ny):
            for x in range(nx):
                if d[z, y, x]:
                    d[z, y, x] = _relax(d, z, y, x, -1)
    for z in range(nz - 1, -1, -1):  # backward: the 13 neighbours after it
        for y in range(ny - 1, -1, -1):
            for x in range(nx - 1, -1, -1):
                if d[z, y, x]:
                    d[z, y, x] = _relax(d, z, y, x, 1)
    return d


@njit(cache=True)
def thinness_chunk(dist, squared, z0, z1, min_thinness, out_xyz, out_dt, out_th):
    """Thinness of every object voxel in slices ``z0 <= z < z1`` of ``dist[z, y, x]``.

    ``dist`` holds squared Euclidean distances (``squared=True``, made exact
    by ``sqrt`` here in float64) or chamfer distances. Thinness is
    ``DT(p) - sum(DT(q) for the 26 neighbours q) / 26``, neighbours outside
    the array counting 0. Points with thinness >= ``min_thinness`` are written
    to the ``out_*`` buffers in raster (file) order; returns how many.
    """
    nz, ny, nx = dist.shape
    n = 0
    for z in range(z0, z1):
        for y in range(ny):
            for x in range(nx):
                c = dist[z, y, x]
                if c == 0:
                    continue
                total = 0.0
                for dz in range(-1, 2):
                    zz = z + dz
                    if zz < 0 or zz >= nz:
                        continue
                    for dy in range(-1, 2):
                        yy = y + dy
                        if yy < 0 or yy >= ny:
                            continue
                        for dx in range(-1, 2):
                            xx = x + dx
                            if xx < 0 or xx >= nx or (dx == 0 and dy == 0 and dz == 0):
                                continue
                            v = dist[zz, yy, xx]
                            if v != 0:
                                total += np.sqrt(np.float64(v)) if squared else np.float64(v)
                dt = np.sqrt(np.float64(c)) if squared else np.float64(c)
                th = dt - total / 26.0
                if th >= min_thinness:
                    out_xyz[n, 0] = x
                    out_xyz[n, 1] = y
                    out_xyz[n, 2] = z
                    out_dt[n] = dt
                    out_th[n] = th
                    n += 1
    return n
