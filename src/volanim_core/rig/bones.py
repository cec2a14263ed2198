"""The bone skeleton: named joints and bones in root order (``.bones``).

Bone i is "root node i" of the old skelselect. Bone Q is a child of bone P
when Q's proximal joint is P's distal joint; the bones form a forest.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from volanim_core.geometry import IDENTITY, Geometry
from volanim_core.limits import MAX_COORD


@dataclass(frozen=True)
class Bone:
    """A segment from joint ``proximal`` to joint ``distal`` (joint names)."""

    proximal: str
    distal: str
    name: str = ""

    @property
    def label(self) -> str:
        """The bone's name, or ``PROXIMAL-DISTAL`` when it has none."""
        return self.name or f"{self.proximal}-{self.distal}"


@dataclass(eq=False)
class BoneSkeleton:
    """Joints (name -> position) and bones in root order."""

    joints: dict[str, np.ndarray] = field(default_factory=dict)
    bones: list[Bone] = field(default_factory=list)
    geometry: Geometry = IDENTITY  # the voxel grid of the joints' coordinates (a .bones file's "# geometry:")

    def __post_init__(self):
        self.joints = {k: np.asarray(v, dtype=np.float64).reshape(3) for k, v in self.joints.items()}
        for name, p in self.joints.items():  # as read_bones refuses them: a joint at NaN or 1e308 is no joint
            if not (np.isfinite(p).all() and np.abs(p).max() <= MAX_COORD):
                raise ValueError(f"joint {name!r} is at {p.tolist()}: coordinates must be finite numbers "
                                 f"within {MAX_COORD:,} voxels")
        self.bones = list(self.bones)
        self.validate()

    def validate(self) -> None:
        """Raise ValueError when a bone names a missing joint or repeats."""
        seen = set()
        for i, b in enumerate(self.bones):
            for j in (b.proximal, b.distal):
                if j not in self.joints:
                    raise ValueError(f"bone {i} ({b.label}) names unknown joint {j!r}")
            if b.proximal == b.distal:
                raise ValueError(f"bone {i} ({b.label}) joins joint {b.proximal!r} to itself")
            key = (b.proximal, b.distal)
            if key in seen:
                raise ValueError(f"bone {b.label} appears twice")
            seen.add(key)
        cycle = bone_cycle(self.bones)
        if cycle:
            raise ValueError("the bones form a cycle (" + " -> ".join(self.bones[i].label for i in cycle)
                             + "); a bone skeleton must be a tree, each bone hanging from one parent")

    def __eq__(self, other) -> bool:
        return (
            isinstance(other, BoneSkeleton)
            and self.bones == other.bones
            and list(self.joints) == list(other.joints)
            and all(np.array_equal(self.joints[k], other.joints[k]) for k in self.joints)
        )

    def __len__(self) -> int:
        return len(self.bones)

    def on_grid(self, geometry: Geometry) -> BoneSkeleton:
        """These bones in the voxels of ``geometry`` (a skeleton's grid), through physical space.

        Bones that record no geometry (files from before it was recorded) are taken to be on that grid
        already, as they always were; bones drawn on another grid (another voxel size, a scan placed
        elsewhere, 3D Slicer's) land where they were drawn in the body, onto the identity grid too (a scan
        at origin 0 in 1 mm voxels records no line, and is a grid all the same: #63).
        """
        if self.geometry.is_identity or self.geometry == geometry:
            return self if geometry == self.geometry else BoneSkeleton(self.joints, self.bones, geometry)
        names = list(self.joints)
        where = geometry.to_index(self.geometry.to_physical(np.array([self.joints[n] for n in names])))
        return BoneSkeleton(dict(zip(names, np.round(where, 6))), self.bones, geometry)

    def on_cubes(self) -> BoneSkeleton:
        """These bones on cubes of their grid's smallest spacing (the grid ``skeletonize`` makes of the
        scan), where they are in the body. Rotations are taken in voxels, and on a grid of 1 x 1 x 2.5 mm
        voxels a rotation in voxels is a shear in the body: every frame is posed on cubes."""
        if self.geometry.is_isotropic:
            return self
        return self.on_grid(self.geometry.with_spacing((min(self.geometry.spacing),) * 3))

    def segment(self, i: int) -> tuple[np.ndarray, np.ndarray]:
        b = self.bones[i]
        return self.joints[b.proximal], self.joints[b.distal]

    def segments(self) -> np.ndarray:
        """``(B, 2, 3)`` array of proximal and distal joint positions."""
        if not self.bones:
            return np.zeros((0, 2, 3))
        return np.array([self.segment(i) for i in range(len(self.bones))])

    def parent(self, i: int) -> int | None:
        """Index of bone ``i``'s parent bone, or None for a top-level bone."""
        prox = self.bones[i].proximal
        for j, b in enumerate(self.bones):
            if b.distal == prox:
                return j
        return None

    def parents(self) -> list[int | None]:
        distal_of = {b.distal: j for j, b in enumerate(self.bones)}
        return [distal_of.get(b.proximal) for b in self.bones]

    def leaves(self) -> list[int]:
        """Indices of the bones no bone starts from (a chain's last: a hand, a foot, a tail's tip)."""
        starts = {b.proximal for b in self.bones}
        return [i for i, b in enumerate(self.bones) if b.distal not in starts]

    def index(self, label: str) -> int:
        for i, b in enumerate(self.bones):
            if label in (b.name, b.label):
                return i
        raise KeyError(f"no bone named {label!r}")


def bone_cycle(bones: list[Bone]) -> list[int]:
    """Bone indices of a parent cycle (A->B, B->A), or [] for a tree. Iterative: any depth.

    A bone's parent is the bone whose distal joint is its proximal joint.
    """
    distal_of = {b.distal: j for j, b in enumerate(bones)}
    parents = [distal_of.get(b.proximal) for b in bones]
    state = [0] * len(parents)  # 0 unseen, 1 on the current walk, 2 known to reach a root
    for start in range(len(parents)):
        walk, i = [], start
        while i is not None and state[i] == 0:
            state[i] = 1
            walk.append(i)
            i = parents[i]
        if i is not None and state[i] == 1:
            return walk[walk.index(i):]
        for j in walk:
            state[j] = 2
    return []
