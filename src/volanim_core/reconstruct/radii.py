"""Sphere radii as the kernels compare them."""

from __future__ import annotations

import numpy as np

from volanim_core.reconstruct._plan_kernels import snapped_squares


def radius_squared(dt: np.ndarray) -> np.ndarray:
    """``dt**2``, snapped to the nearest integer when within 1e-9 (relative) of it."""
    dt = np.asarray(dt, np.float64)
    return snapped_squares(np.ascontiguousarray(dt.reshape(-1))).reshape(dt.shape)
