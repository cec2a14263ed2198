"""An isosurface of a box of values as plain arrays: VTK's flying edges, for code below ``render/``.

The skeleton's hull (``skeleton/hull.py``) needs a surface, not a renderer: this
module is the one place outside ``io/`` and ``render/`` that imports VTK (lazily,
inside the function), so the skeleton never imports the renderer.
"""

from __future__ import annotations

import numpy as np


def flying_edges(box: np.ndarray, origin=(0, 0, 0), level: float = 0.5, spacing: float = 1.0
                 ) -> tuple[np.ndarray, np.ndarray]:
    """VTK flying edges on ``box`` (indexed ``[x, y, z]``): ``(V, 3)`` float32 vertices, ``(F, 3)`` int64 faces."""
    import pyvista as pv

    img = pv.ImageData(dimensions=box.shape, origin=tuple(float(v) for v in origin), spacing=(spacing,) * 3)
    img.point_data["m"] = np.asarray(box).ravel(order="F")
    surf = img.contour([level], scalars="m", method="flying_edges")
    faces = surf.faces.reshape(-1, 4)[:, 1:] if surf.n_cells else np.zeros((0, 3), np.int64)
    return np.asarray(surf.points, np.float32), faces.astype(np.int64)
