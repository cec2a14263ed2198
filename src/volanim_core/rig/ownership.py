"""Which bone owns each rest voxel of the body: the rig's ownership, made once and used by every posed frame.

    mask (the segmentation), connectivity (points on bones)
        --tube_profiles (limb_tubes.py), else the points' depth--> each bone's tube: radius at both joints
        --own_by_tubes (numba)--> labels [x, y, z]: 1 + the bone whose tube holds the voxel deepest, in voxels
                                  below its surface (tube_depth: the tube's elliptic, tapered section)
        --DT of the mask at each bone's proximal joint--> ball radii (the body's depth at the joint)
        --> Ownership (labels cropped to the body, its origin, the bones, the balls)

Why tubes and not the points' attachments: the nearest-bone attachment gives the armpit to the arm (its skeleton
points lie a few voxels from the arm's segment and twenty from the spine's), and any rule built on points inherits
that. A voxel in the armpit lies outside the arm's own round tube and well inside the torso's, so the torso holds it
deeper; the tube's radius is measured from the limb's own middle (limb_tubes.tube_profiles), where no other limb
touches it. Where two tubes overlap (a limb's end inside the torso) the voxel goes to the one whose surface is
farther, as the mannequin's true parts are made: a rule relative to each tube's size gave the thin thigh a third of
the pelvis it overlaps, which it then carried off at every step of the walk clip as a lump of 2,200 voxels (#84; the
absolute rule: none, and the frog's leaf poses 3/6 and 3/6 healthy where they were 2/6 and 1/6). A tube's round end
past a joint yields (holds only what no other tube holds) where the body there is another bone's: behind a bone's
proximal joint when a bone ends there, past its distal joint when one bone goes on (_yields). Without it the thick
parent's round end took the base of a thin leaf (the rabbit's and Spot's leaf bent 90 degrees tore off). What no tube
holds goes to the nearest tube's surface, but a round end that yields keeps what it holds from a tube more than FAR
(30) of its sizes away: the frog's snout-tip leaf, one voxel wide, took the lower jaw 47 voxels off that its parent's
end held, and tore the head at 90 degrees (#86). The ball at the joint keeps the torso whole where a limb leaves it.

Every voxel of the mask gets an owner, so at the identity pose the posed body is the mask voxel for voxel. The
animator repaints ownership where the rule is wrong (the studio, ``volanim connect --fix-lumps``):
:meth:`Ownership.with_labels`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numba
import numpy as np

from volanim_core._run_kernels import run_values, runs
from volanim_core.geometry import IDENTITY, Geometry
from volanim_core.rig._hull_kernels import hull_ends, plane_corners
from volanim_core.rig._ownership_kernels import (
    TUBE_COLUMNS,
    nearest_outside,
    own_by_tubes,
    pool_labels,
    section_moments,
    voxel_flags,
)
from volanim_core.rig._table_kernels import bone_cells, busy_extents, flagged_voxels, row_spans
from volanim_core.rig._thin_kernels import diagonal_bits
from volanim_core.rig.connectivity import BoneSegment, Connectivity
from volanim_core.rig.specks import speck_runs
from volanim_core.volume import tight_bounds

SECTION_VOXELS = 64_000_000  # the lattice the cross-sections' moments are gathered on
CELL = 2  # the cube a turned bone's reads are planned by (Ownership.cells): its cubes moved mark where it can land
#: a voxel's 20 edge and corner neighbours: two such voxels of one bone, each pushed forward and rounded, can land
#: two voxels apart on an axis (centres up to sqrt(3) apart); their midpoint pushed too lands at most one voxel from
#: each (half of sqrt(3) < 1 on every axis), so the pair stays 26-connected (Ownership.diagonals)
DIAGONALS = np.array([(dx, dy, dz) for dx in (-1, 0, 1) for dy in (-1, 0, 1) for dz in (-1, 0, 1)
                      if abs(dx) + abs(dy) + abs(dz) >= 2], np.int64)
THIN = 2  # Ownership.flags' bit of a body voxel its bone's flesh holds one voxel thick along some axis


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
    tubes: np.ndarray | None = None  # (B, TUBE_COLUMNS): the tubes the rule used (_ownership_kernels.tube_distance)
    path: object = None  # the file it was read from or saved to (a .tskel names it)
    #: the rest grid is every ``factor``-th voxel of the skeleton's (:meth:`coarse`: a live preview's), its
    #: voxel c the skeleton's voxels ``factor c .. factor c + factor - 1``
    factor: int = 1
    _coarse: dict = field(default_factory=dict, repr=False)
    _hulls: list | None = field(default=None, repr=False)
    _spans: np.ndarray | None = field(default=None, repr=False)
    _flags: np.ndarray | None = field(default=None, repr=False)
    _cells: tuple | None = field(default=None, repr=False)
    _thin: tuple | None = field(default=None, repr=False)
    _diagonals: np.ndarray | None = field(default=None, repr=False)
    _runs: tuple | None = field(default=None, repr=False)

    def __post_init__(self):
        self.origin = tuple(int(v) for v in self.origin)
        self.ball_radii = np.asarray(self.ball_radii, np.float64).reshape(len(self.bones))
        if self.labels.ndim != 3:
            raise ValueError(f"ownership labels must be a 3-D volume [x, y, z], got shape {self.labels.shape}")
        if self.labels.dtype.kind != "u":
            raise ValueError(f"ownership labels must be unsigned integers, got {self.labels.dtype}")
        # one layout, x fastest, as ownership() makes them and the warm-up compiles for: labels given in C order
        # made every kernel compile again on first use (20 s after `volanim_core warmup`)
        self.labels = np.asfortranarray(self.labels)
        if self.tubes is None:  # no tubes (all zero: a tube that holds nothing): a bone carries what it owns
            self.tubes = np.zeros((len(self.bones), TUBE_COLUMNS))
        self.tubes = np.ascontiguousarray(self.tubes, np.float64).reshape(len(self.bones), TUBE_COLUMNS)

    @property
    def mask(self) -> np.ndarray:
        return self.labels != 0

    def hulls(self) -> list[np.ndarray]:
        """Each bone's hull points ``(K, 3)`` in rest voxels (empty: owns none): owned voxels among which are all
        the vertices of the convex hull of its owned voxels, so a posed bone's voxels lie within them moved and its
        posed box is tight whatever the turn. The corners of its outline in both its z slices and its y planes
        (rig/_hull_kernels): mannequin-large's 7,600 of 47,000 row ends. qhull's vertices of them cost 20-30 ms
        more (18 calls) for no tighter box."""
        if self._hulls is None:
            pts, lab = hull_ends(self.spans())
            keep = plane_corners(pts, lab, *self.labels.shape[1:])
            pts, lab = (pts[keep] + np.asarray(self.origin)).astype(np.float64), lab[keep]
            starts = np.searchsorted(lab, np.arange(len(self.bones) + 1))  # lab rises: made bone by bone
            self._hulls = [pts[starts[b]:starts[b + 1]] for b in range(len(self.bones))]
        return self._hulls

    def runs(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(first, x0, x1, value)``: the runs of one label each along x of every row of :attr:`labels` (row
        ``z * Y + y``; volanim_core/_run_kernels.runs), made once (ownership() keeps the ones its specks read).
        The tables :meth:`spans` and :meth:`cells` are made from them, not from every voxel of the box."""
        if self._runs is None:
            zyx = np.ascontiguousarray(self.labels.T)
            first, x0, x1 = runs(zyx, True)
            self._runs = (first, x0, x1, run_values(zyx, first, x0))
        return self._runs

    def spans(self) -> np.ndarray:
        """``(B, Y, Z, 2)`` int32: each bone's first and last x on each row of :attr:`labels` (x1 < x0: none),
        so a bone moved by whole voxels reads only its own stretch of each row."""
        if self._spans is None:
            spans = np.empty((len(self.bones), *self.labels.shape[1:], 2), np.int32)
            spans[..., 0], spans[..., 1] = 1, 0
            first, x0, x1, value = self.runs()
            row_spans(first, x0, x1, value, self.labels.shape[1], spans)
            self._spans = spans
        return self._spans

    def flags(self) -> np.ndarray:
        """``[x, y, z]`` uint8 beside :attr:`labels` (made once): bit 1 where a voxel and its 26 neighbours hold
        one label (a posed read there needs no interpolation), bit 2 on a body voxel one voxel thick along some
        axis (pushed forward too when its bone turns, so a thin limb stays whole), bit 4 on an outside voxel with
        a face neighbour in the body (only near those can a read be more than half body), bit 8 on every other
        outside voxel (a read nearest one is refused at once): rig/_ownership_kernels."""
        if self._flags is None:
            # laid out as the labels are (Fortran: x runs fastest), so a read of both touches the same lines
            flags = np.zeros(self.labels.shape, np.uint8, order="F")
            voxel_flags(self.labels, busy_extents(*self.runs()[:3], *self.labels.shape[1:], len(self.labels)), flags)
            self._flags = flags
        return self._flags

    def cells(self) -> tuple[np.ndarray, np.ndarray]:
        """Each bone's :data:`CELL`-cubes of :attr:`labels` (made once): ``(starts (B + 1,), cells (N, 3))``, bone b's
        cubes (lower corner / CELL) at ``cells[starts[b]:starts[b + 1]]``. A turned bone's cubes, moved, say which
        output cubes its reads can find it in (reconstruct/owned.py): a frog leg's row holds the other leg too."""
        if self._cells is None:
            self._cells = bone_cells(*self.runs(), np.array(self.labels.shape, np.int64), CELL, len(self.bones))
        return self._cells

    def thin(self) -> tuple[np.ndarray, np.ndarray]:
        """Each bone's thin voxels (:meth:`flags` bit 2), made once: ``(starts (B + 1,), voxels (N, 3))`` as
        :meth:`cells`. A turned bone pushes these forward too (reconstruct/_owned_kernels.splat_turned)."""
        if self._thin is None:
            self._thin = flagged_voxels(*self.runs(), self.flags(), THIN, len(self.bones), self.labels.shape[1])
        return self._thin

    def diagonals(self) -> np.ndarray:
        """``(N,)`` uint32 beside :meth:`thin`'s voxels, made once: bit ``d`` where the voxel's edge or corner neighbour
        :data:`DIAGONALS` ``[d]`` is its bone's and no face neighbour on the way (one step along one of ``d``'s
        axes) is a thin voxel of its bone. Pushed forward, such a pair can land two voxels apart, and the splat
        pushes their midpoint too (reconstruct/_owned_kernels.splat_turned). A thin face neighbour F on the way,
        pushed too, joins them anyway: it lands a voxel from the first at most, and F's own bits join F to the
        other (a face or an edge step). The frog's: 292,000 midpoints -> 231,000 (corners 131,000 -> 70,000)."""
        if self._diagonals is None:
            voxels = self.thin()[1]
            self._diagonals = np.zeros(len(voxels), np.uint32)
            diagonal_bits(self.labels, self.flags(), THIN, voxels, DIAGONALS, self._diagonals)
        return self._diagonals

    def counts(self) -> np.ndarray:
        """Each bone's owned voxels."""
        return np.bincount(self.labels.ravel(), minlength=len(self.bones) + 1)[1:len(self.bones) + 1]

    def coarse(self, factor: int) -> Ownership:
        """This ownership on a ``factor``-times coarser grid (kept: made once per factor): each coarse voxel the
        bone most of its block's body voxels belong to, where at least half the block is body (the body's
        size kept, as the coarse spheres keep it), its joints and balls scaled alike. Pose it with
        :meth:`rest_matrices` of the coarse frame's matrices (:func:`~volanim_core.rig.pose.scaled`)."""
        if factor == 1:
            return self
        if factor not in self._coarse:
            lo = np.asarray(self.origin)
            coarse_lo = np.floor_divide(lo, factor)
            offset = lo - coarse_lo * factor
            shape = -(-(offset + self.labels.shape) // factor)
            labels = np.zeros(tuple(int(n) for n in shape), self.labels.dtype, order="F")
            pool_labels(self.labels, offset.astype(np.int64), int(factor), labels)
            bones = [BoneSegment(b.proximal / factor, b.distal / factor, b.name)
                     for b in self.bones]
            self._coarse[factor] = Ownership(labels, tuple(coarse_lo), bones, self.ball_radii / factor,
                                             self.geometry.with_spacing(np.multiply(self.geometry.spacing, factor)),
                                             factor=self.factor * factor)
        return self._coarse[factor]

    def rest_matrices(self, matrices: np.ndarray) -> np.ndarray:
        """Bone matrices that take the skeleton's rest voxels to posed ones (a coarse frame's: followed by a
        1/factor scale) made to take this grid's rest voxels: a coarse voxel c is the skeleton's voxel factor c."""
        if self.factor == 1:
            return matrices
        s = np.diag([float(self.factor)] * 3 + [1.0])
        return np.ascontiguousarray(s @ np.asarray(matrices, np.float64))

    def with_labels(self, labels: np.ndarray) -> Ownership:
        """The same rig with other owners (a repaint); the labels must cover the same body."""
        if labels.shape != self.labels.shape or not np.array_equal(labels != 0, self.labels != 0):
            raise ValueError("a repaint may change which bone owns a voxel, not which voxels are the body")
        return Ownership(labels, self.origin, self.bones, self.ball_radii, self.geometry, self.tubes)

    def carried_into(self, matrices: np.ndarray, lo, hi, *, but: int | None = None) -> np.ndarray:
        """Flat indices (into :attr:`labels`, Fortran order) of the voxels whose posed place (each moved by its
        owner's matrix) lies in the box ``lo..hi`` (posed rest-grid voxels), except bone ``but``'s: the flesh a
        lump there was made of."""
        flat = self.labels.reshape(-1, order="F")
        idx = np.flatnonzero(flat)
        xyz = np.column_stack(np.unravel_index(idx, self.labels.shape, order="F")) + np.asarray(self.origin)
        bone = flat[idx].astype(np.int64) - 1
        posed = np.empty(xyz.shape, np.float64)
        for b in np.unique(bone):
            at = bone == b
            posed[at] = xyz[at] @ matrices[b, :3, :3] + matrices[b, 3, :3]
        inside = ((posed >= np.asarray(lo, float) - 0.5) & (posed <= np.asarray(hi, float) + 0.5)).all(1)
        if but is not None:
            inside &= bone != but
        return idx[inside]

    def relabelled(self, indices: np.ndarray, bone: int) -> Ownership:
        """The same rig with the voxels at flat ``indices`` (of :attr:`labels`, Fortran order) given to ``bone``."""
        labels = self.labels.copy(order="F")
        labels.reshape(-1, order="F")[np.asarray(indices, np.int64)] = bone + 1
        return self.with_labels(labels)

    def volume(self, shape) -> np.ndarray:
        """The labels on the whole rest grid of ``shape`` (a label volume to draw or save)."""
        out = np.zeros(shape, self.labels.dtype, order="F")
        lo = np.asarray(self.origin)
        hi = np.minimum(lo + self.labels.shape, shape)
        out[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]] = self.labels[:hi[0] - lo[0], :hi[1] - lo[1], :hi[2] - lo[2]]
        return out


