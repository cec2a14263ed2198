"""Deliberately simple NumPy references for the numba kernels (test oracles).

Slow and obvious on purpose: each follows FORMATS.md's words line by line.
"""

from __future__ import annotations

import itertools

import numpy as np


def chamfer_offsets_distance(dx, dy, dz):
    """3-4-5 chamfer distance of integer offsets: sort |d| so a >= b >= c, then 3a + b + c."""
    a = np.sort(np.abs(np.stack([dx, dy, dz])), axis=0)[::-1]
    return 3 * a[0] + a[1] + a[2]


def distance_transform(mask, metric="euclid"):
    """Brute force: min distance from each object voxel to any background voxel centre,
    the volume surrounded by a one-voxel ring of background."""
    m = np.pad(np.asarray(mask) != 0, 1)
    bg = np.argwhere(~m)
    out = np.zeros(m.shape, np.float64)
    for p in np.argwhere(m):
        d = bg - p
        if metric == "euclid":
            out[tuple(p)] = np.sqrt((d.astype(np.float64) ** 2).sum(1)).min()
        else:
            out[tuple(p)] = chamfer_offsets_distance(d[:, 0], d[:, 1], d[:, 2]).min()
    return out[1:-1, 1:-1, 1:-1]


def thinness(dt):
    """DT(p) minus the mean DT over its 26 neighbours (outside = 0), for every voxel."""
    p = np.pad(dt, 1)
    total = np.zeros_like(dt, dtype=np.float64)
    X, Y, Z = dt.shape
    for dx, dy, dz in itertools.product((-1, 0, 1), repeat=3):
        if dx == dy == dz == 0:
            continue
        total += p[1 + dx : 1 + dx + X, 1 + dy : 1 + dy + Y, 1 + dz : 1 + dz + Z]
    return dt - total / 26.0


def union_of_balls(points, radii, shape, metric="euclid"):
    """Voxels q with |q - p| < r for some (p, r): a plain loop over every ball."""
    out = np.zeros(shape, bool)
    grid = np.indices(shape)
    for p, r in zip(points, radii):
        d = grid - np.asarray(p).reshape(3, 1, 1, 1)
        if metric == "euclid":
            out |= (d**2).sum(0) < r * r - 1e-9 * r * r  # dt = sqrt(k): strictly inside
        else:
            out |= chamfer_offsets_distance(d[0], d[1], d[2]) < r
    return out
