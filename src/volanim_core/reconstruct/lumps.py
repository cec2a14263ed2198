"""Flesh a pose carried where its bone cannot carry it (lumps), found without the body's true shape.

    rest owner voxels (RestParts.voxels, rigid joints: each voxel's bone)
      --> each bone's reach: 1.3 x the 75th percentile of its own rest voxels' distance to its segment, + 1
    posed bone volume: each voxel q, its owner b, the rest point it came from p = [q 1] M_b^-1
      carried ....... p lay beyond b's reach but within another bone c's (the nearest such c),
                      and b moved it (|q - p| > MOVED: flesh left where it lay is not carried off)
      moved away .... c would have kept that flesh at [p 1] M_c, more than 1.5 voxels from q
      nobody's own .. no bone k's own rest flesh lands on q ([q 1] M_k^-1 is owned by k at rest)
    --> opened by one voxel (a one-voxel rim is not a lump), 26-connected pieces, largest first
    --> kept when at least SHARE of the limb that carried it (its bone and the bones below, at rest)
    --> Lump(voxels, the posed joint nearest its centre, centre, the bone that carried it, the bone c whose
        flesh it is: the one to give those points to)

Why: the nearest-bone connect gives a limb the torso's flesh next to its joint (the armpit, the groin).
When the limb turns, that flesh turns with it and hangs beside the body: the lump a person sees under a
raised arm, which cracks, stumps, pieces and volume do not see. A bone's reach is where its own flesh
lies at rest; flesh from another bone's reach that the pose moved away from that bone, to a place no
bone's own flesh is, is a lump. Measured against the mannequins' true shapes (benchmarks/bench_shape.py,
the README), over the 70 rigid poses of each: it flags 26 of the mannequin's 27 rows whose largest extra
blob is 0.5 % of the moved limb or more, and 24 of its 27 flags are flesh the true shape lacks;
mannequin-large 28 of 32 and 26 of 29 (it misses the neck, whose reach is learnt from the flesh the head
wrongly carries). A smooth frame's voxel is followed back by the blend that moved it (its row of the
transform table, the owner-mode reconstruction) and is the flesh of its point's bone.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from volanim_core.reconstruct.shape import OPENING, PIECES
from volanim_core.rig.nearest import segment_distances
from volanim_core.rig.skinning import segment_distance

REACH_PERCENTILE, REACH_SCALE, REACH_MARGIN = 75, 1.3, 1.0
MOVED = 1.5  # voxels: flesh its host bone would have kept within this of where it is was not moved away
MIN_VOXELS = 20  # smaller pieces are the rasterisation's, not a lump a person sees
SHARE = 0.005  # of the carrying limb's voxels: #60's bar for a lump a person sees (a fist under an arm is 6 %)


@dataclass
class Lump:
    voxels: int
    near: str  # the posed joint nearest its centre
    centre: np.ndarray  # rest-grid voxels, posed frame
    lo: np.ndarray | None = None  # its box, the same voxels (the studio draws it)
    hi: np.ndarray | None = None
    carrier: str = ""  # the bone that carried it off (its voxels' owner in the pose)
    belongs_to: str = ""  # the bone whose reach its flesh lay in at rest: whom to give it to (#83)

    def __eq__(self, other) -> bool:  # two reports of one frame compare equal (the arrays element by element)
        return isinstance(other, Lump) and (self.voxels, self.near) == (other.voxels, other.near) and all(
            np.array_equal(a, b) for a, b in ((self.centre, other.centre), (self.lo, other.lo), (self.hi, other.hi)))

    def text(self) -> str:
        return f"lump near {self.near}: {self.voxels:,} voxels of {self.whose} carried off{self.by}{self.fix}"

    @property
    def whose(self) -> str:
        return f"{self.belongs_to}'s flesh" if self.belongs_to else "flesh"

    @property
    def by(self) -> str:
        return f" by {self.carrier}" if self.carrier else " where no bone's own flesh is"

    @property
    def fix(self) -> str:
        """What to do about it, in words: give the points there to the bone the flesh belongs to."""
        return f" (give the points there to {self.belongs_to})" if self.belongs_to else ""


def bone_reach(segments: list[tuple[np.ndarray, np.ndarray]], voxels: np.ndarray, bone: np.ndarray) -> np.ndarray:
    """Each bone's reach (voxels from its segment) from its own rest voxels: ``(B,)``."""
    reach = np.full(len(segments), REACH_MARGIN)
    for b, (p0, p1) in enumerate(segments):
        own = voxels[bone == b].astype(np.float64)
        if len(own):
            reach[b] = REACH_SCALE * np.percentile(segment_distance(own, p0, p1), REACH_PERCENTILE) + REACH_MARGIN
    return reach


