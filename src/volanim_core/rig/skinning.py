"""Smooth joints: blend weights per skeleton point, and each point's blended motion.

    .connect (points, dt, bone, bones)
      --links: points whose spheres hold each other's centres (never across a gap)
      --per bone k that meets another: its reach along the body (Dijkstra over the links from its
        points): g_k = 1 for one blend width h_k (blend x its thickest sphere, or blend mm), fading to 0
        at 2 h_k; only points of bones at most HOPS joints from k (bone_hops)
      --per reached point: w_k = g_k * exp(-(d_k / tau_k)^2 / 2), d_k its distance to bone k's segment,
        tau_k = h_k / SHARPNESS, the own bone with g = 1; normalised
      --heat diffusion over the links, DIFFUSION steps, of the blended points only
      --one-voxel spheres (rig/thin_spheres.py): a speck group, and a group of one-voxel points lying on
        one thicker sphere of their bone, move as the thicker sphere that holds them best
      --_with_sheets: the blended points on a medial sheet, and their links' rest lengths
      --> Skin: the blended points, their bones (own first) and weights (summing to 1)
    Skin + a frame's matrices --dual_quaternion.blended_matrices--> one matrix per blended point
      --transform_table--> bone matrices + blended ones, and each point's row in it
    Skin + a frame's posed centres --posed_radii--> the radii the frame is grown with

A point far from every joint keeps weight 1 on its own bone and moves exactly
as in a rigid frame; one in a joint's blend zone moves by the dual-quaternion
blend of the bones there, so the spheres along a bent joint form an arc instead
of two rigid pieces with a crack between them.

Radii stay, except on a stretched medial sheet. Blending turns neighbouring
points by different angles; along a medial curve (a round limb) that bends the
curve and the limb keeps its thickness. A medial sheet whose weights change
across it (mannequin-large's crotch, between the thighs, with thigh weights 0.2
at the midline to 0.95 at the thigh) fans out: its area grows several times at a
bent hip while its spheres keep their radii, and the body grew 4.6 % at 120
degrees. So a blended sphere on a sheet thins by the mean stretch of its links
(a sheet's volume is its area times its thickness), to no less than
``THIN_FLOOR`` of its radius, so neighbours still overlap and nothing tears.

Why the weights come from the bones' segments and not from where the
attachment changes bone: a seam can run along a limb (mannequin-large's torso
ends 68 voxels below the hip, beside the thigh). Blending by the distance from
the seam dragged the whole upper thigh with the torso (far-thigh Dice 0.90 at a
120-degree hip). Blending by the distance from each segment keeps the thigh
rigid and makes the torso's points beside it go with it. The reach along the
body keeps the gaps: a hand resting on the hip is not linked to it, so the hip
never reaches the hand. The diffusion step is for the armpit's crease, where a
limb lies against the torso and the segment distances change fastest.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from volanim_core.memo import Recent, content_key
from volanim_core.rig.skin import INFLUENCES, Skin
from volanim_core.rig.thin_spheres import SPECK, with_thin_spheres

LINK = np.sqrt(3.0)  # points this close (26-neighbours) are always linked, whatever their radii
KNN = 12  # neighbours examined per point for links (a medial curve or surface is dense: these are within ~2 voxels)
DEFAULT_BLEND = 1.0
PLATEAU = 2.0  # a bone reaches fully (PLATEAU - 1) blend widths along the body from its points, then fades out
SHARPNESS = 1.25  # tau = h / SHARPNESS: how fast a bone's weight falls with distance from its segment
MIN_WEIGHT = 0.005  # smaller weights are dropped (and the rest renormalised): far points move exactly rigidly
# A bone blends only with bones at most this many joints away (bone_hops): the torso and an upper arm are 2
# (across the clavicle); an ear's tip curled back onto the ear is 4 from it and only touches it there.
HOPS = 2
DIFFUSION = 8  # smoothing steps over the links (heat diffusion, as Bender does over voxels)
# A point is on a medial sheet when its links spread over a plane: the middle eigenvalue of the scatter
# of their directions (trace 1) is 0 along a curve and 0.5 on a flat sheet. On mannequin-large (measured
# with a prototype) 0.1 and 0.2 thin the same (hip 120: 2.7 % above rest), 0.3 too little (3.1 %).
SHEET = 0.2
# A stretched sheet's spheres keep at least this much of their radius: 0.7 tore a 3-voxel piece off
# mannequin-large's pelvis at a 120-degree hip; 0.75 tore nothing at any angle.
THIN_FLOOR = 0.75
STRETCH_TOL = 1e-6  # a sheet stretched less than this keeps its radii exactly (the rest frame; snapping)


@dataclass(frozen=True)
class Joints:
    """How bones meet: ``rigid`` (each point follows its bone) or ``smooth`` (blended near joints).

    ``blend`` sets how far each bone's blend reaches: a multiple of the bone's thickness (its
    thickest sphere), or millimetres when ``mm``."""

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
        """From the CLI's ``--joints KIND --blend W`` (``W``: a number, times each bone's thickness, or ``12mm``)."""
        if blend is None:
            return cls(kind)
        text = str(blend).strip().lower()
        mm = text.endswith("mm")
        try:
            value = float(text[:-2] if mm else text)
        except ValueError:
            raise ValueError(f"--blend must be a number (times the bones' thickness) or millimetres like 12mm, "
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


def skin_weights(points, dt, bone, bones, joints: Joints, spacing: float = 1.0) -> Skin:
    """The blend weights of every point near a joint (:class:`Skin`); ``spacing``: mm per voxel.

    Each bone ``k`` that meets another (their points are linked, :func:`links`) reaches along the body
    (Dijkstra over the links from its points) fully for one blend width ``h_k`` and fades out over the
    next (``g_k``: 1 .. 0), over the points of bones at most ``HOPS`` joints from it. A reached point
    weighs every bone that reaches it, its own with ``g = 1``, by ``g_k * exp(-(d_k / tau_k)^2 / 2)``:
    ``d_k`` its distance to the bone's segment, ``tau_k = h_k / SHARPNESS`` (so a thick bone's points
    are not taken by a thin neighbour's segment); normalised, smoothed by heat diffusion (:func:`_diffused`),
    weights under ``MIN_WEIGHT`` dropped."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import dijkstra

    points = np.asarray(points, np.float64)
    dt = np.asarray(dt, np.float64)
    bone = np.asarray(bone, np.int64)
    n = len(points)
    i, j, d = links(points, dt)
    cross = bone[i] != bone[j]
    thickness = np.full(len(bones), LINK)  # each bone's thickest sphere
    np.maximum.at(thickness, bone, dt)
    h = np.full(len(bones), joints.blend / spacing) if joints.mm else joints.blend * thickness
    graph = coo_matrix((d, (i, j)), shape=(n, n)).tocsr()
    reached = []  # per bone: the points of other bones it reaches, and how far (g)
    near = bone_hops(bones) <= HOPS
    for k in np.unique(np.concatenate([bone[i][cross], bone[j][cross]])):
        geo = dijkstra(graph, directed=False, indices=np.flatnonzero(bone == k), min_only=True, limit=PLATEAU * h[k])
        p = np.flatnonzero(np.isfinite(geo) & (bone != k) & near[k][bone])
        g = 1.0 - _smoothstep((geo[p] - (PLATEAU - 1) * h[k]) / h[k])
        reached.append((p[g > 0], np.full(int((g > 0).sum()), k), g[g > 0]))
    skin = with_thin_spheres(_weights(reached, points, bone, bones, h / SHARPNESS, graph), points, dt, bone, graph)
    return _with_sheets(skin, points, dt, (i, j, d))


