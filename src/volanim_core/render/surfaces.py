"""Label-coloured surfaces of voxels: the render's surface style and the studio's live preview.

Software OpenGL draws a surface far faster than it ray-casts a volume, so a
preview that must follow a slider is the boundary of the filled voxels, each
surface point coloured by the label of the voxel it came from.

    label_surface   flying edges at 0.5 (VTK): the rounded look of a movie's surface style
    voxel_faces     the square faces between filled and empty voxels (numba, ../voxel_faces.py): the live
                    preview's, a quarter of label_surface's time (the frog's half-size body: 39 -> ~10 ms),
                    each face the colour of its voxel with no lookup of which voxel a point came from
"""

from __future__ import annotations

import numpy as np


def label_surface(volume: np.ndarray, origin, spacing, table: np.ndarray | None = None):
    """The surface around the non-zero voxels of ``volume`` (indexed ``[x, y, z]``).

    Parameters
    ----------
    volume : (X, Y, Z) ndarray of labels (0 = empty), or (X, Y, Z, 3) uint8 colour (black = empty),
        whose surface is coloured by its voxels (``table`` is not used)
    origin, spacing : world position of voxel [0, 0, 0] and the voxel size
    table : (L, 3) uint8, optional
        Colour of label value v at row v (e.g. :func:`~volanim_core.render.bone_colours.label_table`);
        without it the surface has no colours.

    Returns
    -------
    pyvista.PolyData, with point data ``rgb`` when ``table`` is given (possibly empty).
    """
    import pyvista as pv

    origin = np.asarray(origin, np.float64)
    spacing = np.asarray(spacing, np.float64)
    volume = np.asarray(volume)
    colour = volume.ndim == 4
    img = pv.ImageData(dimensions=volume.shape[:3], origin=origin, spacing=spacing)
    filled = volume.any(axis=3) if colour else volume > 0
    img.point_data["values"] = filled.astype(np.uint8).ravel(order="F")
    surf = img.contour([0.5], scalars="values", method="flying_edges")
    if surf.n_points and (table is not None or colour):
        values = filled_voxel_values(volume, (np.asarray(surf.points) - origin) / spacing)
        surf.point_data["rgb"] = values if colour else table[np.clip(values.astype(np.int64), 0, len(table) - 1)]
    return surf


def filled_voxel_values(volume: np.ndarray, at: np.ndarray) -> np.ndarray:
    """The value (label or RGB) of the filled voxel each surface point came from.

    A point at voxel coordinates ``at`` lies on a grid edge between a filled and an empty voxel:
    of the voxels at its floor and ceiling, the filled one (rounding picked the empty one half the
    time, speckling the surface with the background).
    """
    top = np.array(volume.shape[:3]) - 1
    lo = volume[tuple(np.clip(np.floor(at).astype(np.int64), 0, top).T)]
    hi = volume[tuple(np.clip(np.ceil(at).astype(np.int64), 0, top).T)]
    if volume.ndim == 4:
        return np.where(hi.any(axis=1, keepdims=True), hi, lo).astype(np.uint8)
    return np.maximum(lo, hi)


def voxel_faces(volume: np.ndarray, origin, spacing, table: np.ndarray | None = None):
    """The faces between the non-zero voxels of ``volume`` (labels, indexed ``[x, y, z]``) and empty ones or the
    grid's edge: one square per face, its 4 corners at the voxels' common boundary, in world units
    (``origin + spacing * voxel``), coloured (point data ``rgb``) by its filled voxel's row of ``table``
    (values past the table: its last row). Without ``table``: no colours.

    A closed surface of the filled voxels, as :func:`label_surface`'s at iso 0.5 is, but with the voxels'
    corners rather than cut ones: it is what the voxels are, and it is made in one pass (threads over slices).
    """
    from volanim_core.voxel_faces import face_arrays

    points, faces, rgb = face_arrays(volume, origin, spacing, table)
    return faces_mesh(points, faces, None if table is None else rgb)


def faces_mesh(points: np.ndarray, faces: np.ndarray, rgb: np.ndarray | None = None):
    """The pyvista mesh of :func:`~volanim_core.voxel_faces.face_arrays`'s arrays (``rgb`` None: no colours)."""
    import pyvista as pv

    mesh = pv.PolyData.from_regular_faces(points, faces) if len(faces) else pv.PolyData()
    if len(faces) and rgb is not None:
        mesh.point_data["rgb"] = rgb
    return mesh
