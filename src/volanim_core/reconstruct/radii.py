"""Sphere radii as the kernels compare them."""

from __future__ import annotations

import numpy as np


def radius_squared(dt: np.ndarray) -> np.ndarray:
    """``dt**2``, snapped to the nearest integer when within 1e-9 (relative) of it."""
    r2 = np.asarray(dt, np.float64) ** 2
    near = np.rint(r2)
    return np.where(np.abs(r2 - near) <= 1e-9 * np.maximum(1.0, r2), near, r2)