def _with_sheets(skin: Skin, points, dt, linked) -> Skin:
    """The skin with its blended points that lie on a medial sheet (their links spread over a plane:
    the middle eigenvalue of their directions' scatter at least ``SHEET``; one-voxel spheres excluded),
    and the links of those points with their rest lengths, once each: what :func:`posed_radii` reads."""
    i, j, d = linked
    n = len(points)
    if not len(skin) or not len(i):
        return skin
    row = np.full(n, -1, np.int64)
    row[skin.index] = np.arange(len(skin))
    mine = row[i] >= 0
    u = (points[j[mine]] - points[i[mine]]) / d[mine, None]
    scatter = np.zeros((len(skin), 3, 3))
    np.add.at(scatter, row[i[mine]], u[:, :, None] * u[:, None, :])
    ev = np.linalg.eigvalsh(scatter)
    spread = ev[:, 1] / np.maximum(ev.sum(axis=1), 1e-12)
    sheet = skin.index[(spread >= SHEET) & (dt[skin.index] >= SPECK)]
    on = np.zeros(n, bool)
    on[sheet] = True
    touch = on[i] | on[j]
    a, b = np.minimum(i[touch], j[touch]), np.maximum(i[touch], j[touch])
    key = np.unique(a * n + b)  # a link found from both ends counts once
    pairs = np.column_stack([key // n, key % n])
    rest = np.linalg.norm(points[pairs[:, 0]] - points[pairs[:, 1]], axis=1)
    return Skin(skin.index, skin.influence, skin.weight, sheet, pairs, rest)


def posed_radii(tskel, centres: np.ndarray) -> np.ndarray:
    """The radii a frame grows its spheres with: ``tskel.dt``, except on a stretched medial sheet of
    smooth joints, where a sphere's radius is divided by the mean stretch of its links (posed length /
    rest length; ``centres``: the frame's posed centres), never below ``THIN_FLOOR`` of it and never
    above it (a sheet squeezed on the inside of a bend keeps its radii). Why: the module's docstring."""
    dt = tskel.dt
    if not tskel.joints.smooth or not len(tskel) or not len(tskel.skin.sheet):
        return dt
    skin = tskel.skin
    a, b = skin.pairs[:, 0], skin.pairs[:, 1]
    stretch = np.linalg.norm(centres[a] - centres[b], axis=1) / skin.rest
    n = len(dt)
    total = np.bincount(a, stretch, n) + np.bincount(b, stretch, n)
    count = np.bincount(a, minlength=n) + np.bincount(b, minlength=n)
    mean = total[skin.sheet] / np.maximum(count[skin.sheet], 1)
    if not (mean > 1.0 + STRETCH_TOL).any():
        return dt
    out = dt.astype(np.float64, copy=True)
    out[skin.sheet] *= np.where(mean > 1.0 + STRETCH_TOL, np.maximum(1.0 / mean, THIN_FLOOR), 1.0)
    return out


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


def bone_hops(bones) -> np.ndarray:
    """(B, B) how many joints apart two bones are: 0 itself, 1 sharing a joint (a parent and its child,
    two siblings), 2 their neighbours' (the torso and an upper arm, across the clavicle); bones with no
    chain of shared joints between them a large number."""
    from scipy.sparse.csgraph import shortest_path

    ends = np.array([[b.proximal, b.distal] for b in bones], np.float64).reshape(len(bones), 2, 3)
    meet = (np.abs(ends[:, None, :, None] - ends[None, :, None, :]).max(-1) < 1e-6).any(axis=(2, 3))
    np.fill_diagonal(meet, False)
    hops = shortest_path(meet.astype(float), unweighted=True, directed=False)
    return np.where(np.isfinite(hops), hops, len(bones) + 1)


def segment_distance(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Each point's distance to the segment from ``a`` to ``b`` (a bone between its two joints)."""
    ab = np.asarray(b, np.float64) - a
    t = np.clip((points - a) @ ab / max(float(ab @ ab), 1e-12), 0.0, 1.0)
    return np.linalg.norm(points - (a + t[:, None] * ab), axis=1)


def _smoothstep(t: np.ndarray) -> np.ndarray:
    t = np.clip(t, 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def _weights(reached: list, points: np.ndarray, bone: np.ndarray, bones, tau: np.ndarray, graph) -> Skin:
    """Normalised ``g_k * exp(-(d_k / tau_k)^2 / 2)`` of every reached point (own bone first, ``g = 1``).

    A function of the position alone (and of which bones reach it), so two neighbouring points of
    different bones get nearly the same weights: a seam that runs along a limb (a torso's lowest points
    beside the thigh) does not blend the limb, the torso's points that lie along the thigh go with the
    thigh, and the thigh away from the joint stays rigid. ``d_k / tau_k`` compares distances in bone
    thicknesses: two bones share a point equally where it is as many of its thicknesses from each."""
    if not reached:
        return Skin(np.zeros(0, np.int64), np.full((0, INFLUENCES), -1, np.int64), np.zeros((0, INFLUENCES)))
    p, k, g = (np.concatenate(c) for c in zip(*reached))
    index, at = np.unique(p, return_inverse=True)
    m = len(index)
    reach = np.zeros(m)
    np.maximum.at(reach, at, g)
    at = np.concatenate([np.arange(m), at])
    k = np.concatenate([bone[index], k])
    d = np.empty(len(k))
    for b in np.unique(k):
        sel = k == b
        d[sel] = segment_distance(points[index[at[sel]]], bones[b].proximal, bones[b].distal)
    logw = np.log(np.concatenate([np.ones(m), g])) - 0.5 * (d / tau[k]) ** 2
    top = np.full(m, -np.inf)
    np.maximum.at(top, at, logw)
    w = np.exp(logw - top[at])
    total = np.zeros(m)
    np.add.at(total, at, w)
    w /= total[at]
    at, k, w = _diffused(graph, index, reach, at, k, w, bone, len(bones))
    # per point: own first, then the others by weight, at most INFLUENCES and none under MIN_WEIGHT
    order = np.lexsort((-w, k != bone[index[at]], at))
    at, k, w = at[order], k[order], w[order]
    col = np.arange(len(at)) - np.searchsorted(at, np.arange(m))[at]
    keep = (col < INFLUENCES) & ((col == 0) | (w >= MIN_WEIGHT))
    influence = np.full((m, INFLUENCES), -1, np.int64)
    weight = np.zeros((m, INFLUENCES))
    influence[at[keep], col[keep]] = k[keep]
    weight[at[keep], col[keep]] = w[keep]
    weight /= weight.sum(1, keepdims=True)
    blended = weight[:, 0] < 1.0
    return Skin(index[blended], influence[blended], weight[blended])


def _diffused(graph, index, reach, at, k, w, bone, n_bones):
    """``DIFFUSION`` steps of heat diffusion of the weights over the links: each blended point moves
    towards the mean of itself and its linked neighbours, by as much as the other bones reach it
    (``reach``: their largest ``g``, so the zone's fading rim stays continuous with the rigid points
    outside it); every point already on one bone keeps its weights (the boundary), so the blend is
    smoothed where it is steep (the armpit's crease) but never widened. Rows keep summing to 1, and
    nothing crosses a gap (no links there)."""
    from scipy.sparse import csr_matrix, identity

    n = graph.shape[0]
    W = np.zeros((n, n_bones))
    W[np.arange(n), bone] = 1.0
    W[index] = 0.0
    np.add.at(W, (index[at], k), w)
    free = index[W[index].max(1) < 1.0 - MIN_WEIGHT]  # the blended ones: the rest are settled, on one bone
    step = np.zeros(n)
    step[index] = reach
    step = step[free, None]
    a = (graph + graph.T).tocsr()
    a.data[:] = 1.0
    a = (a + identity(n, format="csr"))[free]
    a = csr_matrix(a.multiply(1.0 / np.asarray(a.sum(1))))
    for _ in range(DIFFUSION):
        W[free] += step * (a @ W - W[free])
    sub = W[index]
    at, k = np.nonzero(sub > 0)
    return at, k, sub[at, k]


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
