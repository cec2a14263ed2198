"""Which bone owns each rest voxel of the body: the rig's ownership, made once and used by every posed frame.

    mask (the segmentation), connectivity (points on bones)
        --tube_profiles (limb_tubes.py), else the points' depth--> each bone's tube: radius at both joints
        --own_by_tubes (numba)--> labels [x, y, z]: 1 + the bone whose tube holds the voxel deepest
                                  relative to its radius (distance to the segment / the radius there)
        --DT of the mask at each bone's proximal joint--> ball radii (the body's depth at the joint)
        --> Ownership (labels cropped to the body, its origin, the bones, the balls)

Why tubes and not the points' attachments: the nearest-bone attachment gives the armpit to the arm
(its skeleton points lie a few voxels from the arm's segment and twenty from the spine's), and any rule
built on points inherits that. A voxel in the armpit lies outside the arm's own round tube and well
inside the torso's, so relative to each tube's radius the torso holds it deeper; the tube's radius is
measured from the limb's own middle (limb_tubes.tube_profiles), where no other limb touches it. A
voxel inside two tubes (a limb's end inside the torso) goes to the thinner one, which holds it
relatively deeper: the limb's own flesh moves with the limb, and the ball at the joint keeps the torso
whole where it leaves.

Every voxel of the mask gets an owner, so at the identity pose the posed body is the mask voxel for
voxel. The animator repaints ownership where the rule is wrong (the studio, ``volanim connect
--fix-lumps``): :meth:`Ownership.with_labels`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from volanim_core.geometry import IDENTITY, Geometry
from volanim_core.rig._ownership_kernels import label_boxes, own_by_tubes
from volanim_core.rig.connectivity import BoneSegment, Connectivity
from volanim_core.volume import tight_bounds


def label_dtype(n_bones: int):
    """Ownership's label dtype for a number of bones (0 is "no bone")."""
    return np.uint8 if n_bones < 255 else np.uint16


@dataclass(eq=False)
class Ownership:
    """The rest body's owners: ``labels[x, y, z]`` is 1 + the root-order index of the bone owning rest voxel
    ``origin + (x, y, z)``, 0 outside the body.

    ``ball_radii[b]``: the body's depth at bone b's proximal joint (the ball that closes the joint when it
    bends; 0: none). ``geometry``: the rest grid's place in physical space (the skeleton's).
    """

    labels: np.ndarray
    origin: tuple[int, int, int]
    bones: list[BoneSegment]
    ball_radii: np.ndarray
    geometry: Geometry = IDENTITY
    tubes: np.ndarray | None = None  # (B, 18): the tubes the rule used (_ownership_kernels.tube_distance)
    path: object = None  # the file it was read from or saved to (a .tskel names it)
    _boxes: np.ndarray | None = field(default=None, repr=False)

    def __post_init__(self):
        self.origin = tuple(int(v) for v in self.origin)
        self.ball_radii = np.asarray(self.ball_radii, np.float64).reshape(len(self.bones))
        if self.labels.ndim != 3:
            raise ValueError(f"ownership labels must be a 3-D volume [x, y, z], got shape {self.labels.shape}")
        if self.labels.dtype.kind != "u":
            raise ValueError(f"ownership labels must be unsigned integers, got {self.labels.dtype}")
        if self.tubes is None:  # no tubes (all zero: a tube that holds nothing): a bone carries what it owns
            self.tubes = np.zeros((len(self.bones), 18))
        self.tubes = np.ascontiguousarray(self.tubes, np.float64).reshape(len(self.bones), 18)

    @property
    def mask(self) -> np.ndarray:
        return self.labels != 0

    def boxes(self) -> np.ndarray:
        """``(B, 6)`` each bone's owned voxels' box ``x0 y0 z0 x1 y1 z1`` in rest voxels (x1 < x0: owns none)."""
        if self._boxes is None:
            self._boxes = owned_boxes(self.labels, len(self.bones), self.origin)
        return self._boxes

    def counts(self) -> np.ndarray:
        """Each bone's owned voxels."""
        return np.bincount(self.labels.ravel(), minlength=len(self.bones) + 1)[1:len(self.bones) + 1]

    def with_labels(self, labels: np.ndarray) -> Ownership:
        """The same rig with other owners (a repaint); the labels must cover the same body."""
        if labels.shape != self.labels.shape or not np.array_equal(labels != 0, self.labels != 0):
            raise ValueError("a repaint may change which bone owns a voxel, not which voxels are the body")
        return Ownership(labels, self.origin, self.bones, self.ball_radii, self.geometry, self.tubes)

    def volume(self, shape) -> np.ndarray:
        """The labels on the whole rest grid of ``shape`` (a label volume to draw or save)."""
        out = np.zeros(shape, self.labels.dtype, order="F")
        lo = np.asarray(self.origin)
        hi = np.minimum(lo + self.labels.shape, shape)
        out[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]] = self.labels[:hi[0] - lo[0], :hi[1] - lo[1], :hi[2] - lo[2]]
        return out


