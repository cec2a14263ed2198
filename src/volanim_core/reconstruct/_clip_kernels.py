"""Clipped voxels: how much of the spheres falls outside the output grid (the reconstruction's
``clipped`` statistic), counted per row from run ends found by bisection."""

from __future__ import annotations

import numpy as np
from numba import njit

from volanim_core.reconstruct._kernels import EUCLID, _inside


@njit(cache=True)
def _last_inside(metric, cx, dy, dz, r2, r, inside, outside):
    """Bisect between an x inside the sphere and an x outside it: the last inside x towards ``outside``."""
    dy2, dz2 = dy * dy, dz * dz
    while abs(outside - inside) > 1.0:
        mid = np.floor((inside + outside) / 2.0)
        if _inside(metric, mid - cx, dy, dz, dy2, dz2, r2, r):
            inside = mid
        else:
            outside = mid
    return inside


@njit(cache=True)
def _row_run(metric, cx, dy, dz, r2, r, half):
    """``(x0, x1)``, the inclusive run of integer x inside the sphere on one row (x1 < x0: none).

    Distance grows monotonically away from the centre along a row (both metrics
    are norms), so the voxel nearest the centre decides whether the run is empty
    and bisection finds its ends: O(log r) per row, never O(r).
    """
    xn = np.floor(cx + 0.5)
    if not _inside(metric, xn - cx, dy, dz, dy * dy, dz * dz, r2, r):
        return 0.0, -1.0
    x0 = _last_inside(metric, cx, dy, dz, r2, r, xn, np.floor(cx - half) - 1.0)
    x1 = _last_inside(metric, cx, dy, dz, r2, r, xn, np.ceil(cx + half) + 1.0)
    return x0, x1


@njit(cache=True)
def count_outside(centres, r2s, radii, metric, shape, row_budget):
    """Sphere voxels that fall outside the grid ``shape = (nz, ny, nx)`` (clipped), summed.

    Counted per row from run ends (O(log r) a row). A sphere with more than
    ``row_budget`` rows in its box (radius ~ sqrt(budget) / 2) has its total
    estimated from the continuous ball's volume instead; returns
    ``(count, estimated)``.
    """
    nz, ny, nx = shape
    total = 0.0
    estimated = False
    for i in range(len(centres)):
        cx, cy, cz = centres[i, 0], centres[i, 1], centres[i, 2]
        r2, r = r2s[i], radii[i]
        half = np.sqrt(r2) if metric == EUCLID else r / 3.0
        if cx - half >= 0 and cy - half >= 0 and cz - half >= 0 and \
                cx + half <= nx - 1 and cy + half <= ny - 1 and cz + half <= nz - 1:
            continue
        z0, z1 = np.floor(cz - half) - 1.0, np.ceil(cz + half) + 1.0
        y0, y1 = np.floor(cy - half) - 1.0, np.ceil(cy + half) + 1.0
        inside_grid = 0.0
        for z in range(int(max(z0, 0.0)), int(min(z1, nz - 1.0)) + 1):
            for y in range(int(max(y0, 0.0)), int(min(y1, ny - 1.0)) + 1):
                a, b = _row_run(metric, cx, y - cy, z - cz, r2, r, half)
                a, b = max(a, 0.0), min(b, nx - 1.0)
                if b >= a:
                    inside_grid += b - a + 1.0
        if (z1 - z0 + 1.0) * (y1 - y0 + 1.0) <= row_budget:
            whole = 0.0
            for zf in range(int(z1 - z0) + 1):
                for yf in range(int(y1 - y0) + 1):
                    a, b = _row_run(metric, cx, y0 + yf - cy, z0 + zf - cz, r2, r, half)
                    if b >= a:
                        whole += b - a + 1.0
        else:
            estimated = True
            if metric == EUCLID:
                whole = 4.0 / 3.0 * np.pi * r2 * np.sqrt(r2)
            else:  # the chamfer ball 3a + b + c < r: 48 sorted-orthant simplices of r^3 / 360 each
                whole = 48.0 / 360.0 * r * r * r
        total += max(whole - inside_grid, 0.0)
    return total, estimated
