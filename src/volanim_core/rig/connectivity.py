"""Skeleton points attached to bones, and frames of bone matrices.

One flat layout serves ``.connect``, ``.trans`` and ``.tskel``::

    bones[b]          BoneSegment(proximal xyz, distal xyz, name)   b in root order
    points[i], dt[i], thinness[i], bone[i]                          i = point
    matrices[b]       4x4, row-vector convention: [x y z 1] @ M     (frames only)

Flat arrays with a bone index (rather than a list per bone) are what the numba
kernels want and make "move point i to bone b" a single assignment.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from volanim_core.geometry import IDENTITY, Geometry
from volanim_core.limits import shaped, voxel_points
from volanim_core.rig.skinning import RIGID, Joints, Skin, cached_skin
from volanim_core.skeleton.points import check_metric


def close_floats(a, b, atol: float) -> bool:
    """``np.allclose(a, b, rtol=1e-5, atol=atol)`` for short sequences of floats, without NumPy's overhead
    (a NaN is close to nothing)."""
    return all(abs(x - y) <= atol + 1e-5 * abs(y) for x, y in zip(a, b, strict=True))


@dataclass(eq=False)
class BoneSegment:
    """A bone as ``Root:`` lines name it: joint coordinates and an optional name."""

    proximal: np.ndarray
    distal: np.ndarray
    name: str = ""

    def __post_init__(self):
        whose = f"bone {self.name}'s" if self.name else "a bone's"
        self.proximal = shaped(self.proximal, (3,), f"{whose} proximal joint")
        self.distal = shaped(self.distal, (3,), f"{whose} distal joint")

    def __eq__(self, other) -> bool:
        return (
            isinstance(other, BoneSegment)
            and self.name == other.name
            and np.array_equal(self.proximal, other.proximal)
            and np.array_equal(self.distal, other.distal)
        )

    def same_segment(self, other: BoneSegment, tol: float = 1e-6) -> bool:
        """Both joints within ``np.allclose(self, other, atol=tol)``, in plain floats: two ``allclose`` per bone
        were a sixth of ``volanim scan``'s time over a 1064-frame clip (#65)."""
        return close_floats((*self.proximal.tolist(), *self.distal.tolist()),
                            (*other.proximal.tolist(), *other.distal.tolist()), tol)

    @property
    def label(self) -> str:
        p = " ".join(f"{v:g}" for v in self.proximal)
        d = " ".join(f"{v:g}" for v in self.distal)
        return self.name or f"({p})-({d})"


def _points_fields(points, dt, thinness, bone):
    points = voxel_points(points)
    n = len(points)
    dt = shaped(dt, (n,), f"dt (one radius for each of the {n:,} points)")
    thinness = np.full(n, np.nan) if thinness is None else thinness
    thinness = shaped(thinness, (n,), f"thinness (one for each of the {n:,} points)")
    bone = shaped(bone, (n,), f"bone (one bone index for each of the {n:,} points)", np.int32)
    return points, dt, thinness, bone


