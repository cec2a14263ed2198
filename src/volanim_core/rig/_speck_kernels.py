"""Numba kernels of ownership's specks (rig/specks.py), on the runs of the labels' rows (volanim_core/_run_kernels.py).

    piece_boxes(first, x0, x1, piece, value, n, ny)  -> each piece's label, voxels and box
    paint_box(first, x0, x1, piece, ny, lo, hi)       -> the pieces of one box, as a small grid
    speck_rings(pieces, specks, boxes)                -> each speck's ring: the pieces of the voxels around it
    relabel_runs(zyx, first, x0, x1, piece, new, value) -> the runs of each piece given a new label, rewritten

Why runs: the labels are the body's box, mostly empty (the frog's 27 M voxels hold 1.2 M of body). cc3d
labelled every voxel into a 108 MB grid of pieces, then a pass read it for the pieces' boxes: 0.10-0.24 s
of the frog's ownership where its skeletonize takes 0.26 (#84: ownership <= skeletonize). The runs read the
labels once; a speck's ring is read on a small grid of its box painted from them.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def piece_boxes(first, x0, x1, piece, value, n, ny):
    """Per piece 0..n: its label (``value`` of its runs), voxels and box ``x0 y0 z0 x1 y1 z1`` (stops
    excluded) in ``[x, y, z]`` indices of the grid whose ``[z, y, x]`` view the runs were found in."""
    label = np.zeros(n + 1, np.int64)
    count = np.zeros(n + 1, np.int64)
    box = np.empty((n + 1, 6), np.int64)
    box[:, :3], box[:, 3:] = np.iinfo(np.int64).max, -1
    for row in range(len(first) - 1):
        z, y = row // ny, row % ny
        for r in range(first[row], first[row + 1]):
            p = piece[r]
            label[p] = value[r]
            count[p] += x1[r] - x0[r] + 1
            b = box[p]
            b[0], b[1], b[2] = min(b[0], x0[r]), min(b[1], y), min(b[2], z)
            b[3], b[4], b[5] = max(b[3], x1[r] + 1), max(b[4], y + 1), max(b[5], z + 1)
    return label, count, box


@njit(cache=True, nogil=True)
def paint_box(first, x0, x1, piece, ny, lo, hi):
    """The pieces (0: none) of the ``[x, y, z]`` box ``lo .. hi - 1`` as a grid ``[x, y, z]`` of its size."""
    out = np.zeros((hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]), np.int64)
    for z in range(lo[2], hi[2]):
        for y in range(lo[1], hi[1]):
            row = z * ny + y
            for r in range(first[row], first[row + 1]):
                for x in range(max(x0[r], lo[0]), min(x1[r] + 1, hi[0])):
                    out[x - lo[0], y - lo[1], z - lo[2]] = piece[r]
    return out


@njit(cache=True, nogil=True)
def speck_rings(pieces, specks, boxes):
    """Each speck's ring: the piece (0: outside the body) of every voxel 26-next to speck ``specks[k]`` and not in
    it, once each. ``boxes[k]``: the speck's box ``x0 y0 z0 x1 y1 z1`` (stops excluded). Returns ``starts``
    (``K + 1``) and the rings' pieces, speck k's at ``ring[starts[k]:starts[k + 1]]``."""
    nx, ny, nz = pieces.shape
    room = 0
    for k in range(len(specks)):
        room += (boxes[k, 3] - boxes[k, 0] + 2) * (boxes[k, 4] - boxes[k, 1] + 2) * (boxes[k, 5] - boxes[k, 2] + 2)
    ring = np.empty(room, np.int64)
    starts = np.zeros(len(specks) + 1, np.int64)
    n = 0
    for k in range(len(specks)):
        p = specks[k]
        x0, y0, z0 = max(0, boxes[k, 0] - 1), max(0, boxes[k, 1] - 1), max(0, boxes[k, 2] - 1)
        x1, y1, z1 = min(nx, boxes[k, 3] + 1), min(ny, boxes[k, 4] + 1), min(nz, boxes[k, 5] + 1)
        seen = np.zeros((x1 - x0, y1 - y0, z1 - z0), np.bool_)
        for z in range(boxes[k, 2], boxes[k, 5]):
            for y in range(boxes[k, 1], boxes[k, 4]):
                for x in range(boxes[k, 0], boxes[k, 3]):
                    if pieces[x, y, z] != p:
                        continue
                    for c in range(max(z0, z - 1), min(z1, z + 2)):
                        for b in range(max(y0, y - 1), min(y1, y + 2)):
                            for a in range(max(x0, x - 1), min(x1, x + 2)):
                                if pieces[a, b, c] != p and not seen[a - x0, b - y0, c - z0]:
                                    seen[a - x0, b - y0, c - z0] = True
                                    ring[n] = pieces[a, b, c]
                                    n += 1
        starts[k + 1] = n
    return starts, ring[:n]


@njit(cache=True, nogil=True)
def relabel_runs(zyx, first, x0, x1, piece, new, value):
    """Every run of a piece ``p`` with ``new[p] > 0`` rewritten to ``new[p]`` in ``zyx`` and in its ``value``;
    returns the voxels."""
    ny = zyx.shape[1]
    moved = 0
    for row in range(len(first) - 1):
        z, y = row // ny, row % ny
        for r in range(first[row], first[row + 1]):
            v = new[piece[r]]
            if v > 0:
                for x in range(x0[r], x1[r] + 1):
                    zyx[z, y, x] = v
                value[r] = v
                moved += x1[r] - x0[r] + 1
    return moved
