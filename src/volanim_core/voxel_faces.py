"""The square faces between filled and empty voxels as plain arrays, each coloured by its filled voxel: the live
preview's surface (``render/surfaces.voxel_faces`` makes it a pyvista mesh). Below ``render/``, as
``isosurface.py`` is, so the warm-up can compile it.

    face_arrays: the volume [z, y, x] --_face_kernels.faces_per_slice--> faces a slice --> offsets
                 --_face_kernels.fill_faces--> points, faces, colours
"""

from __future__ import annotations

import numpy as np

from volanim_core._face_kernels import CORNERS, faces_per_slice, fill_faces


def face_arrays(volume: np.ndarray, origin, spacing, table: np.ndarray | None = None
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(points (4F, 3) float32, faces (F, 4) int64, rgb (4F, 3 or 4) uint8)``: each face between a non-zero voxel of
    ``volume`` (labels ``[x, y, z]``) and an empty one or the grid's edge, its corners in world units
    (``origin + spacing * voxel``) and their colour ``table[label]`` (the table's last row past its end; zeros
    without a table)."""
    vol = np.ascontiguousarray(np.asarray(volume).T)  # [z, y, x]: no copy for a picture's [x, y, z] view
    if vol.ndim != 3 or vol.dtype.kind not in "biu":
        raise ValueError(f"voxel faces take a label volume [x, y, z] of integers, got {vol.dtype} {vol.shape[::-1]}")
    vol = vol.view(np.uint8) if vol.dtype == bool else vol
    counts = np.empty(vol.shape[0], np.int64)
    faces_per_slice(vol, counts)
    starts = np.concatenate([[0], np.cumsum(counts)])
    n = int(starts[-1])
    # a user's transfer function gives RGBA rows: its opacity is kept (a faint bone stays faint while dragged)
    rows = np.zeros((1, 3), np.uint8) if table is None else np.ascontiguousarray(table, np.uint8)
    points = np.empty((4 * n, 3), np.float32)
    faces = np.empty((n, 4), np.int64)
    rgb = np.empty((4 * n, rows.shape[1]), np.uint8)
    fill_faces(vol, starts, CORNERS, np.asarray(origin, np.float64), np.asarray(spacing, np.float64), rows, points,
               faces, rgb)
    return points, faces, rgb
