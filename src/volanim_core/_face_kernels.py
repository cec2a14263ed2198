"""numba kernels of :mod:`volanim_core.voxel_faces` (tested against a NumPy count in tests/core/render).

    faces_per_slice   for each z slice (threads take slices): its filled voxels' faces towards empty ones
                      (or the grid's edge), counted
    fill_faces        again, each face written at its slice's offset: 4 corners, the colour of its voxel

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
def _empty(vol, z, y, x):
    nz, ny, nx = vol.shape
    return z < 0 or z >= nz or y < 0 or y >= ny or x < 0 or x >= nx or vol[z, y, x] == 0


@njit(cache=True, parallel=True, nogil=True)
def faces_per_slice(vol, counts):
    """``counts[z]``: the faces of slice z's filled voxels of ``vol [z, y, x]`` that meet an empty voxel."""
    nz, ny, nx = vol.shape
    for z in prange(nz):
        n = 0
        for y in range(ny):
            for x in range(nx):
                if vol[z, y, x] != 0:
                    n += (_empty(vol, z, y, x - 1) + _empty(vol, z, y, x + 1) + _empty(vol, z, y - 1, x)
                          + _empty(vol, z, y + 1, x) + _empty(vol, z - 1, y, x) + _empty(vol, z + 1, y, x))
        counts[z] = n


@njit(cache=True, parallel=True, nogil=True)
def fill_faces(vol, starts, corners, origin, spacing, table, points, faces, rgb):
    """Each face of slice z written from ``starts[z]``: ``points[4f:4f+4]`` its corners in world units
    (``origin + spacing * (voxel + corner)``, (x, y, z)), ``faces[f]`` their indices, ``rgb[4f:4f+4]`` the
    colour ``table[value]`` of its filled voxel (RGB or RGBA, as the table's rows; past the table: its last row)."""
    nz, ny, nx = vol.shape
    top = table.shape[0] - 1
    for z in prange(nz):
        f = starts[z]
        for y in range(ny):
            for x in range(nx):
                v = vol[z, y, x]
                if v == 0:
                    continue
                c = table[min(np.int64(v), top)]
                for d in range(6):
                    dx = -1 if d == 0 else (1 if d == 1 else 0)
                    dy = -1 if d == 2 else (1 if d == 3 else 0)
                    dz = -1 if d == 4 else (1 if d == 5 else 0)
                    if not _empty(vol, z + dz, y + dy, x + dx):
                        continue
                    for k in range(4):
                        p = 4 * f + k
                        points[p, 0] = origin[0] + spacing[0] * (x + corners[d, k, 0])
                        points[p, 1] = origin[1] + spacing[1] * (y + corners[d, k, 1])
                        points[p, 2] = origin[2] + spacing[2] * (z + corners[d, k, 2])
                        faces[f, k] = p
                        for ch in range(rgb.shape[1]):  # RGB, or RGBA (a transfer function's opacity)
                            rgb[p, ch] = c[ch]
                    f += 1