def tube_reach(tube: np.ndarray) -> float:
    """How far a tube (a row :func:`~volanim_core.rig._ownership_kernels.tube_distance` reads) reaches from its
    segment: its largest semi-axis at its thicker end, or a cap (0: a tube that holds nothing)."""
    scale = max(tube[7], tube[7] + tube[8])
    norms = [float(np.linalg.norm(tube[9 + 3 * i:12 + 3 * i])) for i in range(2)]
    if scale <= 0 or min(norms) <= 0:
        return 0.0
    return float(max(scale / min(norms), tube[18], tube[19]))


def tube_reaches(tubes: np.ndarray) -> np.ndarray:  # (B,): each tube's tube_reach
    return np.array([tube_reach(t) for t in tubes], np.float64).reshape(len(tubes))


def tube_radii(conn: Connectivity, box: np.ndarray, lo: np.ndarray) -> np.ndarray:
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
            r = body_depth(box, mid)
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
    mask = np.asarray(mask)
    mask = mask if mask.dtype == bool else mask != 0  # (a copy of mannequin-large's 46 M voxels: 8 ms)
    if not len(conn.bones):
        raise ValueError("ownership needs at least one bone")
    b = tight_bounds(mask)
    if b is None:
        raise ValueError("ownership needs a body: the mask is empty")
    lo = np.asarray(b.lo)
    box = np.asfortranarray(mask[b.slices()])
    radii = tube_radii(conn, box, lo)
    a = np.array([s.proximal for s in conn.bones], np.float64)
    ab = np.array([s.distal - s.proximal for s in conn.bones], np.float64)
    labels = np.zeros(box.shape, label_dtype(len(conn.bones)), order="F")
    tubes = tube_rows(a, ab, radii, cross_sections(box, lo, tube_rows(a, ab, radii, [None] * len(a))))
    own_by_tubes(box, lo.astype(np.float64), tubes, _yields(conn.bones), tube_boxes(tubes, lo), tube_reaches(tubes),
                 labels, numba.get_num_threads())
    runs_after = speck_runs(labels, len(a))[1]
    balls = np.array([_ball_inside(box, s.proximal - lo) for s in conn.bones])
    return Ownership(labels, tuple(lo), list(conn.bones), balls, geometry or conn.geometry, tubes,
                     _runs=runs_after)


