"""Flesh its own chain cannot reach: a bone's rest voxels joined to the body only through another limb's.

    ownership labels [x, y, z] (1 + bone)
        --cc3d (26-connected pieces of each bone's flesh)--> pieces
        --cc3d.region_graph--> which pieces touch
        --from the trunk out (the bones leaving the rig's root joints, every piece reached, and each piece
          in the ball at its own bone's joint: the ball re-grows the flesh there in every pose): a piece is
          reached when it touches a reached piece of one of its bone's ancestors or of the trunk-->
        --> each bone's voxels in pieces not reached

Why: posed, a bone carries its flesh, and flesh that hung from the body only through another limb leaves
that limb and comes off. The frog's auto-rig gives R_POST_3 27,188 voxels, every one of them touching the
body only through L_POST2_3's flesh (two folded legs pressed together), none nearer its joint than 16
voxels (the ball there: 2.2): bent 45 degrees, it tears off 11,984 voxels. No ownership rule can tell
whether such a bone is misplaced or its flesh misassigned (given to the neighbour, R_POST_3 moves 118
voxels and the frog's 45 degree leaf poses are all healthy; its animator would not call that a leg), so
it is said, by bone, where the ownership is made (``volanim connect --ownership``): move the bone, or
repaint.
"""

from __future__ import annotations

import numpy as np

from volanim_core.rig._ownership_kernels import piece_stats
from volanim_core.rig.ownership import Ownership, bone_parents


def unreached(own: Ownership) -> np.ndarray:
    """``(B,)`` each bone's owned voxels its chain cannot reach (module docstring); 0 for the trunk's."""
    lost = np.zeros(len(own.bones), np.int64)
    p = _pieces(own)
    if p is not None:
        np.add.at(lost, p.bone[p.gone], p.sizes[p.gone])
    return lost


def hang_on(own: Ownership, rounds: int = 8) -> tuple[Ownership, list[tuple[int, int, int]]]:
    """The ownership with every piece of flesh its chain cannot reach given to the bone of the largest reached
    piece it touches (the flesh it hangs from), in rounds until none is left; and ``[(from bone, to bone,
    voxels)]``. What `volanim connect --hang-on` and the studio's *Hang on* do, when the animator would rather
    keep the bone where it is: the frog's R_POST_3 then moves 118 voxels, and its leaves bend without tearing."""
    labels = own.labels
    moved: dict[tuple[int, int], int] = {}
    for _ in range(rounds):
        p = _pieces(own.with_labels(labels) if labels is not own.labels else own)
        if p is None or not p.gone.any():
            break
        lut = np.zeros(len(p.bone), labels.dtype)
        for piece in np.flatnonzero(p.gone):
            held = [q for q in p.near[piece] if p.reached[q]]
            if held:
                q = max(held, key=lambda q: p.sizes[q])
                lut[piece] = p.bone[q] + 1
                key = (int(p.bone[piece]), int(p.bone[q]))
                moved[key] = moved.get(key, 0) + int(p.sizes[piece])
        if not lut.any():
            break
        new = lut[p.pieces]
        labels = np.where(new > 0, new, labels)
    out = own if labels is own.labels else own.with_labels(labels)
    return out, [(a, b, n) for (a, b), n in sorted(moved.items())]


class _Pieces:
    """The flesh's pieces (26-connected, each of one bone) and what :func:`unreached` asks of them."""

    def __init__(self, pieces, bone, sizes, near, reached, attached):
        self.pieces, self.bone, self.sizes, self.near = pieces, bone, sizes, near
        self.reached = reached
        self.gone = attached & ~reached  # an island at rest is no limb's loss


