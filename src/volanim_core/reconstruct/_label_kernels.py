"""The 26-connected pieces of a grid, found and measured on its x-runs, without holding Python's GIL.

    runs, run_values, label_runs       -> the runs and their pieces (volanim_core/_run_kernels.py, shared
                                          with ownership's specks)
    piece_stats(...)                   -> each piece's voxel count and coordinate sums
    group_starts(counts, skip)         -> where each piece's rows start in piece_voxels' output
    piece_voxels(..., skip)            -> every voxel of each piece but ``skip``, grouped by piece
    boundary_voxels(zyx, ..., piece)   -> the piece's voxels with an empty 6-neighbour in the grid
    piece_at(..., points)              -> the piece each voxel lies in (0: empty)

Pieces are numbered as ``scipy.ndimage.label(zyx != 0, structure=np.ones((3, 3, 3)))``
numbers them: in the order of their first voxel in ``(z, y, x)`` order.

Why runs, and why not a library: the breakage report labels the studio's full
preview on a worker thread. cc3d (used before) labels voxels and holds the GIL
for its whole call -- 70 ms on the frog's 45 M voxels alone, 220-300 ms while
the window's software OpenGL drew on the same cores -- so the window froze for
that long once per preview; scipy's label is 3x slower still. The frog's posed
body is 1.2 M voxels in 122 k runs: reading the grid once finds them, everything
after works on runs, no label grid (180 MB for the frog) is made, and every
kernel here is ``nogil``.

How the runs are labelled: volanim_core/_run_kernels.py.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from volanim_core._run_kernels import label_runs, run_values, runs  # noqa: F401  (the breakage report's names)


@njit(cache=True, nogil=True)
def piece_stats(first, x0, x1, piece, n, ny):
    """Per piece 0..n (0: none, not measured): its voxel count and the sum of its voxels' ``(z, y, x)``."""
    counts = np.zeros(n + 1, np.int64)
    sums = np.zeros((n + 1, 3))
    for row in range(len(first) - 1):
        z, y = row // ny, row % ny
        for r in range(first[row], first[row + 1]):
            k, c = piece[r], x1[r] - x0[r] + 1
            counts[k] += c
            sums[k, 0] += z * c
            sums[k, 1] += y * c
            sums[k, 2] += (x0[r] + x1[r]) * c / 2  # an integer or a half: exact in float64
    return counts, sums


@njit(cache=True, nogil=True)
def group_starts(counts, skip):
    """``start``: groups 1..n but ``skip``, laid out in order, group k in rows ``start[k]:start[k + 1]``
    (none for 0 and ``skip``), ``start[-1]`` rows in all; ``counts[k]`` is group k's size."""
    n = len(counts) - 1
    start = np.zeros(n + 2, np.int64)
    for k in range(1, n + 1):
        start[k + 1] = start[k] + (counts[k] if k != skip else 0)
    return start


@njit(cache=True, nogil=True)
def piece_voxels(first, x0, x1, piece, counts, skip, ny):
    """``(start, voxels)``: the ``(z, y, x)`` of every voxel of each piece but ``skip``, piece k's being
    ``voxels[start[k]:start[k + 1]]``, in scan order; ``counts`` from :func:`piece_stats`."""
    start = group_starts(counts, skip)
    fill = start.copy()
    out = np.empty((start[-1], 3), np.int64)
    for row in range(len(first) - 1):
        z, y = row // ny, row % ny
        for r in range(first[row], first[row + 1]):
            k = piece[r]
            if k == skip:
                continue
            f = fill[k]
            for x in range(x0[r], x1[r] + 1):
                out[f, 0], out[f, 1], out[f, 2] = z, y, x
                f += 1
            fill[k] = f
    return start, out


@njit(cache=True, nogil=True)
def boundary_voxels(zyx, first, x0, x1, piece, label):
    """``(z, y, x)`` of the voxels of piece ``label`` with a 6-neighbour in the grid that is not, in
    scan order. A 6-neighbour that is not empty is the same piece, so "not the piece" is "empty".

    The voxel of a piece nearest to any voxel outside it is one of these: were it inside, its
    neighbour one step towards the outside voxel (along the largest difference) would be closer."""
    nz, ny, nx = zyx.shape
    size = 0
    for r in range(len(x0)):
        if piece[r] == label:
            size += x1[r] - x0[r] + 1
    out = np.empty((size, 3), np.int64)  # at most every voxel of the piece
    f = 0
    for row in range(len(first) - 1):
        z, y = row // ny, row % ny
        for r in range(first[row], first[row + 1]):
            if piece[r] != label:
                continue
            for x in range(x0[r], x1[r] + 1):
                # a run's ends have an empty neighbour along x, unless it is the grid's edge
                if (x == x0[r] and x > 0) or (x == x1[r] and x < nx - 1) or \
                        (y > 0 and zyx[z, y - 1, x] == 0) or (y < ny - 1 and zyx[z, y + 1, x] == 0) or \
                        (z > 0 and zyx[z - 1, y, x] == 0) or (z < nz - 1 and zyx[z + 1, y, x] == 0):
                    out[f, 0], out[f, 1], out[f, 2] = z, y, x
                    f += 1
    return out[:f]


@njit(cache=True, nogil=True)
def piece_at(first, x0, x1, piece, shape, zyx_points):
    """The piece (1..n, 0: empty or outside) of each ``(z, y, x)`` point of a grid of ``shape``, by a
    binary search among its row's runs (no label grid)."""
    nz, ny, nx = shape
    out = np.zeros(len(zyx_points), np.int64)
    for i in range(len(zyx_points)):
        z, y, x = zyx_points[i, 0], zyx_points[i, 1], zyx_points[i, 2]
        if z < 0 or y < 0 or x < 0 or z >= nz or y >= ny or x >= nx:
            continue
        row = z * ny + y
        lo, hi = first[row], first[row + 1]
        while lo < hi:  # the first run ending at or after x
            mid = (lo + hi) // 2
            if x1[mid] < x:
                lo = mid + 1
            else:
                hi = mid
        if lo < first[row + 1] and x0[lo] <= x:
            out[i] = piece[lo]
    return out