def _meets(bones: list[BoneSegment]) -> np.ndarray:
    """``(B, B)`` whether bone ``j``'s distal joint is bone ``k``'s proximal one, at ``[k, j]``."""
    starts = np.array([b.proximal for b in bones], np.float64).reshape(-1, 3)
    ends = np.array([b.distal for b in bones], np.float64).reshape(-1, 3)
    return np.all(np.abs(starts[:, None, :] - ends[None, :, :]) < 1e-6, axis=2)


def bone_parents(bones: list[BoneSegment]) -> list[int | None]:
    """Each bone's parent: the first bone whose distal joint is its proximal one (None: it leaves a root joint)."""
    return [int(np.argmax(row)) if row.any() else None for row in _meets(bones)]


def _yields(bones: list[BoneSegment]) -> np.ndarray:
    """``(B, 2)`` whether each bone's round end behind its proximal joint and past its distal one yields to the
    other tubes (holds only what none holds): behind the proximal joint when a bone ends there (the thigh's end
    inside the pelvis is the pelvis's flesh), past the distal joint when exactly one bone goes on from it (a
    limb's next segment; a branching joint's end, the shoulders' above the spine, is body)."""
    meets = _meets(bones)
    return np.stack([meets.any(axis=1), meets.sum(axis=0) == 1], axis=1)


