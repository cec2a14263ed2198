"""Sphere radii as the kernels compare them."""

from __future__ import annotations

import numpy as np
from numba import njit


def radius_squared(dt: np.ndarray) -> np.ndarray:
    """``dt**2``, snapped to the nearest integer when within 1e-9 (relative) of it."""
    dt = np.asarray(dt, np.float64)
    return _snapped_squares(np.ascontiguousarray(dt.reshape(-1))).reshape(dt.shape)


@njit(cache=True)
def _snapped_squares(dt):
    # one pass: the NumPy expression made five temporaries the size of the frog's 137 k radii
    out = np.empty(len(dt))
    for i in range(len(dt)):
        r2 = dt[i] * dt[i]
        near = np.rint(r2)
        out[i] = near if abs(r2 - near) <= 1e-9 * max(1.0, r2) else r2
    return out