def owned_boxes(labels: np.ndarray, n_bones: int, origin=(0, 0, 0)) -> np.ndarray:
    """``(n_bones, 6)`` inclusive boxes of each label's voxels, shifted by ``origin`` (x1 < x0 for none)."""
    boxes = np.zeros((n_bones, 6), np.int64)
    boxes[:, :3] = 1
    label_boxes(labels, boxes)
    has = boxes[:, 3] >= boxes[:, 0]
    boxes[has] += np.tile(np.asarray(origin, np.int64), 2)
    return boxes


def tube_radii(conn: Connectivity, depth: np.ndarray, lo: np.ndarray) -> np.ndarray:
    """``(B, 2)``: each bone's tube radius at its proximal and distal joint, from its own points' fit
    (:func:`~volanim_core.rig.limb_tubes.tube_profiles`); a bone too short or too bare for a fit takes the
    median depth of its points, else the body's depth at its middle, else one voxel."""
    from volanim_core.rig.bones import BoneSkeleton
    from volanim_core.rig.limb_tubes import tube_profiles

    segments = np.array([np.concatenate([b.proximal, b.distal]) for b in conn.bones]).reshape(-1, 6)
    bones = _bone_skeleton(conn.bones) if len(conn.bones) else BoneSkeleton({}, [])
    tubes = tube_profiles(conn.points, conn.dt, bones, conn.bone) if len(conn) else \
        np.full((len(conn.bones), 2), np.nan)
    for k in range(len(conn.bones)):
        if np.isfinite(tubes[k]).all() and (tubes[k] > 0).all():
            continue
        mine = conn.dt[conn.bone == k]
        if len(mine):
            r = float(np.median(mine))
        else:
            mid = np.round((segments[k, :3] + segments[k, 3:]) / 2 - lo).astype(int)
            inside = (mid >= 0).all() and (mid < depth.shape).all()
            r = float(depth[tuple(mid)]) if inside else 0.0
        tubes[k] = max(r, 1.0)
    return np.maximum(tubes, 0.5)


def _bone_skeleton(segments: list[BoneSegment]):
    """A :class:`BoneSkeleton` of a ``.connect``'s segments (joints named by position)."""
    from volanim_core.rig.bones import Bone, BoneSkeleton

    joints, bones = {}, []
    for k, s in enumerate(segments):
        names = []
        for p in (s.proximal, s.distal):
            key = tuple(np.round(p, 6))
            joints.setdefault(key, (f"J{len(joints)}", tuple(float(v) for v in p)))
            names.append(joints[key][0])
        bones.append(Bone(names[0], names[1], s.name or f"B{k}"))
    return BoneSkeleton({name: p for name, p in joints.values()}, bones)


def ownership(mask: np.ndarray, conn: Connectivity, *, geometry: Geometry | None = None) -> Ownership:
    """Each voxel of ``mask`` (the rest body, ``[x, y, z]`` on the skeleton's grid) given to one bone of
    ``conn`` (module docstring). ``geometry``: the grid's (default: the connectivity's)."""
    import edt

    mask = np.asarray(mask) != 0
    if not len(conn.bones):
        raise ValueError("ownership needs at least one bone")
    b = tight_bounds(mask)
    if b is None:
        raise ValueError("ownership needs a body: the mask is empty")
    lo = np.asarray(b.lo)
    box = np.asfortranarray(mask[b.slices()])
    depth = edt.edt(np.pad(box, 1), black_border=True, parallel=0)[1:-1, 1:-1, 1:-1]
    radii = tube_radii(conn, depth, lo)
    a = np.array([s.proximal for s in conn.bones], np.float64)
    ab = np.array([s.distal - s.proximal for s in conn.bones], np.float64)
    labels = np.zeros(box.shape, label_dtype(len(conn.bones)), order="F")
    round_tubes = tube_rows(a, ab, radii, [None] * len(a))
    own_by_tubes(box, lo.astype(np.float64), round_tubes, labels)
    tubes = tube_rows(a, ab, radii, [cross_section(labels, lo, k, a[k], ab[k]) for k in range(len(a))])
    own_by_tubes(box, lo.astype(np.float64), tubes, labels)
    join_specks(labels, len(a))
    balls = np.array([_depth_at(depth, s.proximal - lo) for s in conn.bones])
    return Ownership(labels, tuple(lo), list(conn.bones), balls, geometry or conn.geometry, tubes)


