"""Numba kernels of the ownership warp (reconstruct/owned.py): each output voxel read once per bone that can reach it.

    warp_owners(labels, rest_lo, inv, boxes, out_lo, out, row_lo, row_hi, claims, count)
        every output voxel q, for each bone b whose posed box holds q (root order):
        r = round([q 1] @ inv[b]); q is b's when labels[r - rest_lo] == b + 1 (the first such bone keeps it)
    close_joints(out, out_lo, centres, r2s, bones, row_lo, row_hi, claims)
        every empty voxel strictly inside a joint's ball goes to that ball's bone

Why an inverse warp: a forward one (each owned voxel pushed to its posed place) leaves holes wherever a
rotation spreads voxels apart; reading each output voxel from the rest voxel its bone brings it from writes
every output voxel at most once per bone and leaves none out. Nearest-voxel reading makes the identity pose
give back the rest labels exactly. ``claims`` counts the bones (and balls) reaching a voxel: the hotspot mode.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numba import njit


@njit(cache=True, nogil=True, inline="always")
def _row_span(bx, by, bz, sx, sy, sz, box, x_lo):
    """The output x range (one voxel wider, exactness is kept by the read itself) whose rest point
    ``(b + (x + x_lo) s)`` rounds into ``box`` (``x0 y0 z0 x1 y1 z1``); (1, 0) when none."""
    t0, t1 = -1e30, 1e30
    for base, step, lo, hi in ((bx, sx, box[0], box[3]), (by, sy, box[1], box[4]), (bz, sz, box[2], box[5])):
        a, c = lo - 0.5 - base, hi + 0.5 - base
        if abs(step) < 1e-12:
            if a > 0 or c < 0:
                return 1, 0
            continue
        u, w = a / step, c / step
        if u > w:
            u, w = w, u
        t0, t1 = max(t0, u), min(t1, w)
    if t1 < t0:
        return 1, 0
    return int(math.floor(max(t0, -1e9))) - x_lo - 1, int(math.ceil(min(t1, 1e9))) - x_lo + 1


@njit(cache=True, nogil=True, parallel=True)
def warp_owners(labels, rest_lo, inv, boxes, rest_boxes, out_lo, out, row_lo, row_hi, claims, count):
    """``out`` ``[z, y, x]`` (zeroed): each voxel's owning bone + 1. ``labels`` ``[x, y, z]``: the rest owners,
    voxel ``[0, 0, 0]`` at rest voxel ``rest_lo``. ``boxes[b]``: bone b's posed box ``x0 y0 z0 x1 y1 z1`` in
    output indices (empty when x1 < x0); ``rest_boxes[b]`` its owned voxels' box in ``labels``' indices: each
    row reads only where its straight line through the rest frame crosses that box. ``row_lo/row_hi[z, y]``:
    each row's span of written voxels. ``count``: also count every bone reaching a voxel in ``claims``
    (hotspot), else stop at the first. Returns the voxel-bone reads."""
    nz, ny, nx = out.shape
    lx, ly, lz = labels.shape
    nb = inv.shape[0]
    reads = np.zeros(nz, np.int64)
    for z in numba.prange(nz):
        n = 0
        qz = z + out_lo[2]
        for y in range(ny):
            qy = y + out_lo[1]
            lo_x, hi_x = nx, -1
            for b in range(nb):
                if z < boxes[b, 2] or z > boxes[b, 5] or y < boxes[b, 1] or y > boxes[b, 4]:
                    continue
                m = inv[b]
                # the rest point of x = 0 and its step per x: a row is a straight line in the rest frame
                bx = qy * m[1, 0] + qz * m[2, 0] + m[3, 0] - rest_lo[0]
                by = qy * m[1, 1] + qz * m[2, 1] + m[3, 1] - rest_lo[1]
                bz = qy * m[1, 2] + qz * m[2, 2] + m[3, 2] - rest_lo[2]
                x0, x1 = _row_span(bx, by, bz, m[0, 0], m[0, 1], m[0, 2], rest_boxes[b], out_lo[0])
                for x in range(max(x0, boxes[b, 0]), min(x1, boxes[b, 3]) + 1):
                    qx = x + out_lo[0]
                    n += 1
                    if not count and out[z, y, x] != 0:
                        continue
                    ix = int(math.floor(bx + qx * m[0, 0] + 0.5))
                    iy = int(math.floor(by + qx * m[0, 1] + 0.5))
                    iz = int(math.floor(bz + qx * m[0, 2] + 0.5))
                    if ix < 0 or iy < 0 or iz < 0 or ix >= lx or iy >= ly or iz >= lz:
                        continue
                    v = labels[ix, iy, iz]
                    if v != b + 1:
                        continue
                    if out[z, y, x] == 0:
                        out[z, y, x] = b + 1
                        lo_x = min(lo_x, x)
                        hi_x = max(hi_x, x)
                    if count:
                        claims[z, y, x] += 1
            row_lo[z, y] = min(row_lo[z, y], lo_x)
            row_hi[z, y] = max(row_hi[z, y], hi_x)
        reads[z] = n
    return reads.sum()


@njit(cache=True, nogil=True, parallel=True)
def close_joints(out, out_lo, centres, r2s, bones, row_lo, row_hi, claims, count):
    """Every empty voxel of ``out`` strictly inside a ball (``centres[k]``, squared radius ``r2s[k]``, in rest-grid
    coordinates of the posed frame) is given to the ball's bone ``bones[k]`` (+ 1). Balls in order, the first
    to reach an empty voxel keeps it; ``count``: each ball adds one claim to the voxels it covers."""
    nz, ny, nx = out.shape
    for k in range(len(r2s)):
        r = math.sqrt(r2s[k])
        cx, cy, cz = centres[k, 0] - out_lo[0], centres[k, 1] - out_lo[1], centres[k, 2] - out_lo[2]
        z0, z1 = max(0, int(math.ceil(cz - r))), min(nz - 1, int(math.floor(cz + r)))
        for z in numba.prange(z0, z1 + 1):
            dz2 = (z - cz) ** 2
            for y in range(max(0, int(math.ceil(cy - r))), min(ny - 1, int(math.floor(cy + r))) + 1):
                rest = r2s[k] - dz2 - (y - cy) ** 2
                if rest <= 0:
                    continue
                h = math.sqrt(rest)
                for x in range(max(0, int(math.ceil(cx - h))), min(nx - 1, int(math.floor(cx + h))) + 1):
                    if (x - cx) ** 2 + (y - cy) ** 2 + dz2 >= r2s[k]:
                        continue
                    if count:
                        claims[z, y, x] += 1
                    if out[z, y, x] == 0:
                        out[z, y, x] = bones[k] + 1
                        row_lo[z, y] = min(row_lo[z, y], x)
                        row_hi[z, y] = max(row_hi[z, y], x)
