"""Templates for auto-rig: a humanoid and a quadruped, matched to a curve tree by its ends.

    ends of the tree --trim to the template's limb count (shortest branches go first)-->
    every way to pick the unpaired ends (head, tail) and two pairs of limbs
      --cost: how far the pairs are from mirror images, and the unpaired ends from the mirror plane-->
    the best: the pair that meets the head nearer the head is the arms (front legs);
    L_ is the pair's end towards +x in physical space (LPS: the patient's left)
      --joints-->  PELVIS / CHEST where the pairs meet, NECK at the narrowest point below the head,
                   SHOULDER / HIP at the limb's first bend, ANKLE at its last, ELBOW / KNEE / WRIST
                   at anthropometric fractions of the limb (Drillis & Contini 1966), a wrist moved
                   to where the limb thins most near it; tips extended to the body's surface

The humanoid's names and root order are the mannequin's (``samples.mannequin_bones``), so a proposal
drops into every tool that knows those names (BVH retargeting, the sample keys).
"""

from __future__ import annotations

from itertools import combinations

import numpy as np

from volanim_core.rig import landmarks
from volanim_core.rig.bones import Bone, BoneSkeleton
from volanim_core.rig.curve_skeleton import NotRiggable
from volanim_core.rig.tree_walks import Tree, splits

SYMMETRY = 0.15  # a pairing is symmetric when its mirror error is below this fraction of the body's size
ELBOW, WRIST = 0.42, 0.76  # upper arm 0.186 H, forearm 0.146 H, hand 0.108 H (Drillis & Contini)
KNEE = 0.5  # thigh 0.245 H, shank 0.246 H
ARM_JOINTS, LEG_JOINTS = ("SHOULDER", "ELBOW", "WRIST", "FINGERS"), ("HIP", "KNEE", "ANKLE", "TOE")
FORELEG_JOINTS, HINDLEG_JOINTS = ("SHOULDER", "ELBOW", "WRIST", "FRONT_TOE"), ("HIP", "KNEE", "HOCK", "HIND_TOE")
EXTRA = 0.5  # auto: ends beyond the template's are spurs only if shorter than this x its shortest limb


def trimmed(tree: Tree, ends: int, removed: list[float] | None = None) -> Tree:
    """The tree with its shortest leaf branches removed until ``ends`` ends are left (their lengths are
    appended to ``removed``)."""
    adj = [list(a) for a in tree.adj]
    t = tree.with_adjacency(adj)  # edited in place below, before any path is walked on it
    while len(t.ends()) > ends:
        best = None
        for e in t.ends():
            branch = t.branch(e)
            length = float(t.length(branch)[-1])
            if best is None or length < best[0]:
                best = (length, branch[:-1])  # the fork stays
        if removed is not None:
            removed.append(best[0])
        for a in best[1]:
            for b in adj[a]:
                adj[b].remove(a)
            adj[a] = []
    return t


