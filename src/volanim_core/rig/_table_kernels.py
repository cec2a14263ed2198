"""Numba kernels of the tables every posed frame reads (rig/ownership.py), made from the labels' runs.

    row_spans(first, x0, x1, value, ny, spans)    -> each bone's first and last x on each row
    bone_cells(first, x0, x1, value, shape, size, n_bones) -> each bone's cubes of ``size`` voxels a side
    busy_extents(first, x0, x1, ny, nz, nx)       -> the stretch of each row that holds body or touches it
    flagged_voxels(first, x0, x1, value, flags, bit, n_bones, ny) -> each bone's voxels whose flags have a bit

The runs (volanim_core/_run_kernels.runs ``by_value``, over the ``[z, y, x]`` view of the labels ``[x, y, z]``:
row ``z * ny + y``) are what ownership's specks found already (rig/specks.py). Why runs: the labels are the body's
box, mostly empty; a pass over every voxel of the frog's 27 M for each table cost 45 ms (cells) and 12 ms (spans)
of its ownership, which is to cost no more than its skeletonize (#84).
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True, inline="always")
def _counted_to_starts(count, starts):
    """``starts[l]``: the rows of labels 1..l, from ``count[l]`` (each label's rows, counted); ``count[l]`` then
    label l's first row, where the second pass writes it. Returns the rows in all."""
    for v in range(1, len(count)):
        starts[v] = starts[v - 1] + count[v]
    count[1:] = starts[:-1]
    return starts[-1]


@njit(cache=True, nogil=True)
def row_spans(first, x0, x1, value, ny, spans):
    """``spans[l - 1, y, z]`` = the first and last x of label l on row ``(y, z)`` (``spans`` filled with
    ``(1, 0)`` beforehand: none; labels above ``spans.shape[0]`` left out)."""
    nb = spans.shape[0]
    for row in range(len(first) - 1):
        z, y = row // ny, row % ny
        for r in range(first[row], first[row + 1]):
            v = value[r]
            if v == 0 or v > nb:
                continue
            s = spans[v - 1, y, z]
            if s[1] < s[0]:
                s[0] = x0[r]
            s[1] = x1[r]


@njit(cache=True, nogil=True)
def bone_cells(first, x0, x1, value, shape, size, n_bones):
    """Which ``size``-cubes of the labels ``[x, y, z]`` (``shape``) hold a voxel of each label:
    ``(starts (n_bones + 1,), cells (N, 3) int32)``, label l's cubes (their lower corner / size) at
    ``cells[starts[l - 1]:starts[l]]``, in z, y, x order. Two passes over the rows of cubes: count, then fill;
    ``seen[l, kx]`` holds the last row of cubes that found label l in cube kx (no clearing between rows)."""
    nx, ny, nz = shape
    cx, cy, cz = -(-nx // size), -(-ny // size), -(-nz // size)
    seen = np.full((n_bones + 1, cx), -1, np.int64)
    lo = np.empty(n_bones + 1, np.int64)
    hi = np.empty(n_bones + 1, np.int64)
    count = np.zeros(n_bones + 1, np.int64)
    starts = np.zeros(n_bones + 1, np.int64)
    cells = np.empty((0, 3), np.int32)
    for fill in range(2):
        if fill:
            cells = np.empty((_counted_to_starts(count, starts), 3), np.int32)
            seen[:] = -1
        for kz in range(cz):
            for ky in range(cy):
                block = kz * cy + ky + fill * cz * cy  # the second pass's blocks differ from the first's
                lo[:] = cx
                hi[:] = -1
                for z in range(kz * size, min(nz, kz * size + size)):
                    for y in range(ky * size, min(ny, ky * size + size)):
                        row = z * ny + y
                        for r in range(first[row], first[row + 1]):
                            v = value[r]
                            if v == 0 or v > n_bones:
                                continue
                            for kx in range(x0[r] // size, x1[r] // size + 1):
                                seen[v, kx] = block
                            lo[v] = min(lo[v], x0[r] // size)
                            hi[v] = max(hi[v], x1[r] // size)
                for v in range(1, n_bones + 1):
                    for kx in range(lo[v], hi[v] + 1):
                        if seen[v, kx] == block:
                            if fill:
                                c = count[v]
                                cells[c, 0], cells[c, 1], cells[c, 2] = kx, ky, kz
                            count[v] += 1
    return starts, cells


@njit(cache=True, nogil=True)
def busy_extents(first, x0, x1, ny, nz, nx):
    """``(nz, ny, 2)`` int64: the x range ``lo..hi`` (inclusive; lo > hi: none) of row ``(y, z)`` whose voxels have
    body among their 26 neighbours or are body: the runs of the row and its 8 neighbour rows (y and z each one
    apart), widened by one, inside ``0..nx - 1``. Beyond it a voxel and all its neighbours are outside."""
    ends = np.empty((nz, ny, 2), np.int64)  # each row's own runs' first and last x
    ends[..., 0], ends[..., 1] = nx, -1
    for z in range(nz):
        for y in range(ny):
            row = z * ny + y
            if first[row + 1] > first[row]:
                ends[z, y, 0], ends[z, y, 1] = x0[first[row]], x1[first[row + 1] - 1]
    out = np.empty((nz, ny, 2), np.int64)
    for z in range(nz):
        for y in range(ny):
            lo, hi = nx, -1
            for c in range(max(0, z - 1), min(nz, z + 2)):
                for b in range(max(0, y - 1), min(ny, y + 2)):
                    lo, hi = min(lo, ends[c, b, 0]), max(hi, ends[c, b, 1])
            out[z, y, 0], out[z, y, 1] = max(0, lo - 1), min(nx - 1, hi + 1)
    return out


@njit(cache=True, nogil=True)
def flagged_voxels(first, x0, x1, value, flags, bit, n_bones, ny):
    """Each label's voxels whose ``flags`` (``[x, y, z]``) have ``bit``: ``(starts (n_bones + 1,), voxels (N, 3)
    int32)``, label l's at ``voxels[starts[l - 1]:starts[l]]``, in z, y, x order. Read on the runs only, twice:
    count, then write (every voxel of the frog's box read twice: 17 ms)."""
    starts = np.zeros(n_bones + 1, np.int64)
    at = np.zeros(n_bones + 1, np.int64)
    voxels = np.empty((0, 3), np.int32)
    for fill in range(2):
        if fill:
            voxels = np.empty((_counted_to_starts(at, starts), 3), np.int32)
        for row in range(len(first) - 1):
            z, y = row // ny, row % ny
            for r in range(first[row], first[row + 1]):
                v = value[r]
                if v == 0 or v > n_bones:
                    continue
                for x in range(x0[r], x1[r] + 1):
                    if flags[x, y, z] & bit:
                        if fill:
                            voxels[at[v], 0], voxels[at[v], 1], voxels[at[v], 2] = x, y, z
                        at[v] += 1
    return starts, voxels
