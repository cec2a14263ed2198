"""Numba kernel of the points a bone's convex hull is made from (rig/ownership.py's hulls()): the corners of each
slice's outline, read from row_spans' spans.

    hull_ends(spans)   each bone's row ends that are corners of its slice's convex outline (Andrew's chain)
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True, inline="always")
def _side(ys, xs, n, sign, out_y, out_x):
    """The convex chain of ``n`` points ``(y, x)`` (y rising) seen from the side ``sign`` (-1: least x, 1: most x)
    into ``out_*``: Andrew's monotone chain, points on a straight stretch dropped. Returns its length."""
    k = 0
    for i in range(n):
        while k >= 2 and sign * ((out_y[k - 1] - out_y[k - 2]) * (xs[i] - out_x[k - 2])
                                 - (out_x[k - 1] - out_x[k - 2]) * (ys[i] - out_y[k - 2])) >= 0:
            k -= 1
        out_y[k], out_x[k] = ys[i], xs[i]
        k += 1
    return k


@njit(cache=True, nogil=True)
def hull_ends(spans):
    """From :func:`row_spans`' ``spans (B, Y, Z, 2)``: each bone's row ends that are corners of its slice's convex
    outline, ``(points (N, 3) x y z, bone (N,))``. Every vertex of a bone's convex hull is a corner of its
    slice's outline, so these hold all of them: a slice's chain, not its every row, goes to qhull."""
    nb, ny, nz = spans.shape[0], spans.shape[1], spans.shape[2]
    pts = np.empty((2 * ny * nz, 3), np.int64)
    lab = np.empty(2 * ny * nz, np.int64)
    ys, xs, cy, cx = np.empty(ny, np.int64), np.empty(ny, np.int64), np.empty(ny, np.int64), np.empty(ny, np.int64)
    mine = np.empty((nz, ny, 2), spans.dtype)  # one bone's spans slice by slice: read in their order, once
    n = 0
    for b in range(nb):
        if n + 2 * ny * nz > len(lab):  # room for one more bone's worst case, doubled (grown by one case a
            # bone, mannequin-large's copies came to 60 MB: 12 ms)
            grow = max(len(lab), 2 * ny * nz)
            pts = np.concatenate((pts[:n], np.empty((grow, 3), np.int64)))
            lab = np.concatenate((lab[:n], np.empty(grow, np.int64)))
        z_lo, z_hi = nz, -1  # the slices the bone has rows in: most bones hold few of the body's
        for y in range(ny):  # (a slice's rows lie nz * 2 apart in spans: read in their order, once)
            for z in range(nz):
                mine[z, y, 0], mine[z, y, 1] = spans[b, y, z, 0], spans[b, y, z, 1]
                if mine[z, y, 0] <= mine[z, y, 1]:
                    z_lo, z_hi = min(z_lo, z), max(z_hi, z)
        for z in range(z_lo, z_hi + 1):
            for end in range(2):
                m = 0
                for y in range(ny):
                    if mine[z, y, 0] <= mine[z, y, 1]:
                        ys[m], xs[m] = y, mine[z, y, end]
                        m += 1
                for i in range(_side(ys, xs, m, 2 * end - 1, cy, cx)):
                    pts[n, 0], pts[n, 1], pts[n, 2] = cx[i], cy[i], z
                    lab[n] = b
                    n += 1
    return pts[:n], lab[:n]