def _samples(tree: Tree, end: int, other: int, count: int = 8) -> np.ndarray:
    """``count`` points along the branch from ``end`` towards the tree's meeting point with ``other``,
    at equal fractions of its length, so a limb and its twin can be compared point by point."""
    path = tree.path(end, other)
    path = path[: max(2, len(path) // 2)]
    s = tree.length(path)
    return np.array([tree.p[path[int(np.argmin(np.abs(s - f * s[-1])))]] for f in np.linspace(0, 1, count)])


def _mirror_cost(tree: Tree, pairs, singles) -> tuple[float, np.ndarray]:
    p = tree.p
    limbs = [(_samples(tree, a, b), _samples(tree, b, a)) for a, b in pairs]
    diffs = np.concatenate([la - lb for la, lb in limbs])
    diffs = diffs[np.linalg.norm(diffs, axis=1) > 1e-9]
    ref = diffs[np.argmax(np.linalg.norm(diffs, axis=1))]
    n = np.sum([d * (1 if d @ ref >= 0 else -1) for d in diffs], axis=0)  # long differences weigh most
    n = n / (np.linalg.norm(n) or 1)
    if n @ tree.left < 0:
        n = -n
    centre = np.concatenate([(la + lb) / 2 for la, lb in limbs] + [p[list(singles)]]).mean(axis=0)

    def mirror(x):
        return x - 2 * ((x - centre) @ n)[..., None] * n

    err = [np.linalg.norm(mirror(la) - lb, axis=1).mean() for la, lb in limbs] + \
        [2 * abs((p[s] - centre) @ n) for s in singles]
    return float(np.mean(err)), n


def _match(tree: Tree, singles: int):
    """The best (cost, singles, pairs, mirror normal) with ``singles`` unpaired ends and two pairs."""
    ends = tree.ends()
    size = max(np.linalg.norm(tree.p[a] - tree.p[b]) for a, b in combinations(ends, 2))
    best = None
    for single in combinations(ends, singles):
        rest = [e for e in ends if e not in single]
        a = rest[0]
        for b in rest[1:]:
            other = [e for e in rest[1:] if e != b]
            pairs = [(a, b), (other[0], other[1])]
            cost, n = _mirror_cost(tree, pairs, single)
            if best is None or cost / size < best[0]:
                best = (cost / size, single, pairs, n)
    return best


def _hops(tree: Tree, a: int, b: int) -> float:
    return float(tree.length(tree.path(a, b))[-1])


def _at(tree: Tree, path, fraction: float, start: float = 0.0, stop: float | None = None) -> int:
    """Index in ``path`` of the node at ``fraction`` of the arc between arc lengths start and stop."""
    s = tree.length(path)
    stop = s[-1] if stop is None else stop
    return int(np.argmin(np.abs(s - (start + fraction * (stop - start)))))


def _bend(tree: Tree, path, lo: int, hi: int) -> int:
    """The node of ``path[lo:hi+1]`` that strays furthest from its chord."""
    hi = max(hi, lo + 2)
    k = splits(tree.p[path[lo:hi + 1]], tree.r[path[lo:hi + 1]], count=1)
    return lo + (k[0] if k else (hi - lo) // 2)


def _thinning(tree: Tree, path, lo: int, hi: int, default: int) -> int:
    """Where the radius drops most across a few nodes within ``path[lo:hi]`` (a wrist); ``default`` if
    it drops by less than a voxel."""
    r = tree.r[path]
    w = 3
    best, k_best = 1.0, default
    for k in range(max(lo, w), min(hi, len(path) - w)):
        drop = r[k - w] - r[k + w]
        if drop > best:
            best, k_best = drop, k
    return k_best


def _limb(tree: Tree, start: int, end: int, fractions, last_bend: bool, thin_at: int | None = None,
          root: np.ndarray | None = None):
    """Joint positions along the limb from node ``start`` to end ``end``: first bend (or ``root``, a
    joint read off the body), interior joints at ``fractions`` of the rest (or the last bend for the
    final one when ``last_bend``), the tip."""
    path = tree.path(start, end)
    n = len(path)
    first = _bend(tree, path, 0, max(2, int(0.45 * n)))
    s = tree.length(path)
    tip = tree.tip(end, inset=True)
    total = s[-1] + np.linalg.norm(tip - tree.p[end])
    s0 = s[first]
    if root is not None:  # the arc starts where the root lies along the limb, before or after the bend
        down = tree.p[path[min(first + 3, n - 1)]] - tree.p[path[first]]
        s0 -= (tree.p[path[first]] - root) @ (down / (np.linalg.norm(down) or 1))
    inner = [_at(tree, path, f, s0, total) for f in fractions]
    if last_bend:
        inner[-1] = _bend(tree, path, max(first + 2, int(0.6 * n)), n - 1)
        inner[:-1] = [_at(tree, path, f, s0, s[inner[-1]]) for f in fractions[:-1]]
    if thin_at is not None:
        inner[thin_at] = _thinning(tree, path, _at(tree, path, 0.65, s0, total),
                                   _at(tree, path, 0.92, s0, total), inner[thin_at])
    head = _corner(tree.p[path], first) if root is None else root
    return [head] + [tree.p[path[k]] for k in inner] + [tip]


def _section(tree: Tree, start: int, end: int, lo: float, hi: float) -> landmarks.Line | None:
    """The straight line through the nodes between fractions ``lo`` and ``hi`` of the path's length
    after its first bend (an upper arm, a thigh), pointing away from ``start``."""
    path = tree.path(start, end)
    s = tree.length(path)
    s0 = s[_bend(tree, path, 0, max(2, int(0.45 * len(path))))]
    pts = tree.p[path][(s >= s0 + lo * (s[-1] - s0)) & (s <= s0 + hi * (s[-1] - s0))]
    if len(pts) < 3:
        return None
    centre, axis = _line(pts)
    return centre, axis if axis @ (pts[-1] - pts[0]) >= 0 else -axis


def _line(pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    centre = pts.mean(axis=0)
    return centre, np.linalg.svd(pts - centre)[2][0]


def _corner(xyz: np.ndarray, k: int) -> np.ndarray:
    """Where the straight runs before and after node ``k`` meet (the midpoint of their closest points):
    a shoulder where the clavicle's line meets the upper arm's, not on the rounded curve between."""
    before, after = xyz[max(0, k - max(3, k)): k + 1], xyz[k: k + max(3, (len(xyz) - k) // 3)]
    if len(before) < 3 or len(after) < 3:
        return xyz[k]
    (a, u), (b, v) = _line(before), _line(after)
    w, uv = a - b, u @ v
    if abs(1 - uv * uv) < 1e-3:  # parallel runs: no corner
        return xyz[k]
    s = (uv * (w @ v) - (w @ u)) / (1 - uv * uv)
    t = ((w @ v) - uv * (w @ u)) / (1 - uv * uv)
    point = (a + s * u + b + t * v) / 2
    return point if np.linalg.norm(point - xyz[k]) < 0.5 * np.linalg.norm(xyz[-1] - xyz[0]) else xyz[k]


def _at_level(tree: Tree, start: int, end: int, level: np.ndarray, up: np.ndarray) -> np.ndarray:
    """Where the line of a limb's upper part (its second fifth to its half) meets the plane through
    ``level`` across ``up``: a hip level with the pelvis, however the thinned curve rounds the corner."""
    path = tree.path(start, end)
    s = tree.length(path)
    pts = tree.p[path][(s >= 0.2 * s[-1]) & (s <= 0.5 * s[-1])]
    if len(pts) < 2:
        return tree.p[path[len(path) // 4]]
    line = _line(pts)
    up = up / np.linalg.norm(up)
    if abs(line[1] @ up) < landmarks.STEEP:  # a limb across the spine never reaches that level
        return tree.p[path[len(path) // 4]]
    return landmarks.at_level(line, up, level @ up)


def _limb_bones(parent: str, joints, names) -> list[Bone]:
    """The left limb's chain from ``parent`` through ``joints``, bone k named ``names[k]``, then the right's."""
    out = []
    for side in ("L_", "R_"):
        ends = [parent] + [side + j for j in joints]
        out += [Bone(a, b, side + n) for a, b, n in zip(ends, ends[1:], names)]
    return out


def _humanoid(tree: Tree, match) -> BoneSkeleton:
    _, (head,), pairs, n = match
    meets = [tree.median(a, b, head) for a, b in pairs]
    arms_first = _hops(tree, meets[0], head) <= _hops(tree, meets[1], head)
    (arms, m_arms), (legs, m_legs) = ((pairs[0], meets[0]), (pairs[1], meets[1])) if arms_first \
        else ((pairs[1], meets[1]), (pairs[0], meets[0]))
    if m_arms == m_legs:
        raise NotRiggable("the arms and legs leave the body at one point: no spine to place")

    neck_path = tree.path(m_arms, head)
    r = tree.r[neck_path]
    widest = len(r) // 2 + int(np.argmax(r[len(r) // 2:]))
    narrowest = int(np.flatnonzero(r[: widest + 1] <= r[: widest + 1].min() + 0.5)[0])
    k_neck = _at(tree, neck_path, 0.5, 0.0, tree.length(neck_path)[narrowest])
    j = {"PELVIS": tree.p[m_legs], "NECK": tree.p[neck_path[k_neck]], "HEAD": tree.tip(head)}
    hands = sorted(arms, key=lambda e: -(tree.p[e] @ n))
    feet = sorted(legs, key=lambda e: -(tree.p[e] @ n))
    up = (j["NECK"] - j["PELVIS"]) / (np.linalg.norm(j["NECK"] - j["PELVIS"]) or 1)
    for side, hand, foot in zip(("L_", "R_"), hands, feet):
        arm = _limb(tree, m_arms, hand, (ELBOW, WRIST), last_bend=False, thin_at=1)
        leg = _limb(tree, m_legs, foot, (KNEE, 1.0), last_bend=True)
        leg[0] = _at_level(tree, m_legs, foot, j["PELVIS"], up)
        leg[1] = leg[0] + KNEE * (leg[2] - leg[0])  # between the moved hip and the ankle
        j.update(zip((side + k for k in ARM_JOINTS), arm))
        j.update(zip((side + k for k in LEG_JOINTS), leg))
    if tree.curve.body is not None:
        _from_body(tree, j, (m_arms, hands), (m_legs, feet), up, n)
    bones = [Bone("PELVIS", "NECK", "SPINE"), Bone("NECK", "HEAD", "HEAD"),
             *_limb_bones("NECK", ARM_JOINTS, ("CLAVICLE", "UPPERARM", "FOREARM", "HAND")),
             *_limb_bones("PELVIS", LEG_JOINTS, ("PELVIS", "THIGH", "SHIN", "FOOT"))]
    return BoneSkeleton(j, bones)


def _from_body(tree: Tree, j: dict, arms, legs, up: np.ndarray, n: np.ndarray) -> None:
    """Shoulders, hips and the pelvis moved, in place, to where the body's outline puts them
    (:mod:`~volanim_core.rig.landmarks`); each stays the curve's guess where the body shows no landmark."""
    body, spine = tree.curve.body.outline(), (j["PELVIS"], up)
    armpits = []
    for side, hand in zip(("L_", "R_"), arms[1]):
        line = _section(tree, arms[0], hand, 0.08, 0.35)
        found = line and landmarks.shoulder(body, line, spine, up, j[side + "ELBOW"] @ up, j["NECK"] @ up)
        if found:
            armpits.append(found[1])
            arm = _limb(tree, arms[0], hand, (ELBOW, WRIST), last_bend=False, thin_at=1, root=found[0])
            j.update(zip((side + k for k in ARM_JOINTS), arm))
    thighs = [_section(tree, legs[0], foot, 0.1, 0.4) for foot in legs[1]]
    if None in thighs:
        return
    top = np.mean(armpits) if armpits else tree.p[arms[0]] @ up
    level = landmarks.hip_level(body, tuple(thighs), spine, n, up,
                                max(j["L_KNEE"] @ up, j["R_KNEE"] @ up), top)
    if level is None:
        return
    j["PELVIS"] = landmarks.at_level(spine, up, level)
    for side, thigh in zip(("L_", "R_"), thighs):
        j[side + "HIP"] = landmarks.at_level(thigh, up, level)
        j[side + "KNEE"] = j[side + "HIP"] + KNEE * (j[side + "ANKLE"] - j[side + "HIP"])


def _quadruped(tree: Tree, match) -> BoneSkeleton:
    _, singles, pairs, n = match
    # the head is the unpaired end nearest a pair's meeting point; the tail, if any, the other
    meets = [[tree.median(a, b, s) for s in singles] for a, b in pairs]
    dist = [[_hops(tree, meets[i][k], singles[k]) for k in range(len(singles))] for i in range(2)]
    i_front, k_head = min(((i, k) for i in range(2) for k in range(len(singles))), key=lambda ik: dist[ik[0]][ik[1]])
    head = singles[k_head]
    front, hind = pairs[i_front], pairs[1 - i_front]
    m_front, m_hind = tree.median(*front, head), tree.median(*hind, head)
    if m_front == m_hind:
        raise NotRiggable("the front and hind legs leave the body at one point: no spine to place")

    j = {"PELVIS": tree.p[m_hind], "CHEST": tree.p[m_front], "HEAD": tree.tip(head)}
    bones = [Bone("PELVIS", "CHEST", "SPINE"), Bone("CHEST", "HEAD", "NECK")]
    for side, pick in (("L_", 0), ("R_", 1)):
        paw = sorted(front, key=lambda e: -(tree.p[e] @ n))[pick]
        foot = sorted(hind, key=lambda e: -(tree.p[e] @ n))[pick]
        j.update(zip((side + k for k in FORELEG_JOINTS),
                     _limb(tree, m_front, paw, (0.45, 1.0), last_bend=True)))
        j.update(zip((side + k for k in HINDLEG_JOINTS),
                     _limb(tree, m_hind, foot, (0.45, 1.0), last_bend=True)))
    bones += _limb_bones("CHEST", FORELEG_JOINTS, ("SCAPULA", "HUMERUS", "RADIUS", "FRONT_FOOT"))
    bones += _limb_bones("PELVIS", HINDLEG_JOINTS, ("PELVIS", "FEMUR", "TIBIA", "HIND_FOOT"))
    if len(singles) == 2:
        tail = singles[1 - k_head]
        j["TAIL"] = tree.tip(tail)
        bones.append(Bone("PELVIS", "TAIL", "TAIL"))
    return BoneSkeleton(j, bones)


def _legs_vs_spine(bones: BoneSkeleton, top: str) -> float:
    """Cosine between the spine (PELVIS -> top) and the mean leg (hip -> toe)."""
    j = bones.joints
    spine = j[top] - j["PELVIS"]
    toe = "TOE" if "L_TOE" in j else "HIND_TOE"
    leg = sum(j[s + toe] - j[s + "HIP"] for s in ("L_", "R_"))
    return float(spine @ leg / (np.linalg.norm(spine) * np.linalg.norm(leg) or 1))


def fit(tree: Tree, template: str) -> BoneSkeleton:
    """``template``'s bones placed on the tree, however well it fits (the user asked for it)."""
    need = 5 if template == "humanoid" else 6 if len(tree.ends()) >= 6 else 5
    if len(tree.ends()) < 5:
        raise NotRiggable(f"a {template} needs 5 limb ends (head and four limbs); the skeleton has "
                          f"{len(tree.ends())}: " + ", ".join(f"({', '.join(f'{v:.0f}' for v in tree.p[e])})"
                                                             for e in tree.ends()))
    t = trimmed(tree, need)
    match = _match(t, need - 4)
    return _humanoid(t, match) if template == "humanoid" else _quadruped(t, match)


def best_fit(tree: Tree) -> tuple[BoneSkeleton, str, str] | None:
    """The template that fits (symmetric limbs; legs pointing away from the head for a humanoid,
    across the spine for a quadruped), with why; None when neither does."""
    ends = len(tree.ends())
    if ends < 5:
        return None
    for template, singles in (("humanoid", 1), ("quadruped", 2), ("quadruped", 1)):
        if template == "quadruped" and singles == 2 and ends < 6:
            continue
        removed: list[float] = []
        t = trimmed(tree, 4 + singles, removed)
        limbs = [float(t.length(t.branch(e))[-1]) for e in t.ends()]
        if removed and max(removed) > EXTRA * min(limbs):
            continue  # a limb the template has no place for (an ant's third pair of legs): not this template
        match = _match(t, singles)
        if match[0] > SYMMETRY:
            continue
        try:
            bones = _humanoid(t, match) if template == "humanoid" else _quadruped(t, match)
        except NotRiggable:
            continue
        c = _legs_vs_spine(bones, "NECK" if template == "humanoid" else "CHEST")
        if (template == "humanoid" and c < -0.5) or (template == "quadruped" and abs(c) < 0.6):
            why = (f"template {template}: {4 + singles} of {ends} ends, limbs mirror to {match[0]:.0%} of the "
                   f"body's size, legs at {np.degrees(np.arccos(np.clip(c, -1, 1))):.0f} deg to the spine")
            return bones, template, why
    return None