def tube_rows(a: np.ndarray, ab: np.ndarray, radii: np.ndarray, sections: list) -> np.ndarray:
    """``(B, 18)`` tubes as :func:`~volanim_core.rig._ownership_kernels.tube_distance` reads them: each bone's
    segment, its taper (``radii`` at both joints, relative to the middle) and its cross-section (``sections[k]``:
    ``(axes (2, 3), semi-axes (2,))`` from :func:`cross_section`, None: round, of the middle's radius)."""
    rows = np.zeros((len(a), 18))
    for k in range(len(a)):
        length2 = float(ab[k] @ ab[k])
        mid = max(0.5 * (radii[k, 0] + radii[k, 1]), 0.5)
        u = ab[k] / np.sqrt(length2) if length2 > 0 else np.array([0.0, 0.0, 1.0])
        if sections[k] is None:
            e = _perpendiculars(u)
            semi = (mid, mid)
        else:
            e, semi = sections[k]
        rows[k, :3], rows[k, 3:6], rows[k, 6] = a[k], ab[k], 1.0 / length2 if length2 > 0 else 0.0
        rows[k, 7], rows[k, 8] = radii[k, 0] / mid, (radii[k, 1] - radii[k, 0]) / mid
        # the end caps: stretched along the axis as far as the section's larger semi-axis
        for i, (axis, r) in enumerate(((e[0], semi[0]), (e[1], semi[1]), (u, max(semi)))):
            rows[k, 9 + 3 * i:12 + 3 * i] = axis / r
    return rows


def _perpendiculars(u: np.ndarray) -> np.ndarray:
    e1 = np.cross(u, [1.0, 0.0, 0.0] if abs(u[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    return np.array([e1, np.cross(u, e1)])


def cross_section(labels: np.ndarray, lo: np.ndarray, k: int, a: np.ndarray, ab: np.ndarray):
    """Bone k's cross-section in the middle of its own voxels (0.3 < t < 0.7): the principal axes of their
    offsets from the segment and the semi-axes of the filled ellipse with those moments (2 sigma); None for
    a bone with too few voxels there or a flat one."""
    length2 = float(ab @ ab)
    if length2 <= 0:
        return None
    v = np.argwhere(labels == k + 1)
    if len(v) < 50:
        return None
    if len(v) > 200_000:
        v = v[:: len(v) // 200_000]
    p = v + lo - a
    t = p @ ab / length2
    p = p[(t > 0.3) & (t < 0.7)]
    t = t[(t > 0.3) & (t < 0.7)]
    if len(p) < 50:
        return None
    perp = p - np.outer(t, ab)
    w, e = np.linalg.eigh(np.cov(perp.T))
    axes = e[:, ::-1][:, :2].T  # the two largest
    semi = 2.0 * np.sqrt(np.maximum(w[::-1][:2], 0.0))
    if semi.min() < 0.5:
        return None
    return axes, semi


def join_specks(labels: np.ndarray, n_bones: int) -> int:
    """Give each piece of a bone's voxels cut off from its largest piece (26-connected) to the bone its
    neighbours mostly belong to, in place; returns the voxels moved. Why: the tube rule can leave a speck
    of one bone inside another's flesh (a voxel of spine in the shoulder), which then stays behind, alone,
    when the limb around it moves."""
    from scipy import ndimage

    moved = 0
    boxes = owned_boxes(labels, n_bones)
    ball = np.ones((3, 3, 3), bool)
    for k in range(n_bones):
        if boxes[k, 3] < boxes[k, 0]:
            continue
        sl = tuple(slice(max(0, int(boxes[k, i]) - 1), int(boxes[k, 3 + i]) + 2) for i in range(3))
        region = labels[sl]
        pieces, n = ndimage.label(region == k + 1, ball)
        if n < 2:
            continue
        sizes = np.bincount(pieces.ravel())
        sizes[0] = 0
        keep = int(sizes.argmax())
        for piece, where in enumerate(ndimage.find_objects(pieces), start=1):
            if piece == keep or where is None:
                continue
            grown = tuple(slice(max(0, w.start - 1), w.stop + 1) for w in where)
            mine = pieces[grown] == piece
            ring = ndimage.binary_dilation(mine, ball) & ~mine
            around = region[grown][ring]
            around = around[(around != 0) & (around != k + 1)]
            if len(around):
                region[grown][mine] = np.bincount(around).argmax()
                moved += int(mine.sum())
    return moved


def _depth_at(depth: np.ndarray, p: np.ndarray) -> float:
    """A radius whose ball around ``p`` lies inside the body: the depth at the nearest voxel less the way to it."""
    v = np.round(p).astype(int)
    if (v < 0).any() or (v >= depth.shape).any():
        return 0.0
    return max(0.0, float(depth[tuple(v)]) - float(np.linalg.norm(p - v)))
