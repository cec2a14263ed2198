"""Runs of a grid's rows and their 26-connected pieces: the grid read once, everything after on runs.

    runs(zyx[, by_value])              -> every row's runs of non-zero voxels (or of one value each)
    run_values(zyx, first, x0)         -> each run's value
    label_runs(zyx[, by_value])        -> the runs, each run's piece (1..n), n; ``by_value``: a piece holds
                                          one value (a label grid's pieces, each label's own)

Pieces are numbered as ``scipy.ndimage.label(zyx != 0, structure=np.ones((3, 3, 3)))`` numbers them: in
the order of their first voxel in ``(z, y, x)`` order (and as cc3d numbers a label grid's).

Labelling: a run touches the runs of the four rows scanned before it that can reach it -- ``(z, y-1)``,
``(z-1, y-1)``, ``(z-1, y)``, ``(z-1, y+1)`` -- when their x-ranges, widened by one voxel, overlap
(26-connectivity) and, ``by_value``, their values are equal. A union-find keeps each piece's smallest
run as its root, so numbering roots in run order numbers pieces in first-voxel order.

Used by the breakage report (reconstruct/_label_kernels.py: the posed frame's pieces, without holding the
GIL) and by ownership's specks (rig/specks.py: each bone's pieces of the rest labels).
"""

from __future__ import annotations

import numpy as np
from numba import njit

# the rows a run of row (z, y) can touch among the rows scanned before it: (dz, dy)
_BEFORE = ((0, -1), (-1, -1), (-1, 0), (-1, 1))


@njit(cache=True, nogil=True)
def runs(zyx, by_value=False):
    """``(first, x0, x1)``: row ``z * ny + y``'s runs of non-zero voxels are ``first[row]:first[row + 1]``,
    each ``x0..x1`` inclusive, in ``(z, y, x)`` order; ``by_value``: a run also ends where the value
    changes (runs of one label each, :func:`run_values`). Counted first, then written: arrays grown
    inside the voxel loop made this 40x slower than reading the grid."""
    nz, ny, nx = zyx.shape
    first = np.zeros(nz * ny + 1, np.int64)
    for z in range(nz):
        for y in range(ny):
            row = zyx[z, y]
            starts = 0
            before = row[0] * 0
            for x in range(nx):
                here = row[x]
                starts += here != 0 and (before == 0 or (by_value and here != before))
                before = here
            first[z * ny + y + 1] = starts
    first = np.cumsum(first)
    x0 = np.empty(first[-1], np.int32)
    x1 = np.empty(first[-1], np.int32)
    for z in range(nz):
        for y in range(ny):
            k = first[z * ny + y]
            if k == first[z * ny + y + 1]:
                continue
            row = zyx[z, y]
            before = row[0] * 0
            for x in range(nx):
                here = row[x]
                changed = here != before and (by_value or here == 0 or before == 0)
                if before != 0 and changed:
                    x1[k] = x - 1
                    k += 1
                if here != 0 and changed:
                    x0[k] = x
                before = here
            if before != 0:
                x1[k] = nx - 1
    return first, x0, x1


@njit(cache=True, nogil=True)
def run_values(zyx, first, x0):
    """The value of each run of :func:`runs` ``(zyx, by_value=True)`` (its first voxel's)."""
    ny = zyx.shape[1]
    out = np.empty(len(x0), np.int64)
    for row in range(len(first) - 1):
        z, y = row // ny, row % ny
        for r in range(first[row], first[row + 1]):
            out[r] = zyx[z, y, x0[r]]
    return out


@njit(cache=True, nogil=True)
def _root(parent, r):
    while parent[r] != r:
        parent[r] = parent[parent[r]]  # path halving
        r = parent[r]
    return r


@njit(cache=True, nogil=True)
def label_runs(zyx, by_value=False):
    """``(first, x0, x1, piece, n)``: the :func:`runs` of ``zyx`` and each run's piece, 1..n; ``by_value``: runs
    of one value each, joined only to runs of the same value."""
    nz, ny, _ = zyx.shape
    first, x0, x1 = runs(zyx, by_value)
    value = run_values(zyx, first, x0) if by_value else np.zeros(0, np.int64)
    parent = np.arange(len(x0))
    for z in range(nz):
        for y in range(ny):
            row = z * ny + y
            for dz, dy in _BEFORE:
                zz, yy = z + dz, y + dy
                if zz < 0 or yy < 0 or yy >= ny:
                    continue
                other = zz * ny + yy  # the two rows' runs, both in x order
                b, b_end = first[other], first[other + 1]
                for a in range(first[row], first[row + 1]):
                    # each run against every run of the other row its widened range touches: runs of one value
                    # each lie side by side, so two runs of a row can touch one run of the other (a sweep that
                    # moves on from the run that ends first misses one of them)
                    while b < b_end and x1[b] < x0[a] - 1:
                        b += 1
                    k = b
                    while k < b_end and x0[k] <= x1[a] + 1:
                        if not by_value or value[a] == value[k]:
                            ra, rk = _root(parent, a), _root(parent, k)
                            if ra < rk:
                                parent[rk] = ra
                            elif rk < ra:
                                parent[ra] = rk
                        k += 1
    piece = np.zeros(len(x0), np.int64)
    n = 0
    for r in range(len(x0)):
        root = _root(parent, r)
        if piece[root] == 0:  # a piece's smallest run is its first: pieces numbered in scan order
            n += 1
            piece[root] = n
        piece[r] = piece[root]
    return first, x0, x1, piece, n