def limb_voxels(segments, bone: np.ndarray) -> np.ndarray:
    """Each bone's limb at rest: its own voxels and those of every bone below it (a bone whose proximal
    joint is its distal one, and so on): ``(B,)``."""
    own = np.bincount(bone, minlength=len(segments)).astype(np.int64)
    children = [[c for c, (p0, _) in enumerate(segments) if c != b and np.allclose(p0, segments[b][1])]
                for b in range(len(segments))]
    out = np.zeros(len(segments), np.int64)
    for b in range(len(segments)):
        todo, seen = [b], set()
        while todo:
            k = todo.pop()
            if k not in seen:
                seen.add(k)
                todo.extend(children[k])
        out[b] = own[sorted(seen)].sum()
    return out


def find_lumps(posed_bone: np.ndarray, origin, matrices: np.ndarray, segments, reach: np.ndarray,
               rest_owner: np.ndarray, rest_origin, joints: dict[str, np.ndarray],
               limbs: np.ndarray | None = None, labels: list[str] | None = None,
               row_bone: np.ndarray | None = None) -> list[Lump]:
    """The lumps of a frame (see the module docstring), largest first.

    Parameters
    ----------
    posed_bone : (X, Y, Z) ints
        The frame's bone-mode reconstruction (bone + 1 per voxel), its voxel [0, 0, 0] at ``origin``; with
        ``row_bone``, its owner-mode one (each voxel's row of ``matrices`` + 1).
    matrices : (B, 4, 4)
        The frame's bone matrices, rest voxels -> posed (``[x y z 1] @ M``); with ``row_bone``, its transform
        table (:func:`~volanim_core.rig.skinning.transform_table`: the bone matrices, then smooth joints'
        blended ones).
    segments : list of (proximal, distal)
        Each bone's rest segment (the ``Root:`` records).
    reach : (B,)
        :func:`bone_reach` of the connectivity.
    rest_owner : (X, Y, Z) ints
        The rest frame's bone-mode reconstruction (bone + 1), its voxel [0, 0, 0] at ``rest_origin``.
    joints : dict
        Posed joint positions, to name each lump's place.
    limbs : (B,), optional
        :func:`limb_voxels` of the connectivity: a lump is kept when it is SHARE of the limb that carried it
        (None: every piece of MIN_VOXELS or more).
    labels : list of str, optional
        The bones' names: each lump then says which bone carried it and which bone its flesh belongs to.
    row_bone : (R,) ints, optional
        Each row's bone (a blended row's: its point's): a smooth frame's voxel is followed back by the blend
        that moved it, and is its bone's flesh.
    """
    q = np.argwhere(posed_bone > 0)
    row = posed_bone[tuple(q.T)].astype(np.int64) - 1
    own = row if row_bone is None else np.asarray(row_bone, np.int64)[row]
    qf = q.astype(np.float64) + np.asarray(origin, np.float64)
    inverse = np.linalg.inv(matrices)
    # where each voxel's flesh lay at rest (by the matrix that moved it), and whether its own bone reaches there:
    # a bone's own matrix for most voxels (one product a bone); a smooth frame's blended ones one by one (the few
    # voxels near a bent joint: a matrix gathered per voxel of mannequin-large's body would be 300 MB)
    rest = np.empty_like(qf)
    plain = row < len(segments)
    for b in np.unique(row[plain]):
        sel = row == b
        rest[sel] = qf[sel] @ inverse[b, :3, :3] + inverse[b, 3, :3]
    if not plain.all():
        r = row[~plain]
        rest[~plain] = np.einsum("ni,nij->nj", qf[~plain], inverse[r, :3, :3]) + inverse[r, 3, :3]
    beyond = np.zeros(len(q), bool)
    for b in np.unique(own):
        sel = own == b
        beyond[sel] = segment_distance(rest[sel], *segments[b]) > reach[b]
    # flesh its own bone left where it lay at rest was not carried anywhere: the body had flesh there
    # (a groin point of the thigh's, held by the still pelvis while the thigh lifts, is not a lump)
    beyond &= np.linalg.norm(rest - qf, axis=1) > MOVED
    cand = np.flatnonzero(beyond)
    if not len(cand):
        return []
    d = segment_distances(rest[cand], np.array([[p0, p1] for p0, p1 in segments], np.float64))
    inside = d <= reach[None, :]
    host = np.argmin(np.where(inside, d, np.inf), axis=1)
    # whose flesh it is, to name (not to find) a lump: the bone whose reach it lies deepest in, relative to
    # that reach. The nearest segment named the clavicle for the armpit; the body part is the torso's (the
    # mannequin's own parts, tests/core/reconstruct/test_lumps.py)
    deepest = np.argmin(np.where(inside, d / reach[None, :], np.inf), axis=1)
    keep = inside.any(axis=1)  # within another bone's reach at rest: that bone's flesh, carried
    kept_at = np.empty((len(cand), 3))
    for c in np.unique(host):
        sel = host == c
        kept_at[sel] = rest[cand[sel]] @ matrices[c, :3, :3] + matrices[c, 3, :3]
    keep &= np.linalg.norm(kept_at - qf[cand], axis=1) > MOVED  # ... and moved away from it
    cand, deepest = cand[keep], deepest[keep]
    rest_origin = np.asarray(rest_origin, np.int64)
    for k in range(len(segments)):  # a bone whose own rest flesh lands here: overlap, not a lump
        if not len(cand):
            break
        at = np.rint(qf[cand] @ inverse[k, :3, :3] + inverse[k, 3, :3]).astype(np.int64) - rest_origin
        ok = np.all((at >= 0) & (at < rest_owner.shape), axis=1)
        theirs = np.zeros(len(cand), bool)
        theirs[ok] = rest_owner[tuple(at[ok].T)] == k + 1
        mine = ~(theirs & (own[cand] != k))
        cand, deepest = cand[mine], deepest[mine]
    if not len(cand):
        return []
    # opened and labelled in the flagged voxels' box only (a margin of 1 for the opening), not the whole grid
    lo = np.maximum(q[cand].min(axis=0) - 1, 0)
    hi = np.minimum(q[cand].max(axis=0) + 2, posed_bone.shape)
    box = tuple(slice(a, b) for a, b in zip(lo, hi))
    flagged = np.zeros(tuple(hi - lo), bool)
    flagged[tuple((q[cand] - lo).T)] = True
    hosts = np.zeros(tuple(hi - lo), np.int64)  # each flagged voxel's owner at rest + 1: whom the flesh belongs to
    hosts[tuple((q[cand] - lo).T)] = deepest + 1
    posed_bone = posed_bone[box]
    origin = np.asarray(origin, np.float64) + lo
    pieces, n = ndimage.label(ndimage.binary_opening(flagged, OPENING), PIECES)
    if not n:
        return []
    sizes = np.bincount(pieces.ravel())[1:]
    names = list(joints)
    at = np.array([joints[n] for n in names], np.float64) if names else None
    lumps = []
    for k in np.argsort(-sizes, kind="stable"):
        if sizes[k] < MIN_VOXELS:
            break
        piece = pieces == k + 1
        carried = posed_bone[piece].astype(np.int64) - 1
        carrier = np.bincount(carried if row_bone is None else row_bone[carried]).argmax()  # its most common owner
        if limbs is not None and sizes[k] < SHARE * limbs[carrier]:  # under SHARE of the limb that carried it
            continue
        where = np.argwhere(piece) + np.asarray(origin, np.float64)
        centre = where.mean(axis=0)
        near = names[int(((at - centre) ** 2).sum(axis=1).argmin())] if names else ""
        held = hosts[piece]
        held = held[held > 0]
        belongs = int(np.bincount(held).argmax()) - 1 if len(held) else -1
        lumps.append(Lump(int(sizes[k]), near, centre, where.min(axis=0), where.max(axis=0),
                          carrier=labels[carrier] if labels else "",
                          belongs_to=labels[belongs] if labels and belongs >= 0 else ""))
    return lumps