def _pieces(own: Ownership) -> _Pieces | None:
    import cc3d

    up = bone_parents(own.bones)
    trunk = {k for k, p in enumerate(up) if p is None}
    allowed = []  # each bone's ancestors and the trunk: the flesh it may hang from
    for k in range(len(up)):
        chain, p, seen = set(trunk), up[k], {k}
        while p is not None and p not in seen:  # (a cycle would be a broken file; stop rather than loop)
            chain.add(p)
            seen.add(p)
            p = up[p]
        allowed.append(chain)
    pieces, n = cc3d.connected_components(own.labels, connectivity=26, out_dtype=np.uint32, return_N=True)
    if n == 0:
        return None
    label, sizes = np.zeros(n + 1, np.int64), np.zeros(n + 1, np.int64)
    boxes = np.empty((n + 1, 6), np.int64)
    boxes[:, :3], boxes[:, 3:] = np.iinfo(np.int64).max, -1
    piece_stats(pieces, own.labels, label, sizes, boxes)  # one pass: each piece's bone and size
    bone = label - 1
    near: list[list[int]] = [[] for _ in range(n + 1)]
    for a, b in cc3d.region_graph(pieces, connectivity=26):
        if a and b:
            near[a].append(b)
            near[b].append(a)
    trunk_pieces = np.isin(bone, list(trunk))
    trunk_pieces[0] = False
    seeds = trunk_pieces | _at_own_joint(own, pieces, bone, boxes)
    reached = _spread(seeds, near, lambda piece, q: bone[q] in allowed[bone[piece]])
    attached = _spread(trunk_pieces, near, lambda piece, q: True)
    return _Pieces(pieces, bone, sizes, near, reached, attached)


def _at_own_joint(own: Ownership, pieces: np.ndarray, bone: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """The pieces with a voxel in the ball at their bone's proximal joint (at least a voxel and a half): the
    ball re-grows the flesh there in every pose, so such a piece stays on whatever its joint is in (Spot's
    tail and the rabbit's hind foot touch their parents only through a sibling's flesh, and bend whole)."""
    out = np.zeros(len(bone), bool)
    for piece in range(1, len(bone)):
        k = bone[piece]
        if k < 0:
            continue
        joint = np.asarray(own.bones[k].proximal, np.float64) - np.asarray(own.origin, np.float64)
        r = max(float(own.ball_radii[k]), 1.5)
        lo, hi = boxes[piece, :3], boxes[piece, 3:]
        if np.linalg.norm(np.clip(joint, lo, hi - 1) - joint) > r:
            continue  # its box is farther than the ball
        a, b = np.maximum(np.floor(joint - r).astype(int), lo), np.minimum(np.ceil(joint + r).astype(int) + 1, hi)
        if np.any(b <= a):
            continue
        box = tuple(slice(int(x), int(y)) for x, y in zip(a, b))
        at = np.argwhere(pieces[box] == piece) + a
        out[piece] = bool(len(at)) and float(np.min(np.linalg.norm(at - joint, axis=1))) <= r
    return out


def _spread(start: np.ndarray, near: list[list[int]], may) -> np.ndarray:
    """The pieces reached from ``start`` through touching pieces, a step from ``q`` to ``piece`` where
    ``may(piece, q)``."""
    reached = start.copy()
    todo = list(np.flatnonzero(start))
    while todo:
        q = todo.pop()
        for piece in near[q]:
            if not reached[piece] and may(piece, q):
                reached[piece] = True
                todo.append(piece)
    return reached


LEAST = 0.01  # of a bone's flesh: out of reach below this is a speck a repaint is not worth, and goes unsaid


def out_of_reach(own: Ownership, least: float = LEAST) -> list[tuple[int, int]]:
    """``[(bone, voxels)]``: the bones with more than ``least`` of their flesh out of their chain's reach (the
    rest: specks a repaint is not worth), and how many voxels."""
    lost, counts = unreached(own), own.counts()
    return [(int(k), int(lost[k])) for k in np.flatnonzero(lost > least * np.maximum(counts, 1))]


def reach_notes(own: Ownership, least: float = LEAST) -> list[str]:
    """One line per bone of :func:`out_of_reach`, for the user."""
    counts = own.counts()
    return [f"{own.bones[k].label}: {lost} of its {int(counts[k])} voxels touch the body only through another "
            "limb's flesh; posed, they come off: move the bone, or repaint them"
            for k, lost in out_of_reach(own, least)]
