"""World -> display projection and 2-D picking, with the camera's own matrices.

Pure NumPy on a ``(4, 4)`` composite projection matrix, so picking and
(later) lasso selection are testable without a window and identical at any
device pixel ratio: everything is in VTK display pixels (device pixels,
origin bottom-left).
"""

from __future__ import annotations

import numpy as np

CLICK_SLOP = 4.0  # display pixels: a press and release further apart is a drag (camera, lasso), not a click

def project(points: np.ndarray, matrix: np.ndarray, viewport: tuple[float, float, float, float]):
    """Display coordinates and depth of world points.

    Parameters
    ----------
    points : (N, 3) world coordinates
    matrix : (4, 4) composite projection (world -> clip), column-vector convention
    viewport : (x0, y0, width, height) in display pixels

    Returns
    -------
    xy : (N, 2) display pixels; depth : (N,) normalised device z (smaller is nearer)
    """
    p = np.asarray(points, np.float64)
    clip = p @ matrix[:3, :3].T + matrix[:3, 3]
    w = p @ matrix[3, :3] + matrix[3, 3]
    w = np.where(np.abs(w) < 1e-12, 1e-12, w)
    ndc = clip / w[:, None]
    x0, y0, width, height = viewport
    xy = np.empty((len(p), 2))
    xy[:, 0] = x0 + (ndc[:, 0] + 1.0) * 0.5 * width
    xy[:, 1] = y0 + (ndc[:, 1] + 1.0) * 0.5 * height
    return xy, ndc[:, 2]


def nearest_in_radius(xy: np.ndarray, depth: np.ndarray, click, radius: float) -> int | None:
    """Index of the front-most point within ``radius`` pixels of ``click``, or None."""
    if not len(xy):
        return None
    d2 = ((xy - np.asarray(click, np.float64)) ** 2).sum(1)
    near = np.flatnonzero((d2 <= radius * radius) & (depth >= -1.0) & (depth <= 1.0))
    if not len(near):
        return None
    return int(near[np.argmin(depth[near])])


def segment_distance_2d(click, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Pixel distance from ``click`` to each 2-D segment ``a[i]``-``b[i]``."""
    c = np.asarray(click, np.float64)
    ab = b - a
    t = np.clip(((c - a) * ab).sum(1) / np.maximum((ab * ab).sum(1), 1e-12), 0.0, 1.0)
    return np.linalg.norm(a + t[:, None] * ab - c, axis=1)