def tube_boxes(tubes: np.ndarray, lo) -> np.ndarray:
    """``(B, 6)`` ``x0 x1 y0 y1 z0 z1``: the box (indices of a grid whose voxel 0 is ``lo``) each tube can hold a
    voxel in: its segment's box grown by its reach (:func:`tube_reach`: a voxel it holds lies within that of the
    segment) and a voxel; empty for a tube that holds nothing. The kernels measure a bone only in its box, with
    the same owners: mannequin-large's voxels were measured against 3.7 bones each (those reaching the slice),
    now 1.7 (its ownership 0.35 -> 0.25 s)."""
    out = np.zeros((len(tubes), 6), np.int64)
    for b, (tube, r) in enumerate(zip(tubes, tube_reaches(tubes))):
        for axis in range(3):
            ends = (tube[axis], tube[axis] + tube[3 + axis])
            out[b, 2 * axis:2 * axis + 2] = (np.floor(min(ends) - r) - lo[axis] - 1,
                                             np.ceil(max(ends) + r) - lo[axis] + 1) if r > 0 else (1, 0)
    return out


def tube_rows(a: np.ndarray, ab: np.ndarray, radii: np.ndarray, sections: list) -> np.ndarray:
    """``(B, TUBE_COLUMNS)`` tubes as :func:`~volanim_core.rig._ownership_kernels.tube_distance` reads them: each
    bone's segment, its taper (``radii`` at both joints, relative to the middle), its cross-section
    (``sections[k]``: ``(axes (2, 3), semi-axes (2,))`` from :func:`cross_section`, None: round, of the middle's
    radius), ending round past both joints."""
    rows = np.zeros((len(a), TUBE_COLUMNS))
    for k in range(len(a)):
        length2 = float(ab[k] @ ab[k])
        mid = max(0.5 * (radii[k, 0] + radii[k, 1]), 0.5)
        u = ab[k] / np.sqrt(length2) if length2 > 0 else np.array([0.0, 0.0, 1.0])
        e, semi = (_perpendiculars(u), (mid, mid)) if sections[k] is None else sections[k]
        rows[k, :3], rows[k, 3:6], rows[k, 6] = a[k], ab[k], 1.0 / length2 if length2 > 0 else 0.0
        rows[k, 7], rows[k, 8] = radii[k, 0] / mid, (radii[k, 1] - radii[k, 0]) / mid
        rows[k, 9:12], rows[k, 12:15], rows[k, 15:18] = e[0] / semi[0], e[1] / semi[1], u
        # past a joint the tube ends round, as far as its larger semi-axis reaches at that end
        rows[k, 18:20] = max(semi) * np.array([radii[k, 0], radii[k, 1]]) / mid
    return rows


