"""Numba kernels of the points a bone's convex hull is made from (rig/ownership.py's hulls()): the corners of each
slice's outline, read from row_spans' spans, then those of them that are corners of their y plane's outline too.

    hull_ends(spans)                       each bone's row ends that are corners of its z slice's convex outline
    plane_corners(pts, lab, ny, nz)        of those, the ones that are corners of their y plane's outline as well

A vertex of a convex hull is a corner of the outline of the hull's points in any plane through it: were it
between two of them, it would be between two points of the hull. So each filter keeps every vertex, and the points
kept bound a posed bone's box as its hull's vertices would, with no qhull (mannequin-large: 47,000 row ends ->
7,600 points).
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True, inline="always")
def _side(ys, xs, ids, n, sign, out_y, out_x, out_ids):
    """The convex chain of ``n`` points ``(y, x)`` (y rising) seen from the side ``sign`` (-1: least x, 1: most x)
    into ``out_*`` (``ids``: what each point is, carried along): Andrew's monotone chain, points on a straight
    stretch dropped. Returns its length."""
    k = 0
    for i in range(n):
        while k >= 2 and sign * ((out_y[k - 1] - out_y[k - 2]) * (xs[i] - out_x[k - 2])
                                 - (out_x[k - 1] - out_x[k - 2]) * (ys[i] - out_y[k - 2])) >= 0:
            k -= 1
        out_y[k], out_x[k], out_ids[k] = ys[i], xs[i], ids[i]
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
    ci = np.empty(ny, np.int64)
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
                for i in range(_side(ys, xs, ys, m, 2 * end - 1, cy, cx, ci)):
                    pts[n, 0], pts[n, 1], pts[n, 2] = cx[i], cy[i], z
                    lab[n] = b
                    n += 1
    return pts[:n], lab[:n]


@njit(cache=True, nogil=True)
def plane_corners(pts, lab, ny, nz):
    """Of :func:`hull_ends`' points (bone by bone, ``(x, y, z)``), the ones that are corners of the convex outline of
    their bone's points in their y plane: ``keep (N,)`` bool. A plane's points are at most two a slice (a row's
    ends), so its outline is the chain of the least x seen from -x and of the most x seen from +x, z rising."""
    n = len(lab)
    keep = np.zeros(n, np.bool_)
    least, most = np.full((ny, nz), -1, np.int64), np.full((ny, nz), -1, np.int64)  # the point with the least x ...
    zs, xs, ids = np.empty(nz, np.int64), np.empty(nz, np.int64), np.empty(nz, np.int64)
    cz, cx, ci = np.empty(nz, np.int64), np.empty(nz, np.int64), np.empty(nz, np.int64)
    start = 0
    while start < n:
        stop = start
        while stop < n and lab[stop] == lab[start]:
            stop += 1
        y_lo, y_hi, z_lo, z_hi = ny, -1, nz, -1
        for i in range(start, stop):
            y, z = pts[i, 1], pts[i, 2]
            if least[y, z] < 0 or pts[i, 0] < pts[least[y, z], 0]:
                least[y, z] = i
            if most[y, z] < 0 or pts[i, 0] > pts[most[y, z], 0]:
                most[y, z] = i
            y_lo, y_hi, z_lo, z_hi = min(y_lo, y), max(y_hi, y), min(z_lo, z), max(z_hi, z)
        for y in range(y_lo, y_hi + 1):
            for end in range(2):
                side = least if end == 0 else most
                m = 0
                for z in range(z_lo, z_hi + 1):
                    if side[y, z] >= 0:
                        zs[m], xs[m], ids[m] = z, pts[side[y, z], 0], side[y, z]
                        m += 1
                for i in range(_side(zs, xs, ids, m, 2 * end - 1, cz, cx, ci)):
                    keep[ci[i]] = True
        for i in range(start, stop):  # cleared for the next bone
            least[pts[i, 1], pts[i, 2]], most[pts[i, 1], pts[i, 2]] = -1, -1
        start = stop
    return keep
