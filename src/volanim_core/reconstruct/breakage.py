"""Where a pose breaks the volume: the report the studio shows after each preview.

    spheres of different bones that overlap at rest but no longer touch in the pose
        --> cracks, located at the pair's rest midpoint, weighted by the gap
        --> nearest joint of each crack --> joints ranked by crack weight
    identity reconstruction (bone mode): each rest voxel, owned by bone b,
        should reappear at round(v @ M_b) --> lost voxels (a count)
    posed reconstruction --> connected components (26-neighbour) and sizes
    points lying along another bone than their own, which the pose carries far from
        where that bone went --> stumps (a piece left behind that stays connected; spheres only)

Why cracks and not lost voxels rank the joints: points wrongly left on the torso stay put as a stump, and
their voxels reappear where they were -- nothing is "lost" -- but the stump's spheres and the arm's part
company: a crack at the shoulder, which is where the user must re-attach points. An owned body (#84) moves by
its ownership, not its points: no stumps (shoulder points on the torso moved 65 of its voxels and its raised arm
came out whole, yet "STUMP left behind"); its flesh in the wrong place is what the lumps find.

Why stumps as well: cracks open at every bent joint (the outside of an elbow),
so their count alone cannot tell a healthy bend from "a part of the upper arm
fixed to the shoulder while the rest of the arm moves away" (the thesis's
words). A stump stays one piece with the torso, so the component count misses
it too. What marks it is geometric: its points lie along the upper arm's
segment, clearly closer to it than to their own bone's, and the pose puts them
more than a sphere's diameter away from where the upper arm took that place.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from volanim_core.progress import Reporter
from volanim_core.reconstruct import _label_kernels as L
from volanim_core.reconstruct.cracks import cracks, touching_pairs
from volanim_core.reconstruct.engine import OWNER, Reconstruction, moves_owned, reconstruct
from volanim_core.reconstruct.lumps import frame_lumps
from volanim_core.reconstruct.torn import SPECK_REACH, SPECK_VOXELS, homes, loose_specks, pieces_at, torn_off
from volanim_core.rig.connectivity import Connectivity, Tskel
from volanim_core.rig.nearest import segment_distances
from volanim_core.rig.pose import apply_matrices, apply_rows
from volanim_core.rig.skinning import blended_with, links, transform_table
from volanim_core.rig.tskel_tools import identity_tskel


@dataclass
class JointLoss:
    name: str
    lost: int  # cracks near this joint (sphere pairs that separated)
    rest: np.ndarray  # the joint's rest position
    posed: np.ndarray  # where it is in the posed frame
    gap: float = 0.0  # summed opening of those cracks, voxels


@dataclass
class BreakageReport:
    components: list[int]  # sizes, largest first
    posed_voxels: int
    rest_voxels: int
    lost_voxels: int
    hotspot_max: int
    hotspot_mean: float
    joints: list[JointLoss] = field(default_factory=list)
    cracks: int = 0
    pieces: list = field(default_factory=list)  # (voxels, nearest joint, posed centroid) of torn-off parts
    stumps: list = field(default_factory=list)  # Stump, largest first
    rest_pieces: int = 1  # the body's pieces at rest: pieces the pose keeps apart are not breakage
    body_pieces: int | None = None  # the segmented volume's pieces, when the caller knows them (the studio)
    lumps: list = field(default_factory=list)  # Lump (lumps.py), largest first: flesh carried off (rigid frames)
    source_coverage: tuple[int, int] | None = None  # (covered at rest, object voxels) of the scan, when given
    specks: list = field(default_factory=list)  # (voxels, nearest joint, posed centroid): let go near (torn.py)

    @property
    def loss_percent(self) -> float:
        """Voxel loss against the identity pose (negative: the pose grew the volume)."""
        return 100.0 * (self.rest_voxels - self.posed_voxels) / max(self.rest_voxels, 1)

    @property
    def size_change(self) -> str:
        """The loss in words: "0.44 % fewer voxels than the rest pose", or "more" (#83: "-0.44 % loss")."""
        loss = self.loss_percent
        if abs(loss) < 0.005:
            return "as many voxels as the rest pose"
        return f"{abs(loss):.2f} % {'fewer' if loss > 0 else 'more'} voxels than the rest pose"

    @property
    def shredded(self) -> bool:
        """The skeleton re-grows the rest pose in more pieces than the volume has (thin parts lost)."""
        return self.body_pieces is not None and self.rest_pieces > self.body_pieces

    @property
    def healthy(self) -> bool:
        """No piece torn off and no stump: measured against the rest pose, not against "one piece"."""
        return not self.pieces and not self.stumps

    @property
    def verdict(self) -> str:
        """One line for the status bar: the worst finding first."""
        if self.pieces:
            where = f" (near {self.pieces[0][1]})" if self.pieces[0][1] else ""
            return f"BROKEN: the pose tore off {len(self.pieces)} piece{'s' if len(self.pieces) > 1 else ''}{where}"
        if self.stumps:
            s = self.stumps[0]
            return f"STUMP left behind near {s.joint}: {s.points} points of {s.attached} lie along {s.lies_along}"
        whole = (f"nothing torn off (the rest pose too is {self.rest_pieces:,} pieces), no stump"
                 if self.rest_pieces > 1 else "one piece, no stump")
        if self.shredded:  # said first: every pose of this skeleton is in pieces, whatever the pose does
            return (f"the rest pose is already {self.rest_pieces:,} pieces where the volume is "
                    f"{self.body_pieces:,}: thin parts have no points (lower the thinness); {whole}")
        if self.lumps:  # the finding first (#83: it came last, cut off as "...lump near L_SHOUL..." after "healthy")
            first = self.lumps[0]
            more = f" and {len(self.lumps) - 1} more" if len(self.lumps) > 1 else ""
            moved = f" moved by {first.carrier}" if first.carrier else " carried off"
            return f"lump near {first.near}: {first.voxels:,} voxels of {first.whose}{moved}{more}; {whole}"
        return f"healthy: {whole}"

    def lines(self) -> list[str]:
        sizes = "" if len(self.components) == 1 else ": " + ", ".join(str(c) for c in self.components[:6]) + " voxels"
        out = [f"{len(self.components)} connected component(s){sizes}"
               + (f"; {self.rest_pieces:,} at rest" if self.rest_pieces > 1 else ""),
               *(f"piece of {n} voxels torn off near {j}" for n, j, _ in self.pieces[:5]),
               *([f"{len(self.specks)} speck(s) of at most {SPECK_VOXELS} voxels let go within {SPECK_REACH} voxels "
                  f"of the body near {self.specks[0][1]}, where the rest pose's own lie (the voxel grid's, not "
                  "breakage)"]
                 if self.specks else []),
               *(s.text() for s in self.stumps[:5]),
               *(lump.text() for lump in self.lumps[:5]),
               f"{self.posed_voxels:,} voxels, {self.size_change} ({self.lost_voxels:,} rest voxels not covered)",
               f"{self.cracks} cracks (sphere pairs of different bones that touched at rest and part in the pose)",
               f"hotspot: up to {self.hotspot_max} spheres on one voxel, mean {self.hotspot_mean:.1f}"]
        if self.source_coverage is not None:
            covered, total = self.source_coverage
            out.append(f"the rest pose re-grows {covered} of the scan's {total} object voxels "
                       f"({100 * covered / max(total, 1):.2f} %): the rest is the skeleton's loss, not the pose's")
        return out


@dataclass
class Stump:
    """Points attached to ``attached`` that lie along ``lies_along`` and were left behind by the pose."""

    points: int
    joint: str  # the joint nearest to them at rest
    attached: str
    lies_along: str
    posed: np.ndarray  # (K, 3) where the pose put them (their spheres' centres)
    weight: float  # sum of radius^3: how much volume stays behind, for ranking
    margin: float = 0.0  # their largest sphere radius: posed +- margin encloses the stump's voxels

    def text(self) -> str:
        return (f"stump near {self.joint}: {self.points} points attached to {self.attached} lie along "
                f"{self.lies_along} and stay behind (connect them to {self.lies_along})")


TOUCH_NEIGHBOURS = 16  # spheres of the other bone examined per misplaced point
# "Clearly closer" to another bone: by more than the point's radius and by this share of the distance.
# The frog's foot webbing lies 51-57 voxels from every segment of its leg, 1 nearer the upper arm's than
# the foot's: nearer by its radius, yet along neither; a true stump is 2-3 times nearer its limb's.
CLEARLY = 0.25


def misplaced_points(conn: Connectivity) -> tuple[np.ndarray, np.ndarray]:
    """Points that lie clearly closer to another bone's rest segment than to their own (pose-independent).

    Returns ``(indices, the bone they lie along)``. "Clearly": closer by more than the
    point's radius, so points near a joint, equally close to both bones, never count, and by a
    ``CLEARLY`` share of the distance, so points far from every bone (a web between the toes) never
    do. And part of that bone's flesh: its sphere reaches one of the bone's spheres. A point the body keeps apart from
    that bone by a gap (the torso's flank beside a hanging arm, nearer the arm's segment than the
    spine's) is not a piece of the limb, and stays where it is in any pose. None on an owned connectivity or
    frame (#84): its body moves by its ownership, so no point's attachment leaves flesh behind.
    """
    if not len(conn) or len(conn.bones) < 2 or moves_owned(conn, "auto"):
        return np.zeros(0, np.int64), np.zeros(0, np.int64)

    segs = np.array([[b.proximal, b.distal] for b in conn.bones])
    d = np.vstack([segment_distances(conn.points[s:s + 65536], segs)  # bounded temporaries on 10^5 points
                   for s in range(0, len(conn), 65536)])
    rows = np.arange(len(d))
    own = d[rows, conn.bone]
    d[rows, conn.bone] = np.inf
    near = d.argmin(1)
    idx = np.flatnonzero((own > d[rows, near] + conn.dt) & (own > (1.0 + CLEARLY) * d[rows, near]))
    return _part_of_flesh(conn, idx, near[idx])


def _part_of_flesh(conn: Connectivity, idx: np.ndarray, along: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The misplaced points ``idx`` that are part of the flesh of the bone they lie ``along``: linked
    (:func:`~volanim_core.rig.skinning.links`, through each other) to a point whose sphere reaches one
    of that bone's spheres. A bone with no points of its own yet takes every point along it."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    points, dt = np.asarray(conn.points, np.float64), np.asarray(conn.dt, np.float64)
    touching = np.zeros(len(idx), bool)
    for b in np.unique(along):
        mine = np.flatnonzero(conn.bone == b)
        sel = np.flatnonzero(along == b)
        if not len(mine):
            touching[sel] = True
            continue
        # the bone's nearest spheres (a limb's medial points are dense: the one reached is among them)
        dist, nb = cKDTree(points[mine]).query(points[idx[sel]], k=min(TOUCH_NEIGHBOURS, len(mine)))
        dist, nb = dist.reshape(len(sel), -1), nb.reshape(len(sel), -1)
        touching[sel] = (dist <= dt[mine][nb] + dt[idx[sel], None]).any(1)
    # and those linked to them through misplaced points of the same two bones (a stump's far end)
    i, j, _ = links(points[idx], dt[idx])
    same = (along[i] == along[j]) & (conn.bone[idx[i]] == conn.bone[idx[j]])
    _, part = connected_components(coo_matrix((np.ones(int(same.sum())), (i[same], j[same])),
                                              shape=(len(idx), len(idx))), directed=False)
    keep = np.isin(part, np.unique(part[touching]))
    return idx[keep], along[keep]


def stumps(tskel: Tskel, joints: dict[str, np.ndarray], misplaced=None) -> list[Stump]:
    """Misplaced points the pose carries more than a sphere's diameter from where the bone they lie
    along went, grouped by (their bone, that bone); largest first. With smooth joints, a point blended
    with the bone it lies along is not left behind (:func:`~volanim_core.rig.skinning.blended_with`).

    ``misplaced``: :func:`misplaced_points` of the same connectivity, when scanning many frames.
    """
    idx, along = misplaced_points(tskel) if misplaced is None else misplaced
    if not len(idx):
        return []
    p = tskel.points[idx].astype(np.float64)
    own = tskel.bone[idx].astype(np.int64)
    table, row = transform_table(tskel)  # smooth joints: a point near its bone's joint moves by the blend
    went = apply_rows(p, row[idx], table, len(tskel.bones))
    should = apply_matrices(p, along, tskel.matrices)
    behind = (np.linalg.norm(went - should, axis=1) > 2.0 * tskel.dt[idx]) & ~blended_with(tskel, idx, along)
    names = list(joints)
    pos = np.array([joints[n] for n in names], np.float64) if names else np.zeros((0, 3))
    label = [b.name or f"bone {k}" for k, b in enumerate(tskel.bones)]
    out = []
    for o, n in sorted({(int(o), int(n)) for o, n in zip(own[behind], along[behind])}):
        k = np.flatnonzero(behind & (own == o) & (along == n))
        centre = p[k].mean(0)
        joint = names[int(((pos - centre) ** 2).sum(1).argmin())] if names else ""
        out.append(Stump(len(k), joint, label[o], label[n], went[k], float((tskel.dt[idx[k]] ** 3).sum()),
                         float(tskel.dt[idx[k]].max())))
    return sorted(out, key=lambda s: -s.weight)


def components(volume: np.ndarray) -> list[int]:
    """Sizes of the 26-connected components of the non-zero voxels, largest first."""
    return [n for n, _, _ in _components(volume)[0]]


def _components(volume: np.ndarray) -> tuple[list[tuple[int, np.ndarray, int]], tuple]:
    """(size, where it broke off, piece number) per 26-connected component, largest first (equal sizes
    in the order they are met scanning the ``[z, y, x]`` grid), array coordinates; and the labelled
    runs ``(first, x0, x1, piece, n)`` (:mod:`._labels`), to ask which piece a voxel is in.

    For the largest "where" is its centroid; for every other piece it is the
    piece's voxel nearest to the largest one -- the place of the break (ties: the
    first in x-fastest order).

    Works on the ``[z, y, x]`` view, which is C-contiguous for a reconstruction (the frog's
    posed grid is 45 M voxels: nothing of grid size is copied), and on its x-runs
    (:mod:`._labels`: labelled, measured and searched run by run, with the GIL released so the
    studio's window keeps drawing while its worker makes the report). The nearest voxels come
    from one KD-tree of the main body's boundary voxels, which holds the nearest main voxel of
    any voxel outside, made once for all the pieces -- not a box search per piece (0.4 s for the
    frog's 250 pieces), a distance transform (1.1 s) or the boundary found with array operations
    over the grid (0.45 s).
    """
    zyx = np.ascontiguousarray(np.asarray(volume).T)
    ny = zyx.shape[1]
    first, x0, x1, piece, n = labels = L.label_runs(zyx)
    if n == 0:
        return [], labels
    counts, sums = L.piece_stats(first, x0, x1, piece, n, ny)
    sizes = counts[1:]
    order = np.argsort(-sizes, kind="stable")
    main = int(order[0]) + 1
    out = [(int(sizes[order[0]]), (sums[main] / counts[main])[::-1], main)]
    if n == 1:
        return out, labels
    from scipy.spatial import cKDTree

    start, pieces = L.piece_voxels(first, x0, x1, piece, counts, main, ny)  # every other piece's voxels
    # a KD-tree's query slows with the distance searched (a piece reaching 90 voxels away: 0.3 s), so each
    # piece asks within a reach grown until one of its voxels is nearer: every voxel at the piece's least
    # distance is then found, so the first of them in x-fastest order is exact
    tree = cKDTree(L.boundary_voxels(zyx, first, x0, x1, piece, main), balanced_tree=False, compact_nodes=False)
    for k in order[1:] + 1:
        voxels = pieces[start[k]:start[k + 1]]  # x-fastest order
        reach = 8.0
        while True:
            d, _ = tree.query(voxels, distance_upper_bound=reach)
            if np.isfinite(d).any():
                break
            reach *= 4.0
        out.append((int(sizes[k - 1]), voxels[int(np.argmin(d))][::-1].astype(np.float64), int(k)))
    return out, labels


def rest_voxels(rest_bone: Reconstruction) -> tuple[np.ndarray, np.ndarray]:
    """Every filled voxel of a rest reconstruction in bone (or owner) mode: its rest coordinates ``(K, 3)``
    and its label - 1 ``(K,)`` (the bone; the owner's row of the transform table), grouped by it (so
    :func:`~volanim_core.rig.pose.apply_matrices` moves them slice by slice: 0.3 s less per report
    on the frog than a mask per bone), in x-fastest order within a label. Pose-independent, so a
    caller reporting on many poses makes them once."""
    # C-contiguous for a reconstruction (no copy); a caller's C-ordered volume is copied, not compiled for anew
    zyx = np.ascontiguousarray(np.asarray(rest_bone.volume).T)
    first, x0, x1 = L.runs(zyx, True)  # runs of one label each, measured and listed as the pieces are
    label = L.run_values(zyx, first, x0)
    counts, _ = L.piece_stats(first, x0, x1, label, int(label.max(initial=0)), zyx.shape[1])
    _, voxels = L.piece_voxels(first, x0, x1, label, counts, 0, zyx.shape[1])
    bone = np.repeat(np.arange(len(counts) - 1), counts[1:])
    return voxels[:, ::-1] + np.asarray(rest_bone.origin), bone


def posed_images(points: np.ndarray, owner: np.ndarray, posed: Reconstruction, matrices: np.ndarray,
                 n_bones: int | None = None) -> np.ndarray:
    """Where rest voxels ``points`` land in the pose: ``(K, 3)`` array coordinates of ``posed``'s grid
    (possibly outside it). ``owner``: each voxel's row of ``matrices`` (bone matrices, then with smooth
    joints the blended ones from row ``n_bones`` on, :func:`~volanim_core.rig.skinning.transform_table`)."""
    moved = apply_rows(points, owner, matrices, len(matrices) if n_bones is None else n_bones)
    return np.floor(moved + 0.5).astype(np.int64) - np.asarray(posed.origin)


def lost_voxels(rest_bone: Reconstruction, posed: Reconstruction, matrices: np.ndarray,
                rest: tuple[np.ndarray, np.ndarray] | None = None, images: np.ndarray | None = None) -> np.ndarray:
    """Rest voxels (``(K, 3)`` rest coordinates) whose posed image under their bone is empty.

    ``rest``: :func:`rest_voxels` of ``rest_bone``, when the caller keeps them; ``images``: their
    :func:`posed_images`, when made already."""
    points, owner = rest_voxels(rest_bone) if rest is None else rest
    q = posed_images(points, owner, posed, matrices) if images is None else images
    shape = np.asarray(posed.volume.shape)
    inside = ((q >= 0) & (q < shape)).all(1)
    filled = np.zeros(len(q), bool)
    filled[inside] = posed.volume[tuple(q[inside].T)] > 0
    return points[~filled]


@dataclass
class RestParts:
    """What the report needs that no pose changes, made once per connectivity: the rest frame's
    owner volume (bone + 1 per voxel; with smooth joints, the owner's row of the transform table + 1),
    its voxels' rest coordinates and rows (:func:`rest_voxels`), and the sphere pairs that touch at
    rest (:func:`touching_pairs`). The studio keeps them between previews."""

    rest_bone: Reconstruction
    voxels: tuple[np.ndarray, np.ndarray]
    pairs: tuple
    piece: np.ndarray | None = None  # per rest voxel, the rest piece it belongs to (1..pieces)
    pieces: int = 1  # how many 26-connected pieces the body is at rest
    reach: tuple | None = None  # each bone's reach and limb (lumps.py), made by the first report that needs them

    @classmethod
    def of(cls, conn: Connectivity, cancel=None) -> RestParts:
        rest = identity_tskel(conn)
        rest_bone = reconstruct(rest, mode=OWNER, cancel=cancel)
        voxels = rest_voxels(rest_bone)
        parts, labels = _components(rest_bone.volume)
        piece = pieces_at(labels, rest_bone.volume, voxels[0] - np.asarray(rest_bone.origin))
        return cls(rest_bone, voxels, touching_pairs(rest), piece, len(parts))


def breakage_report(tskel: Tskel, joints: dict[str, np.ndarray], posed_joints: dict[str, np.ndarray], *,
                    posed: Reconstruction | None = None, rest: RestParts | None = None,
                    top: int = 5, cancel=None) -> BreakageReport:
    """The breakage report of one posed frame.

    Parameters
    ----------
    tskel : the posed frame
    joints, posed_joints : joint name -> rest / posed position
    posed : the frame's bone-mode reconstruction, already made, reused
    rest : :class:`RestParts` of the frame's connectivity, when the caller keeps them (made when None)
    cancel : callable, optional
        ``cancel() -> True`` raises :class:`~volanim_core.errors.Cancelled` between phases.
    """
    check = Reporter(None, cancel)
    if posed is None:
        posed = reconstruct(tskel, mode="bone", cancel=cancel)
    if rest is None:
        rest = RestParts.of(tskel.connectivity, cancel)
    hot = reconstruct(tskel, mode="hotspot", bounds=posed.bounds, cancel=cancel)
    check(0, 1)
    table, _ = transform_table(tskel)
    images = posed_images(*rest.voxels, posed, table, len(tskel.bones))
    lost = lost_voxels(rest.rest_bone, posed, tskel.matrices, rest.voxels, images)
    where, gaps = cracks(tskel, pairs=rest.pairs)
    check(0, 1)
    parts, labels = _components(posed.volume)
    specks = set()
    if rest.piece is not None:
        landed = pieces_at(labels, posed.volume, images)
        home = homes(rest.piece, landed, labels[4])  # made once: the rest voxels' sort is the report's dearest
        torn = set(torn_off(home, labels[4]).tolist())
        specks = loose_specks(torn, {k: n for n, _, k in parts}, home, rest.piece, landed, images, labels,
                              posed.volume)
    else:
        torn = {k for _, _, k in parts[1:]}
    report = BreakageReport([n for n, _, _ in parts], int(posed.stats["filled"]), int(rest.rest_bone.stats["filled"]),
                            len(lost), int(hot.stats["hotspot_max"]), float(hot.stats["hotspot_mean"]),
                            cracks=len(gaps), stumps=stumps(tskel, joints), rest_pieces=rest.pieces)
    report.lumps = frame_lumps(tskel, posed, rest, {n: posed_joints.get(n, joints[n]) for n in joints})
    names = list(joints)
    posed_pos = np.array([posed_joints.get(n, joints[n]) for n in names], np.float64) if names else None
    for size, centroid, k in parts:
        if k in torn:
            c = centroid + np.asarray(posed.origin)
            near = names[int(((posed_pos - c) ** 2).sum(1).argmin())] if names else ""
            (report.specks if k in specks else report.pieces).append((size, near, c))
    if len(gaps) and names:
        from scipy.spatial import cKDTree

        pos = np.array([joints[n] for n in names], np.float64)
        _, nearest = cKDTree(pos).query(where)
        weight = np.bincount(nearest, weights=gaps, minlength=len(names))
        counts = np.bincount(nearest, minlength=len(names))
        for k in np.argsort(-weight, kind="stable")[:top]:
            if counts[k]:
                n = names[k]
                report.joints.append(JointLoss(n, int(counts[k]), np.asarray(joints[n]),
                                               np.asarray(posed_joints.get(n, joints[n])), float(weight[k])))
    return report

