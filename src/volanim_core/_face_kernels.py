"""numba kernels of :mod:`volanim_core.voxel_faces` (tested against a NumPy count in tests/core/render).

    row_extents       for each row: its first filled voxel and one past its last (the kernels below read inside)
    faces_per_slice   for each z slice of a range (threads take slices): its filled voxels' faces towards empty
                      ones (or the grid's edge), counted
    fill_faces        again, each face written at its slice's offset: 4 corners, the colour of its voxel (face
                      f is always points 4f..4f+3: voxel_faces numbers them, no kernel writes it)

The volume is read as its C-ordered ``[z, y, x]`` array (the studio's pictures are the transposes of their
``[x, y, z]`` views: x-runs are contiguous). ``nogil``: the live thread makes faces while the GUI thread draws.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

# each face's 4 corners as offsets from the voxel's centre, in (x, y, z), for the faces towards -x, +x, -y, +y,
# -z, +z; wound counter-clockwise seen from outside (the normal points from the filled voxel to the empty one)
CORNERS = 0.5 * np.array([
    [[-1, -1, -1], [-1, -1, 1], [-1, 1, 1], [-1, 1, -1]],  # -x
    [[1, -1, -1], [1, 1, -1], [1, 1, 1], [1, -1, 1]],      # +x
    [[-1, -1, -1], [1, -1, -1], [1, -1, 1], [-1, -1, 1]],  # -y
    [[-1, 1, -1], [-1, 1, 1], [1, 1, 1], [1, 1, -1]],      # +y
    [[-1, -1, -1], [-1, 1, -1], [1, 1, -1], [1, -1, -1]],  # -z
    [[-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]],      # +z
])


@njit(cache=True, inline="always")
def _empty_beside(vol, lo, hi, z, y, x):
    """Whether voxel (z, y, x) is empty or past the grid, reading it only inside its row's filled extent."""
    nz, ny, nx = vol.shape
    if z < 0 or z >= nz or y < 0 or y >= ny or x < lo[z, y] or x >= hi[z, y]:
        return True
    return vol[z, y, x] == 0


@njit(cache=True, inline="always")
def _open_sides(vol, lo, hi, z, y, x):
    """Bit d set: voxel (z, y, x)'s face d (CORNERS' order: -x, +x, -y, +y, -z, +z) meets an empty voxel. Both
    kernels ask it (written out: a table of steps made them 20 % slower)."""
    e = _empty_beside
    return (np.int64(e(vol, lo, hi, z, y, x - 1)) | np.int64(e(vol, lo, hi, z, y, x + 1)) << 1
            | np.int64(e(vol, lo, hi, z, y - 1, x)) << 2 | np.int64(e(vol, lo, hi, z, y + 1, x)) << 3
            | np.int64(e(vol, lo, hi, z - 1, y, x)) << 4 | np.int64(e(vol, lo, hi, z + 1, y, x)) << 5)


STRIDE = 16  # voxels row_extents tests at once: one OR of a vector's lanes, not a branch per voxel


@njit(cache=True, parallel=True, nogil=True)
def row_extents(vol, lo, hi):
    """``lo[z, y]``, ``hi[z, y]``: the first filled voxel of row (z, y) of ``vol [z, y, x]`` and one past its last
    (0, 0 for an empty row). The face kernels read only inside them: a body fills a few percent of its box, and
    a tight scan for the first and the last filled voxel is what reading the rest costs (#85: the mannequin's
    full-size faces, 19 ms on one thread, mostly spent on empty voxels' neighbour tests).
    The empty run is skipped :data:`STRIDE` voxels a step (an OR over them, which LLVM makes one vector test),
    then voxel by voxel: a live grid's rows are mostly empty, and a branch per voxel took 3-4 ms of the frog's
    and the mannequin's live pictures, a third of their faces."""
    nz, ny, nx = vol.shape
    for z in prange(nz):
        for y in range(ny):
            row = vol[z, y]
            a = 0
            while a + STRIDE <= nx:
                seen = 0
                for k in range(STRIDE):
                    seen |= row[a + k]
                if seen != 0:
                    break
                a += STRIDE
            while a < nx and row[a] == 0:
                a += 1
            b = nx
            while b - STRIDE >= a:
                seen = 0
                for k in range(STRIDE):
                    seen |= row[b - STRIDE + k]
                if seen != 0:
                    break
                b -= STRIDE
            while b > a and row[b - 1] == 0:
                b -= 1
            lo[z, y] = a if a < nx else 0
            hi[z, y] = b if a < nx else 0


@njit(cache=True, parallel=True, nogil=True)
def faces_per_slice(vol, lo, hi, z0, z1, counts):
    """``counts[z - z0]`` for the slices ``z0 <= z < z1``: the faces of slice z's filled voxels of ``vol [z, y, x]``
    that meet an empty voxel (``lo``, ``hi``: :func:`row_extents`). The slices around them are read as
    neighbours: a slab's faces with the slices beside it as they are."""
    nz, ny, nx = vol.shape
    for z in prange(z0, z1):
        n = 0
        for y in range(ny):
            for x in range(lo[z, y], hi[z, y]):
                if vol[z, y, x] != 0:
                    sides = _open_sides(vol, lo, hi, z, y, x)
                    for d in range(6):
                        n += (sides >> d) & 1
        counts[z - z0] = n


@njit(cache=True, parallel=True, nogil=True)
def fill_faces(vol, lo, hi, z0, z1, z_at, starts, corners, origin, spacing, table, points, rgb):
    """Each face of slice z (``z0 <= z < z1``, as :func:`faces_per_slice` counted them) written from
    ``starts[z - z0]``: ``points[4f:4f+4]`` its corners in world units (``origin + spacing * (voxel + corner)``,
    (x, y, z), where ``vol``'s slice z is the grid's slice ``z + z_at``), ``rgb[4f:4f+4]`` the colour
    ``table[value]`` of its filled voxel (RGB or RGBA, as the table's rows; past the table: its last row).
    ``lo``, ``hi``: :func:`row_extents`."""
    nz, ny, nx = vol.shape
    top = table.shape[0] - 1
    nch = rgb.shape[1]  # RGB, or RGBA (a transfer function's opacity)
    at = np.empty((6, 4, 3), np.float64)  # each corner's offset in world units (a voxel's own added below)
    for d in range(6):
        for k in range(4):
            for a in range(3):
                at[d, k, a] = origin[a] + spacing[a] * corners[d, k, a]
    for z in prange(z0, z1):
        f = starts[z - z0]
        for y in range(ny):
            for x in range(lo[z, y], hi[z, y]):
                v = vol[z, y, x]
                if v == 0:
                    continue
                sides = _open_sides(vol, lo, hi, z, y, x)
                if sides == 0:
                    continue
                row = min(np.int64(v), top)  # an index, not a view of the table: no reference counts a voxel
                wx, wy, wz = spacing[0] * x, spacing[1] * y, spacing[2] * (z + z_at)
                for d in range(6):
                    if not (sides >> d) & 1:
                        continue
                    p = 4 * f
                    for k in range(4):
                        points[p + k, 0] = at[d, k, 0] + wx
                        points[p + k, 1] = at[d, k, 1] + wy
                        points[p + k, 2] = at[d, k, 2] + wz
                        for ch in range(nch):
                            rgb[p + k, ch] = table[row, ch]
                    f += 1