@dataclass(eq=False)
class Connectivity:
    """Contents of a ``.connect`` file.

    ``bone[i]`` is the root-order index of point i's bone (always >= 0: points
    attached to no bone are not part of a ``.connect``).
    """

    bones: list[BoneSegment]
    points: np.ndarray
    dt: np.ndarray
    thinness: np.ndarray | None
    bone: np.ndarray
    metric: str = "euclid"
    thinness_threshold: float | None = None
    geometry: Geometry = IDENTITY  # the voxel grid of the coordinates (volanim_core.geometry)
    joints: Joints = RIGID  # how bones meet: rigid, or smooth with a blend width (rig/skinning.py)
    #: which bone owns each rest voxel (rig/ownership.py), when the rig has one: rigid frames posed from this
    #: connectivity carry it, and reconstruct() then moves the voxels themselves (reconstruct/owned.py)
    ownership = None

    def __post_init__(self):
        self.points, self.dt, self.thinness, self.bone = _points_fields(
            self.points, self.dt, self.thinness, self.bone
        )
        check_metric(self.metric)
        if len(self.bone) and (self.bone.min() < 0 or self.bone.max() >= len(self.bones)):
            i = int(np.flatnonzero((self.bone < 0) | (self.bone >= len(self.bones)))[0])
            raise ValueError(f"bone: point {i}'s bone index {int(self.bone[i])} is not one of the "
                             f"{len(self.bones)} bones (0 to {len(self.bones) - 1}, root order)")
        self._skin: Skin | None = None

    @property
    def skin(self) -> Skin:
        """The blend weights of smooth joints, made from the points on first use and kept with them
        (every frame posed from this connectivity shares them; rig/skinning.py)."""
        if self._skin is None:
            self._skin = cached_skin(self)
        return self._skin

    def __len__(self) -> int:
        return len(self.points)

    def __eq__(self, other) -> bool:
        return (
            type(other) is type(self)
            and self.bones == other.bones
            and self.metric == other.metric
            and np.array_equal(self.points, other.points)
            and np.array_equal(self.dt, other.dt)
            and np.array_equal(self.thinness, other.thinness, equal_nan=True)
            and np.array_equal(self.bone, other.bone)
            and self.joints == other.joints
        )

    def take(self, order: np.ndarray) -> Connectivity:
        """A copy holding the points in ``order`` (a permutation or a subset)."""
        return Connectivity(self.bones, self.points[order], self.dt[order], self.thinness[order],
                            self.bone[order], self.metric, self.thinness_threshold, self.geometry, self.joints)

    def posed(self, matrices, joints: Joints | None = None) -> Tskel:
        """A frame of these points: one matrix per bone, the joints of the connectivity (or ``joints``)."""
        joints = self.joints if joints is None else joints
        skin = self.skin if joints == self.joints and joints.smooth else None
        t = Tskel(self.bones, matrices, self.points, self.dt, self.thinness, self.bone, self.metric,
                  self.geometry, joints=joints, skin=skin)
        t.ownership = self.ownership
        t._posed_from = self  # its connectivity, while the frame's joints and ownership are still these
        return t

    def with_ownership(self, ownership) -> Connectivity:
        """The same points with a rig's ownership (None: without; its bones must be these)."""
        if ownership is not None and len(ownership.bones) != len(self.bones):
            raise ValueError(f"the ownership has {len(ownership.bones)} bones, the connectivity {len(self.bones)}")
        c = self.take(np.arange(len(self)))
        c.ownership = ownership
        return c

    def with_joints(self, joints: Joints) -> Connectivity:
        """The same points with other joints."""
        c = Connectivity(self.bones, self.points, self.dt, self.thinness, self.bone, self.metric,
                         self.thinness_threshold, self.geometry, joints)
        c.ownership = self.ownership
        return c

    def is_grouped(self) -> bool:
        """Whether points are grouped by bone in root order, as files list them."""
        return len(self) < 2 or bool(np.all(self.bone[:-1] <= self.bone[1:]))

    def grouped(self) -> Connectivity:
        """A copy with points grouped by bone in root order (stable), as files list them."""
        return self.take(np.argsort(self.bone, kind="stable"))


def _check_matrices(matrices, bones):
    m = np.asarray(matrices, dtype=np.float64)
    if m.shape == (4, 4) or m.size == 0:  # one bone's matrix alone; no bones, no matrices
        m = m.reshape(-1, 4, 4)
    m = shaped(m, (len(bones), 4, 4), f"matrices (one 4 x 4 for each of the {len(bones)} bones)",
               hint="each maps [x y z 1] @ M, so a 3 x 4 affine needs the column 0 0 0 1 added")
    bad = ~np.isfinite(m).all(axis=(1, 2))
    if bad.any():  # as the files' readers refuse them: a NaN frame reconstructs to nothing
        b = int(np.argmax(bad))
        raise ValueError(f"bone {b} ({bones[b].label}): its matrix holds NaN or infinite numbers")
    return m


