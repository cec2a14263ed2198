"""Bilateral symmetry by the ``L_`` / ``R_`` naming convention (as Blender's Symmetrize).

Pure functions: names in, names out; positions mirrored across the plane
``x = plane_x`` and snapped to the nearest skeleton point on the other side.
"""

from __future__ import annotations

import numpy as np

SIDES = (("L_", "R_"), ("R_", "L_"), ("l_", "r_"), ("r_", "l_"), ("Left", "Right"), ("Right", "Left"))


def side(name: str) -> str | None:
    """'L' or 'R' for a sided name, None for a centre name."""
    for a, _ in SIDES:
        if name.startswith(a):
            return "L" if a.lower().startswith("l") else "R"
    return None


def mirror_name(name: str) -> str:
    """``L_ELBOW`` -> ``R_ELBOW`` (and back); centre names are their own mirror."""
    for a, b in SIDES:
        if name.startswith(a):
            return b + name[len(a):]
    return name


def mirror_point(p, plane_x: float) -> np.ndarray:
    p = np.array(p, np.float64)
    p[..., 0] = 2.0 * plane_x - p[..., 0]
    return p


def snap(points: np.ndarray, target) -> np.ndarray:
    """The skeleton point nearest to ``target`` (or ``target`` itself without points)."""
    if points is None or not len(points):
        return np.asarray(target, np.float64)
    d = ((points - np.asarray(target)) ** 2).sum(1)
    return points[int(np.argmin(d))].astype(np.float64)
