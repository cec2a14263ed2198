"""Selecting skeleton points: cube, lasso and the lasso's depth modes. Pure NumPy.

    cube:  |p - centre| <= size / 2 on every axis (voxel coordinates)
    lasso: the point's display position lies inside the drawn polygon, then by depth
        through  everything under the outline
        visible  only points no other shown point hides (a coarse depth buffer of the points)
        slab     only points within ``slab`` (world units along the view) of the nearest selected one
"""

from __future__ import annotations

import numpy as np
from skimage.measure import points_in_poly

DEPTH_MODES = ("through", "visible", "slab")


def in_cube(points: np.ndarray, centre, size: float) -> np.ndarray:
    """Boolean mask of points inside the axis-aligned cube (edges included)."""
    half = float(size) / 2.0
    return (np.abs(np.asarray(points, np.float64) - np.asarray(centre, np.float64)) <= half).all(axis=1)


def in_polygon(xy: np.ndarray, polygon) -> np.ndarray:
    """Boolean mask of 2-D points inside the polygon (closed automatically)."""
    polygon = np.asarray(polygon, np.float64)
    if len(polygon) < 3 or not len(xy):
        return np.zeros(len(xy), bool)
    return points_in_poly(np.asarray(xy, np.float64), polygon)


def visible_mask(xy: np.ndarray, depth: np.ndarray, *, cell: float = 3.0, tolerance: float = 0.0) -> np.ndarray:
    """Points not hidden behind others: the front-most point of each ``cell``-pixel cell is
    visible, and so is any point within ``tolerance`` (depth units) of it."""
    if not len(xy):
        return np.zeros(0, bool)
    ij = np.floor(np.asarray(xy) / cell).astype(np.int64)
    ij -= ij.min(axis=0)
    key = ij[:, 0] * (ij[:, 1].max() + 1) + ij[:, 1]
    front = np.full(int(key.max()) + 1, np.inf)
    np.minimum.at(front, key, depth)
    return depth <= front[key] + tolerance


def select_lasso(xy: np.ndarray, depth: np.ndarray, view_depth: np.ndarray, polygon, *, mode: str = "through",
                 slab: float = 10.0, cell: float = 3.0) -> np.ndarray:
    """Indices (into ``xy``) of the points a lasso selects.

    Parameters
    ----------
    xy, depth : display positions and normalised depth of the shown points
    view_depth : distance of each point along the viewing direction (world units)
    polygon : (M, 2) the lasso outline in display pixels
    mode : 'through', 'visible' or 'slab'
    slab : depth of the slab behind the nearest selected point (world units)
    """
    if mode not in DEPTH_MODES:
        raise ValueError(f"depth mode must be one of {', '.join(DEPTH_MODES)}, got {mode!r}")
    inside = in_polygon(xy, polygon)
    if mode == "visible":
        inside &= visible_mask(xy, depth, cell=cell)
    elif mode == "slab" and inside.any():
        nearest = view_depth[inside].min()
        inside &= view_depth <= nearest + float(slab)
    return np.flatnonzero(inside)