def frame_lumps(tskel, posed, rest, posed_joints: dict) -> list[Lump]:
    """The lumps of a frame (``tskel``) whose bone-mode reconstruction is ``posed`` (``rest``: its
    :class:`~volanim_core.reconstruct.breakage.RestParts`, whose reach it keeps). A smooth frame is followed
    back by the blends: its owner-mode reconstruction on the same grid, each row the flesh of its point's bone."""
    from volanim_core.reconstruct.engine import OWNER, reconstruct
    from volanim_core.rig.skinning import transform_table

    segments = [(b.proximal, b.distal) for b in tskel.bones]
    labels = [b.label for b in tskel.bones]
    row_bone = None
    if tskel.joints.smooth:  # rows of the transform table: a bone's own row is the bone, a blended row its point's
        table, row = transform_table(tskel)
        row_bone = np.arange(len(table), dtype=np.int64)
        row_bone[row] = np.asarray(tskel.bone, np.int64)
    points, rows = rest.voxels  # the rest frame's rows: the same points blend the same way
    if rest.reach is None:
        bones = rows if row_bone is None else row_bone[rows]
        rest.reach = bone_reach(segments, points, bones), limb_voxels(segments, bones)
    reach, limbs = rest.reach
    if row_bone is None:
        return find_lumps(posed.volume, posed.origin, np.asarray(tskel.matrices, np.float64), segments, reach,
                          rest.rest_bone.volume, rest.rest_bone.origin, posed_joints, limbs, labels=labels)
    rest_owner = np.concatenate([[0], row_bone + 1])[rest.rest_bone.volume]  # each rest voxel's bone + 1
    owner = reconstruct(tskel, mode=OWNER, bounds=posed.bounds)
    return find_lumps(owner.volume, owner.origin, table, segments, reach, rest_owner, rest.rest_bone.origin,
                      posed_joints, limbs, labels=labels, row_bone=row_bone)
