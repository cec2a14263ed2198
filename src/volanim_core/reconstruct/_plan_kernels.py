"""numba kernels of a frame's plan (plan.py), run before the fill kernels (_kernels.py).

    spheres_fit       every sphere within a coordinate limit (the frame's checks)
    sphere_box        the box around all spheres (the output grid)
    build_halfspaces  the overdraw cut: each big sphere's planes against its neighbours (bisector
                      against larger, power plane against smaller), in its own frame, with the margin
    slice_lists       bucket spheres by the output z-slices they overlap, keeping file order
                      inside each slice (that order is the tie-break)
    snapped_squares   the radii squared as the kernels compare them (radii.py)
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def spheres_fit(centres, extents, limit):
    """True when every sphere (centre +- extent, the extent not negative) is finite and lies within
    ``limit`` voxels of the origin: the frame checks' fast path, one pass (on the frog the NumPy checks
    took 4 ms of a 65 ms call); only when it fails do the callers find the point and say what is wrong."""
    for i in range(centres.shape[0]):
        e = extents[i]
        reach = max(abs(centres[i, 0]), abs(centres[i, 1]), abs(centres[i, 2])) + e
        if not (e >= 0.0 and reach <= limit):  # NaN fails both
            return False
    return True


@njit(cache=True)
def sphere_box(centres, extents):
    """``(lo[3], hi[3])``: the smallest and largest ``centre -+ extent`` on each axis (finite input)."""
    lo = np.full(3, np.inf)
    hi = np.full(3, -np.inf)
    for i in range(centres.shape[0]):
        e = extents[i]
        for k in range(3):
            lo[k] = min(lo[k], centres[i, k] - e)
            hi[k] = max(hi[k], centres[i, k] + e)
    return lo, hi


@njit(cache=True)
def _cuts(r2i, r2j, d0, d1, d2):
    """True when sphere i's plane against j (at ``d`` from it) cuts its ball: a plane that misses it
    would still cost each slice a test and deny the sphere the cheaper box sweep."""
    d2sum = d0 * d0 + d1 * d1 + d2 * d2
    # the plane's distance from c_i, times 2 |d|: |d|^2 + max(0, r_i^2 - r_j^2)
    return d2sum > 0.0 and d2sum + max(0.0, r2i - r2j) < 2.0 * np.sqrt(d2sum * r2i)


@njit(cache=True)
def build_halfspaces(centres, r2s, neighbours, min_r2):
    """Each big sphere's cut planes against its neighbours, with the float margin, in the sphere's own
    frame ``u = q - c_i``: ``a.u + w <= 0`` keeps ``q``, where ``a = 2 (c_j - c_i)`` and
    ``w = -|c_j - c_i|^2 - max(0, r_i^2 - r_j^2) - margin``, so ``a.u + w`` is
    ``|q - c_i|^2 - |q - c_j|^2 - max(0, r_i^2 - r_j^2) - margin`` computed from small numbers (its
    rounding stays far below the margin wherever the grid lies). Against a larger neighbour that is
    the bisector plane, against a smaller one their power plane (_kernels.py says why each is exact).
    Column 4 is ``|(a_x, a_y)|``, how fast the value changes within a slice. Sphere i's planes are
    rows ``start[i]:start[i + 1]``; spheres with ``r2 < min_r2`` get none: for small spheres
    clipping each row costs more than it saves. Only planes that cut the ball are kept (dropping a
    cut is always exact): a big sphere among much smaller ones (the frog's) has power planes that
    all miss it."""
    n, k = neighbours.shape
    start = np.zeros(n + 1, np.int64)
    keep = np.zeros((n, k), np.bool_)
    for i in range(n):
        c = 0
        if r2s[i] >= min_r2:
            for h in range(k):
                j = neighbours[i, h]
                if j >= 0 and _cuts(np.float64(r2s[i]), np.float64(r2s[j]), centres[j, 0] - centres[i, 0],
                                    centres[j, 1] - centres[i, 1], centres[j, 2] - centres[i, 2]):
                    keep[i, h] = True
                    c += 1
        start[i + 1] = start[i] + c
    planes = np.empty((start[n], 5))
    for i in range(n):
        if start[i + 1] == start[i]:
            continue
        margin = r2s[i] * 2.0**-20 + 1e-6
        row = start[i]
        for h in range(k):
            if not keep[i, h]:
                continue
            j = neighbours[i, h]
            d0 = centres[j, 0] - centres[i, 0]
            d1 = centres[j, 1] - centres[i, 1]
            d2 = centres[j, 2] - centres[i, 2]
            # the radii's difference is exact: float32 squares (integers below 2^24, or a sheet's thinned ones)
            shift = max(0.0, np.float64(r2s[i]) - np.float64(r2s[j]))
            planes[row, 0] = 2.0 * d0
            planes[row, 1] = 2.0 * d1
            planes[row, 2] = 2.0 * d2
            planes[row, 3] = -(d0 * d0 + d1 * d1 + d2 * d2) - shift - margin
            planes[row, 4] = 2.0 * np.sqrt(d0 * d0 + d1 * d1)
            row += 1
    return start, planes


@njit(cache=True)
def slice_lists(zlo, zhi, nz):
    """Spheres per z-slice: ``(offsets[nz + 1], ids)``, file order within a slice."""
    starts = np.zeros(nz + 1, np.int64)  # spheres starting minus spheres ending at each slice ...
    for i in range(len(zlo)):
        a, b = max(zlo[i], 0), min(zhi[i], nz - 1)
        if a <= b:
            starts[a] += 1
            starts[b + 1] -= 1
    offsets = np.zeros(nz + 1, np.int64)
    running = 0
    for z in range(nz):  # ... summed: the spheres on each slice
        running += starts[z]
        offsets[z + 1] = offsets[z] + running
    ids = np.empty(offsets[-1], np.int32)
    fill = offsets[:-1].copy()
    for i in range(len(zlo)):
        for z in range(max(zlo[i], 0), min(zhi[i], nz - 1) + 1):
            ids[fill[z]] = i
            fill[z] += 1
    return offsets, ids


@njit(cache=True)
def snapped_squares(dt):
    """``dt**2`` per sphere, snapped to the nearest integer within 1e-9 (relative): radii.py's kernel."""
    # one pass: the NumPy expression made five temporaries the size of the frog's 137 k radii
    out = np.empty(len(dt))
    for i in range(len(dt)):
        r2 = dt[i] * dt[i]
        near = np.rint(r2)
        out[i] = near if abs(r2 - near) <= 1e-9 * max(1.0, r2) else r2
    return out
