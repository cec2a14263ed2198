"""numba kernel for auto-connect: the first candidate bone reachable by a straight path inside the mask."""

from __future__ import annotations

import numpy as np
from numba import njit, prange


@njit(cache=True, inline="always")
def _path_inside(mask, p0, p1, step):
    """All samples of the segment p0-p1 (every ``step`` voxels) fall in object voxels."""
    d0, d1, d2 = p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]
    length = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    n = int(np.ceil(length / step)) + 1
    nx, ny, nz = mask.shape
    for k in range(n + 1):
        t = k / n if n > 0 else 0.0
        x = int(np.floor(p0[0] + t * d0 + 0.5))
        y = int(np.floor(p0[1] + t * d1 + 0.5))
        z = int(np.floor(p0[2] + t * d2 + 0.5))
        if x < 0 or y < 0 or z < 0 or x >= nx or y >= ny or z >= nz or not mask[x, y, z]:
            return False
    return True


@njit(cache=True, parallel=True)
def first_reachable(points, segments, order, mask, step, out):
    """For each point, the first bone in ``order[i]`` (nearest first) whose closest point on the
    segment is reachable by a straight path inside ``mask``; -1 when none is."""
    n, k = order.shape
    for i in prange(n):
        out[i] = -1
        p = points[i].astype(np.float64)
        for c in range(k):
            b = order[i, c]
            a = segments[b, 0]
            ab = segments[b, 1] - a
            denom = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2]
            t = 0.0
            if denom > 1e-12:
                t = ((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1] + (p[2] - a[2]) * ab[2]) / denom
                t = min(max(t, 0.0), 1.0)
            q = a + t * ab
            if _path_inside(mask, p, q, step):
                out[i] = b
                break


@njit(cache=True, parallel=True)
def _path_inside_many(points, rows, cols, mask, step):
    """Whether each edge ``points[rows[e]]``-``points[cols[e]]`` runs inside the mask."""
    out = np.empty(len(rows), np.bool_)
    for e in prange(len(rows)):
        out[e] = _path_inside(mask, points[rows[e]], points[cols[e]], step)
    return out
