"""Numba kernel of the rest body's ownership (rig/ownership.py): each voxel to the bone whose tube holds it deepest."""

from __future__ import annotations

import math

import numba
import numpy as np
from numba import njit


@njit(cache=True, nogil=True, inline="always")
def tube_distance(tube, px, py, pz):
    """Point p's distance from the tube ``a(3) ab(3) 1/|ab|^2 s0 ds w1(3) w2(3) w3(3)`` relative to its size:
    < 1 inside. The offset v from the segment's nearest point (t clamped to 0..1) is measured along three
    axes scaled by the tube's semi-axes (``w_i = e_i / a_i``: an elliptic cross-section, round end caps
    stretched alike) and tapered by ``s0 + t ds``."""
    dx, dy, dz = px - tube[0], py - tube[1], pz - tube[2]
    t = min(1.0, max(0.0, (dx * tube[3] + dy * tube[4] + dz * tube[5]) * tube[6]))
    vx, vy, vz = dx - t * tube[3], dy - t * tube[4], dz - t * tube[5]
    s = tube[7] + t * tube[8]
    q = 0.0
    for i in range(3):
        c = vx * tube[9 + 3 * i] + vy * tube[10 + 3 * i] + vz * tube[11 + 3 * i]
        q += c * c
    return math.sqrt(q) / s


@njit(cache=True, nogil=True, parallel=True)
def own_by_tubes(mask, lo, tubes, out):
    """``out[x, y, z]`` = 1 + the bone whose tube holds mask voxel ``(x, y, z) + lo`` deepest relative to its
    size (the least :func:`tube_distance`); 0 outside the mask."""
    nx, ny, nz = mask.shape
    nb = tubes.shape[0]
    for z in numba.prange(nz):
        for y in range(ny):
            for x in range(nx):
                if not mask[x, y, z]:
                    continue
                best, who = np.inf, 0
                for b in range(nb):
                    d = tube_distance(tubes[b], x + lo[0], y + lo[1], z + lo[2])
                    if d < best:
                        best, who = d, b + 1
                out[x, y, z] = who


@njit(cache=True, nogil=True)
def label_boxes(labels, boxes):
    """``boxes[l - 1]`` = ``x0 y0 z0 x1 y1 z1`` of label l's voxels in ``labels`` ``[x, y, z]`` (left as given,
    ``x1 < x0``, for a label with none)."""
    nx, ny, nz = labels.shape
    nb = boxes.shape[0]
    for z in range(nz):
        for y in range(ny):
            for x in range(nx):
                v = labels[x, y, z]
                if v == 0 or v > nb:
                    continue
                k = v - 1
                if boxes[k, 3] < boxes[k, 0]:
                    boxes[k, 0], boxes[k, 1], boxes[k, 2] = x, y, z
                    boxes[k, 3], boxes[k, 4], boxes[k, 5] = x, y, z
                else:
                    boxes[k, 0], boxes[k, 3] = min(boxes[k, 0], x), max(boxes[k, 3], x)
                    boxes[k, 1], boxes[k, 4] = min(boxes[k, 1], y), max(boxes[k, 4], y)
                    boxes[k, 5] = z
                    boxes[k, 2] = min(boxes[k, 2], z)
