"""The skeleton cloud: points with a distance transform and a thinness each.

A :class:`Skeleton` is what ``.skel`` and ``.mskel`` files hold. It is kept
sorted by decreasing thinness (stable), so "the skeleton at thinness t" is the
prefix ``[:skel.count_at(t)]`` -- the studio's slider and every tool rely on it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from volanim_core.geometry import IDENTITY, Geometry
from volanim_core.limits import voxel_points

METRICS = ("euclid", "345")


def check_metric(metric: str) -> str:
    if metric not in METRICS:
        raise ValueError(f"metric must be 'euclid' or '345', got {metric!r}")
    return metric


@dataclass(eq=False)
class Skeleton:
    """Skeleton points of a volume.

    Attributes
    ----------
    points : (N, 3) ndarray of int32
        Voxel coordinates ``x, y, z``.
    dt : (N,) ndarray of float64
        Distance transform at each point (sphere radius), in ``metric`` units.
    thinness : (N,) ndarray of float64
        Thinness of each point; NaN when unknown (a ``.skel`` file).
    metric : {'euclid', '345'}
    geometry : Geometry
        Where the voxel grid of ``points`` is in physical space (the identity for a file
        that records none); ``dt`` is in its voxels, which are cubes (``spacing`` isotropic)
        whenever the skeleton was made by :func:`~volanim_core.skeleton.skeletonize`.
    """

    points: np.ndarray
    dt: np.ndarray
    thinness: np.ndarray
    metric: str = "euclid"
    geometry: Geometry = IDENTITY

    def __post_init__(self):
        self.points = voxel_points(self.points)
        n = len(self.points)
        self.dt = np.ascontiguousarray(self.dt, dtype=np.float64).reshape(n)
        if self.thinness is None:
            self.thinness = np.full(n, np.nan)
        self.thinness = np.ascontiguousarray(self.thinness, dtype=np.float64).reshape(n)
        check_metric(self.metric)

    def __len__(self) -> int:
        return len(self.points)

    def __eq__(self, other) -> bool:
        return (
            isinstance(other, Skeleton)
            and self.metric == other.metric
            and np.array_equal(self.points, other.points)
            and np.array_equal(self.dt, other.dt)
            and np.array_equal(self.thinness, other.thinness, equal_nan=True)
        )

    def sorted(self) -> Skeleton:
        """A copy sorted by decreasing thinness (stable; NaN last)."""
        key = np.where(np.isnan(self.thinness), -np.inf, self.thinness)
        order = np.argsort(-key, kind="stable")
        return Skeleton(self.points[order], self.dt[order], self.thinness[order], self.metric, self.geometry)

    def is_sorted(self) -> bool:
        key = np.where(np.isnan(self.thinness), -np.inf, self.thinness)
        return bool(np.all(key[:-1] >= key[1:]))

    @property
    def single_resolution(self) -> bool:
        """No thinness known (a ``.skel``): the points are one skeleton, not a family of them."""
        return len(self) > 0 and bool(np.isnan(self.thinness).all())

    def one_level(self, thinness: float = 0.0) -> Skeleton:
        """A ``.skel``'s points given one thinness, so a tool that chooses by thinness (the studio's slider)
        shows them all; a skeleton with thinness is returned as it is."""
        if not self.single_resolution:
            return self
        return Skeleton(self.points, self.dt, np.full(len(self), float(thinness)), self.metric, self.geometry)

    def count_at(self, thinness: float) -> int:
        """Number of points with thinness >= ``thinness`` (the sorted prefix length)."""
        # Sorted decreasing, so search the negated (increasing) array.
        return int(np.searchsorted(-self.thinness, -thinness, side="right"))

    def at(self, thinness: float) -> Skeleton:
        """The skeleton at ``thinness``: the points with thinness >= it."""
        n = self.count_at(thinness)
        return Skeleton(self.points[:n], self.dt[:n], self.thinness[:n], self.metric, self.geometry)


#: voxel_keys packs coordinates within this distance of the origin (21 bits each, signed)
KEY_REACH = 1 << 20


def voxel_keys(vox: np.ndarray) -> np.ndarray:
    """One int64 per voxel (integer coordinates within +-``KEY_REACH`` of the origin): a set of voxels
    compared, sorted or searched as plain integers."""
    v = np.asarray(vox, np.int64) + KEY_REACH
    return (v[:, 0] << 42) | (v[:, 1] << 21) | v[:, 2]
