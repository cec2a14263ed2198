"""numba kernel for the curve skeleton: the union of a skeleton's balls painted on a coarse grid."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)  # run by the studio's worker: the window draws meanwhile
def paint_balls(centres, radii, out):
    """Set every voxel of ``out`` whose centre lies in a ball (``centres`` and ``radii`` in ``out``'s voxels)."""
    nx, ny, nz = out.shape
    for i in range(len(radii)):
        cx, cy, cz, r = centres[i, 0], centres[i, 1], centres[i, 2], radii[i]
        r2 = r * r
        x0, x1 = max(0, int(np.ceil(cx - r))), min(nx - 1, int(np.floor(cx + r)))
        y0, y1 = max(0, int(np.ceil(cy - r))), min(ny - 1, int(np.floor(cy + r)))
        z0, z1 = max(0, int(np.ceil(cz - r))), min(nz - 1, int(np.floor(cz + r)))
        for x in range(x0, x1 + 1):
            dx2 = (x - cx) * (x - cx)
            for y in range(y0, y1 + 1):
                dxy2 = dx2 + (y - cy) * (y - cy)
                if dxy2 > r2:
                    continue
                for z in range(z0, z1 + 1):
                    if dxy2 + (z - cz) * (z - cz) <= r2:
                        out[x, y, z] = True
