"""Label-coloured isosurfaces: the look of the studio's live preview.

Software OpenGL draws a surface far faster than it ray-casts a volume, so a
preview that must follow a slider is the boundary of the filled voxels, each
surface point coloured by the label of the voxel it came from.
"""

from __future__ import annotations

import numpy as np


def label_surface(volume: np.ndarray, origin, spacing, table: np.ndarray | None = None):
    """The surface around the non-zero voxels of ``volume`` (indexed ``[x, y, z]``).

    Parameters
    ----------
    volume : (X, Y, Z) ndarray of labels (0 = empty)
    origin, spacing : world position of voxel [0, 0, 0] and the voxel size
    table : (L, 3) uint8, optional
        Colour of label value v at row v (e.g. :func:`~volanim_core.render.colours.label_table`);
        without it the surface has no colours.

    Returns
    -------
    pyvista.PolyData, with point data ``rgb`` when ``table`` is given (possibly empty).
    """
    import pyvista as pv

    origin = np.asarray(origin, np.float64)
    spacing = np.asarray(spacing, np.float64)
    img = pv.ImageData(dimensions=volume.shape, origin=origin, spacing=spacing)
    img.point_data["values"] = (np.asarray(volume) > 0).astype(np.uint8).ravel(order="F")
    surf = img.contour([0.5], scalars="values", method="flying_edges")
    if surf.n_points and table is not None:
        # a surface point lies on a grid edge between a filled and an empty voxel: colour it by the
        # filled one (rounding picked the empty one half the time, speckling the surface with row 0)
        at = (np.asarray(surf.points) - origin) / spacing
        top = np.array(volume.shape) - 1
        lo = np.clip(np.floor(at).astype(np.int64), 0, top)
        hi = np.clip(np.ceil(at).astype(np.int64), 0, top)
        vol = np.asarray(volume)
        labels = np.maximum(vol[tuple(lo.T)], vol[tuple(hi.T)]).astype(np.int64)
        surf.point_data["rgb"] = table[np.clip(labels, 0, len(table) - 1)].astype(np.uint8)
    return surf


def flying_edges(box: np.ndarray, origin=(0, 0, 0), level: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """VTK flying edges on ``box`` (indexed ``[x, y, z]``): ``(V, 3)`` float32 vertices, ``(F, 3)`` int64 faces."""
    import pyvista as pv

    img = pv.ImageData(dimensions=box.shape, origin=tuple(float(v) for v in origin))
    img.point_data["m"] = np.asarray(box).ravel(order="F")
    surf = img.contour([level], scalars="m", method="flying_edges")
    faces = surf.faces.reshape(-1, 4)[:, 1:] if surf.n_cells else np.zeros((0, 3), np.int64)
    return np.asarray(surf.points, np.float32), faces.astype(np.int64)
