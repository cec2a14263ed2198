"""Smooth joints: blend weights per skeleton point, and each point's blended motion.

    .connect (points, dt, bone, bones)
      --links: points whose spheres hold each other's centres (never across a gap)
      --per joint (two bones a, b with linked points): a graph over a's and b's points near
        the other bone;
        geodesic distance d from the other bone's points (Dijkstra)
      --closeness f = 1 - smoothstep(d / h) per other bone, 1 for its own; h = blend x the joint's
        radius (or blend mm); weights f / sum f
      --> Skin: the blended points, their bones (own first) and weights (summing to 1)
    Skin + a frame's matrices --dual_quaternion.blended_matrices--> one matrix per blended point
      --transform_table--> bone matrices + blended ones, and each point's row in it

A point far from every joint keeps weight 1 on its own bone and moves exactly
as in a rigid frame; one in a joint's blend zone moves by the dual-quaternion
blend of its bone and the neighbour's, so the spheres along a bent joint form an
arc instead of two rigid pieces with a crack between them. Radii never change.

Why distances along the body from the *other bone's points* and not from the
joint marker: the blend is then 50/50 exactly where the attachment changes bone,
wherever the user put the joint, and a hand resting on the hip never follows it
(the two are not linked: neither sphere holds the other's centre).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from volanim_core.memo import Recent, content_key

INFLUENCES = 4  # bones per point at most: its own and three neighbours' (a fork's bone near two children)
LINK = np.sqrt(3.0)  # points this close (26-neighbours) are always linked, whatever their radii
KNN = 12  # neighbours examined per point for links (a medial curve or surface is dense: these are within ~2 voxels)
DEFAULT_BLEND = 1.0


@dataclass(frozen=True)
class Joints:
    """How bones meet: ``rigid`` (each point follows its bone) or ``smooth`` (blended near joints).

    ``blend`` is the half-width of a joint's blend zone: a multiple of the joint's radius (the
    thickest sphere where the two bones' points meet), or millimetres when ``mm``."""

    kind: str = "rigid"
    blend: float = DEFAULT_BLEND
    mm: bool = False

    def __post_init__(self):
        if self.kind not in ("rigid", "smooth"):
            raise ValueError(f"joints must be 'rigid' or 'smooth', got {self.kind!r}")
        if not (np.isfinite(self.blend) and self.blend > 0):
            raise ValueError(f"the blend width must be a positive number, got {self.blend!r}")

    @property
    def smooth(self) -> bool:
        return self.kind == "smooth"

    def text(self) -> str:
        """``rigid``, ``smooth 1`` or ``smooth 12mm``: the ``# joints:`` header and the CLI's words."""
        if not self.smooth:
            return "rigid"
        return f"smooth {self.blend:g}" + ("mm" if self.mm else "")

    @classmethod
    def parse(cls, kind: str, blend: str | float | None = None) -> Joints:
        """From the CLI's ``--joints KIND --blend W`` (``W``: a number, times the joint's radius, or ``12mm``)."""
        if blend is None:
            return cls(kind)
        text = str(blend).strip().lower()
        mm = text.endswith("mm")
        try:
            value = float(text[:-2] if mm else text)
        except ValueError:
            raise ValueError(f"--blend must be a number (times the joint's radius) or millimetres like 12mm, "
                             f"got {blend!r}") from None
        return cls(kind, value, mm)

    @classmethod
    def from_header(cls, text: str) -> Joints:
        """The value of a ``# joints:`` header line (ValueError saying what is wrong)."""
        toks = text.split()
        if not toks or len(toks) > 2:
            raise ValueError(f"expected 'rigid' or 'smooth [WIDTH]', got {text.strip()!r}")
        return cls.parse(toks[0].lower(), toks[1] if len(toks) == 2 else None)


RIGID = Joints()


@dataclass(frozen=True)
class Skin:
    """Blend weights of the points that have any: ``index`` (K,) point indices, ``influence`` (K, J)
    bone indices (the point's own bone first, -1 padding) and ``weight`` (K, J), each row summing to 1."""

    index: np.ndarray
    influence: np.ndarray
    weight: np.ndarray

    def __len__(self) -> int:
        return len(self.index)

    def take(self, order: np.ndarray, n: int) -> Skin:
        """The skin of ``points[order]`` (a permutation or subset of ``n`` points)."""
        row = np.full(n, -1, np.int64)
        row[self.index] = np.arange(len(self.index))
        picked = row[np.asarray(order)]
        keep = np.flatnonzero(picked >= 0)
        return Skin(keep.astype(np.int64), self.influence[picked[keep]], self.weight[picked[keep]])


def skin_weights(points, dt, bone, bones, joints: Joints, spacing: float = 1.0) -> Skin:
    """The blend weights of every point near a joint (:class:`Skin`); ``spacing``: mm per voxel.

    A joint here is any two bones whose points are linked (:func:`links`): a parent and its
    child, and also the torso and the upper arm where the arm's first points touch the chest's."""
    from scipy.spatial import cKDTree

    points = np.asarray(points, np.float64)
    dt = np.asarray(dt, np.float64)
    bone = np.asarray(bone, np.int64)
    i, j, _ = links(points, dt)
    cross = bone[i] != bone[j]
    pairs = np.unique(np.sort(np.column_stack([bone[i][cross], bone[j][cross]]), axis=1), axis=0)
    others: dict[int, list[tuple[int, float]]] = {}
    for a, b in pairs:
        ia, ib = np.flatnonzero(bone == a), np.flatnonzero(bone == b)
        # Euclid, a lower bound of the distance along the body. Nothing beyond the largest radius (where the
        # bones meet) or the largest blend width matters: bounded queries skip the far points (4x on the frog)
        reach = max(float(dt[ia].max()), float(dt[ib].max()), LINK)
        reach = max(reach, joints.blend / spacing if joints.mm else joints.blend * reach) + 1e-6  # the query's
        # bound is strict, and a point exactly one radius from the other bone meets it
        da = cKDTree(points[ib]).query(points[ia], distance_upper_bound=reach, workers=-1)[0]
        db = cKDTree(points[ia]).query(points[ib], distance_upper_bound=reach, workers=-1)[0]
        meet = np.concatenate([dt[ia][da <= np.maximum(dt[ia], LINK)], dt[ib][db <= np.maximum(dt[ib], LINK)]])
        h = joints.blend / spacing if joints.mm else joints.blend * float(meet.max())
        near = np.concatenate([ia[da < h], ib[db < h]])
        on_b = bone[near] == b
        f = 1.0 - _smoothstep(_geodesic(points[near], dt[near], on_b) / h)
        for k in np.flatnonzero(f > 0):
            others.setdefault(int(near[k]), []).append((int(a if on_b[k] else b), float(f[k])))
    return _skin(others, bone)


def links(points: np.ndarray, dt: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Linked point pairs ``(i, j, distance)``: among each point's nearest, those whose sphere holds
    the other's centre (or 26-neighbours). Two limbs that merely touch are never linked: their
    medial points are a radius apart from each side, further than either radius."""
    from scipy.spatial import cKDTree

    n = len(points)
    if n < 2:
        return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0)
    k = min(KNN + 1, n)
    dist, nn = cKDTree(points).query(points, k=k, workers=-1)
    i = np.repeat(np.arange(n), k - 1)
    j, d = nn[:, 1:].ravel(), dist[:, 1:].ravel()
    ok = (j < n) & (d > 0)
    i, j, d = i[ok], j[ok], d[ok]
    ok = d <= np.maximum(np.maximum(dt[i], dt[j]), LINK)
    return i[ok], j[ok], d[ok]


def _smoothstep(t: np.ndarray) -> np.ndarray:
    t = np.clip(t, 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def _geodesic(points: np.ndarray, dt: np.ndarray, side: np.ndarray) -> np.ndarray:
    """For each point, the length of the shortest linked path (:func:`links`) to a point of the
    other ``side`` (inf when none: a gap)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import dijkstra

    n = len(points)
    out = np.full(n, np.inf)
    i, j, d = links(points, dt)
    graph = coo_matrix((d, (i, j)), shape=(n, n)).tocsr()
    for mine in (side, ~side):
        src = np.flatnonzero(~mine)
        if len(src) and mine.any():
            out[mine] = dijkstra(graph, directed=False, indices=src, min_only=True)[mine]
    return out


def _skin(others: dict[int, list[tuple[int, float]]], bone: np.ndarray) -> Skin:
    """Weights from closeness: the own bone counts 1, another bone ``1 - smoothstep(d / h)``, normalised.

    Two bones meet 50/50 at their seam and a point ``h`` away is its own bone's alone; where three
    meet (the armpit: torso, clavicle, upper arm) each seam point is a third of each, so neighbouring
    points of different bones get nearly the same blend from every side."""
    index = np.array(sorted(others), np.int64)
    influence = np.full((len(index), INFLUENCES), -1, np.int64)
    weight = np.zeros((len(index), INFLUENCES))
    for r, i in enumerate(index):
        pairs = sorted(others[int(i)], key=lambda p: -p[1])[:INFLUENCES - 1]
        total = 1.0 + sum(f for _, f in pairs)
        influence[r, 0], weight[r, 0] = bone[i], 1.0 / total
        for c, (o, f) in enumerate(pairs, start=1):
            influence[r, c], weight[r, c] = o, f / total
    return Skin(index, influence, weight)


_RECENT = Recent(4)


def cached_skin(conn, joints: Joints | None = None) -> Skin:
    """:func:`skin_weights` of a connectivity (its own ``joints`` unless given), remembered for the last few:
    every frame of a clip and every studio preview shares one set (the key hashes what they depend on)."""
    joints = joints or conn.joints
    spacing = float(conn.geometry.spacing[0])
    key = content_key(conn.points, conn.dt, conn.bone, [[*b.proximal, *b.distal] for b in conn.bones],
                      text=f"{joints.text()} {spacing!r}")
    return _RECENT.get(key, lambda: skin_weights(conn.points, conn.dt, conn.bone, conn.bones, joints, spacing))


def blended_with(tskel, idx: np.ndarray, along: np.ndarray) -> np.ndarray:
    """Whether smooth joints give point ``idx[k]`` some weight on bone ``along[k]``: then it is part of
    that joint's bend, the body stretching continuously between the two bones, not a piece left behind
    (the breakage report's stumps)."""
    out = np.zeros(len(idx), bool)
    if not tskel.joints.smooth or not len(tskel.skin):
        return out
    skin = tskel.skin
    row = np.full(len(tskel), -1, np.int64)
    row[skin.index] = np.arange(len(skin))
    r = row[idx]
    has = r >= 0
    out[has] = (skin.influence[r[has]][:, 1:] == along[has, None]).any(axis=1)
    return out


def transform_table(tskel) -> tuple[np.ndarray, np.ndarray]:
    """``(table, row)``: the matrices a frame's points move by and each point's row in ``table``.

    Rigid joints: the bone matrices and the bones. Smooth: the bone matrices, then one blended
    matrix per point in a blend zone (:func:`cached_skin`); a point with weight 1 keeps its bone's
    row, so it moves exactly as in the rigid frame."""
    mats = np.asarray(tskel.matrices, np.float64)
    if not tskel.joints.smooth or not len(tskel):
        return mats, np.asarray(tskel.bone, np.int64)
    from volanim_core.rig.dual_quaternion import blended_matrices

    skin = tskel.skin
    row = np.asarray(tskel.bone, np.int64).copy()
    if not len(skin):
        return mats, row
    names = [b.label for b in tskel.bones]
    row[skin.index] = len(mats) + np.arange(len(skin))
    return np.concatenate([mats, blended_matrices(mats, skin.influence, skin.weight, names)]), row