def _perpendiculars(u: np.ndarray) -> np.ndarray:
    e1 = np.cross(u, [1.0, 0.0, 0.0] if abs(u[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    return np.array([e1, np.cross(u, e1)])


def cross_sections(box: np.ndarray, lo: np.ndarray, round_tubes: np.ndarray) -> list:
    """Each bone's cross-section in its middle (0.3 < t < 0.7), from the voxels its round tube holds deepest:
    the principal axes of their offsets from the segment and the semi-axes of the filled ellipse with those
    moments (2 sigma); None for a bone with too few voxels there, or a flat one. Moments are gathered on a
    lattice only beyond 64 M voxels (SECTION_VOXELS): a coarser one (every 2nd voxel) moved the
    hip's gap on the mannequin from 4.6 % to 11 % of the leg, so the fit is sensitive to it."""
    step = max(1, int(np.ceil((box.size / SECTION_VOXELS) ** (1 / 3))))
    sums = np.zeros((len(round_tubes), 10))
    section_moments(box, lo.astype(np.float64), round_tubes, tube_boxes(round_tubes, lo), tube_reaches(round_tubes),
                    step, sums, numba.get_num_threads())
    out = []
    for s in sums:
        if s[0] < 30:
            out.append(None)
            continue
        mean = s[1:4] / s[0]
        xx, xy, xz, yy, yz, zz = s[4:] / s[0]
        cov = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]) - np.outer(mean, mean)
        w, e = np.linalg.eigh(cov)
        semi = 2.0 * np.sqrt(np.maximum(w[::-1][:2], 0.0))
        out.append(None if semi.min() < 0.5 else (e[:, ::-1][:, :2].T, semi))
    return out


def body_depth(box: np.ndarray, p) -> float:
    """The distance from voxel ``p`` of ``box`` (the body) to the nearest voxel outside it (0 outside the body;
    beyond the box is outside). A window around p, doubled until it holds an outside voxel: the few joints
    asked about need no distance transform of the whole body."""
    p = np.asarray(p, int)
    if (p < 0).any() or (p >= box.shape).any() or not box[tuple(p)]:
        return 0.0
    r = 4
    while True:
        lo, hi = p - r, p + r + 1
        edge = ((lo < 0) | (hi > np.array(box.shape))).any()
        best = float(np.sqrt(nearest_outside(box, p[0], p[1], p[2], r)))  # numba: mannequin-large's torso 20 ms
        if edge:  # beyond the box is outside: the nearest face of the box counts
            best = min(best, float(np.min(np.concatenate([p + 1, np.array(box.shape) - p]))))
        if best <= r:
            return best
        r *= 2


def _ball_inside(box: np.ndarray, p: np.ndarray) -> float:
    """A radius whose ball around ``p`` lies inside the body: the depth at the nearest voxel less the way to it."""
    v = np.round(p).astype(int)
    return max(0.0, body_depth(box, v) - float(np.linalg.norm(p - v)))