@dataclass(eq=False)
class Trans:
    """Contents of a ``.trans`` file: one 4x4 matrix per bone, root order, in the voxels of ``geometry``
    (its ``# geometry:`` line; none: the grid of whatever file it is paired with, as the seed's were)."""

    bones: list[BoneSegment]
    matrices: np.ndarray
    geometry: Geometry = IDENTITY

    def __post_init__(self):
        self.matrices = _check_matrices(self.matrices, self.bones)

    def __eq__(self, other) -> bool:
        return (
            isinstance(other, Trans)
            and self.bones == other.bones
            and np.array_equal(self.matrices, other.matrices)
            and self.geometry == other.geometry
        )

    def on_grid(self, geometry: Geometry) -> Trans:
        """This frame in the voxels of ``geometry`` (a ``.connect``'s grid), through physical space.

        A frame posed on one grid and a rig skeletonized on another (a scan of 1 x 1 x 2.5 mm voxels
        and the 1 mm cubes skeletonize resampled it to) are one frame: the roots go where they are in
        the body, each matrix is conjugated by the map between the grids (``A M A^-1``, row vectors).
        Between cube grids that is a similarity, so a rotation stays a rotation. A frame recording no
        grid is taken as on the other, as :meth:`~volanim_core.rig.bones.BoneSkeleton.on_grid` does; the identity
        grid (no line)
        is a grid like any other to a frame that records one.
        """
        if self.geometry.is_identity or self.geometry == geometry:
            return self if geometry == self.geometry else Trans(self.bones, self.matrices, geometry)
        a = geometry.index_map(self.geometry)  # [i j k 1] @ a: our voxels -> theirs, then M, then back

        def here(p):
            return np.round(geometry.to_index(self.geometry.to_physical(p[None]))[0], 6)

        bones = [BoneSegment(here(b.proximal), here(b.distal), b.name) for b in self.bones]
        return Trans(bones, a[None] @ self.matrices @ np.linalg.inv(a)[None], geometry)


class Tskel(Connectivity):
    """Contents of a ``.tskel`` file: a connectivity plus one matrix per bone (root order).

    ``Tskel(bones, matrices, points, dt, thinness, bone, metric, geometry)``; a matrix maps
    rest voxel coordinates to posed ones, ``[x y z 1] @ M``, both in the voxels of ``geometry``.
    """

    def __init__(self, bones, matrices, points, dt, thinness, bone, metric: str = "euclid",
                 geometry: Geometry = IDENTITY, *, joints: Joints = RIGID, skin: Skin | None = None):
        super().__init__(bones, points, dt, thinness, bone, metric, None, geometry, joints)
        self.matrices = _check_matrices(matrices, self.bones)
        self._skin = skin

    def with_joints(self, joints: Joints) -> Tskel:
        return self.connectivity.with_joints(joints).posed(self.matrices)

    def with_radii(self, dt: np.ndarray) -> Tskel:
        """The same frame (and skin) with other radii: the ones a pose grows it with (rig/skinning.posed_radii)."""
        return Tskel(self.bones, self.matrices, self.points, dt, self.thinness, self.bone, self.metric,
                     self.geometry, joints=self.joints, skin=self._skin)

    def __eq__(self, other) -> bool:
        return super().__eq__(other) and np.array_equal(self.matrices, other.matrices)

    def __repr__(self) -> str:
        return f"Tskel({len(self.bones)} bones, {len(self)} points, metric={self.metric!r})"

    def take(self, order: np.ndarray) -> Tskel:
        skin = self.skin.take(order, len(self)) if self.joints.smooth else None
        return Tskel(self.bones, self.matrices, self.points[order], self.dt[order], self.thinness[order],
                     self.bone[order], self.metric, self.geometry, joints=self.joints, skin=skin)

    @property
    def connectivity(self) -> Connectivity:
        """The frame's points as a connectivity: the one it was posed from when the frame still has its joints and
        ownership (a drag's pictures then share one object, whose ownership is looked up once, #85)."""
        source = getattr(self, "_posed_from", None)
        if source is not None and source.joints == self.joints and source.ownership is self.ownership:
            return source
        c = Connectivity(self.bones, self.points, self.dt, self.thinness, self.bone, self.metric,
                         geometry=self.geometry, joints=self.joints)
        c.ownership = self.ownership
        return c
