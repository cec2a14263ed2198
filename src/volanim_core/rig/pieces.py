"""A body in pieces: each piece's points go to the bones of that piece (#62).

    mask --label, 26-connected--> pieces
    each bone --its segment sampled every half voxel, inside the mask--> the piece most of it lies in
                (none of it inside: the piece of the skeleton point nearest its middle)
    each piece's points --> the nearest of that piece's bones
    a piece no bone lies in --> whole to the one bone nearest to it (it moves as one piece)

Why: a model whose limbs are separate shells (pyvista's ant: 13 pieces) has its joints where the shells
meet, and the nearest bone is blind to the gap: a leg shell's first points lie nearer the bone of the
shell next to it, so turning the leg leaves them behind and the shell tears (8 of the ant's 10 leaf poses
broke). Which piece a point lies in is evidence no distance outweighs: the flesh of one shell moves with
that shell's bones. A body in one piece (the mannequin) is attached exactly as by the nearest bone.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from volanim_core.rig.bones import BoneSkeleton
from volanim_core.rig.nearest import attach_nearest_bone, segment_distances

STEP = 0.5  # voxels between a segment's samples
CHUNK = 65536  # points measured against the bones at a time: (chunk, bones, 3) of memory, not (points, ...)


def pieces(mask: np.ndarray) -> tuple[np.ndarray, int]:
    """The mask's 26-connected pieces (1..n, 0 outside) and their count."""
    return ndimage.label(np.asarray(mask, bool), ndimage.generate_binary_structure(3, 3))


def bone_pieces(bones: BoneSkeleton, labels: np.ndarray, points: np.ndarray, point_piece: np.ndarray
                ) -> np.ndarray:
    """``(B,)``: the piece each bone's segment mostly lies in (see the module docstring); 0 for none."""
    out = np.zeros(len(bones), np.int64)
    hi = np.array(labels.shape) - 1
    inside = point_piece > 0
    for k, (a, b) in enumerate(bones.segments()):
        n = int(np.ceil(np.linalg.norm(b - a) / STEP)) + 1
        at = np.rint(a + np.linspace(0.0, 1.0, n)[:, None] * (b - a)).astype(np.int64)
        ok = np.all((at >= 0) & (at <= hi), axis=1)
        found = labels[tuple(at[ok].T)]
        found = found[found > 0]
        if len(found):
            out[k] = np.bincount(found).argmax()
        elif inside.any():
            middle = (a + b) / 2
            out[k] = point_piece[inside][np.argmin(((points[inside] - middle) ** 2).sum(axis=1))]
    return out


def attach_by_piece(points: np.ndarray, bones: BoneSkeleton, mask: np.ndarray) -> np.ndarray:
    """Each point's bone: the nearest of its piece's bones; a piece with none goes whole to the bone nearest
    it; a point outside the mask to its nearest bone. ``(N,)`` int32."""
    points = np.asarray(points)
    labels, n = pieces(mask)
    hi = np.array(labels.shape) - 1
    ok = np.all((points >= 0) & (points <= hi), axis=1)
    piece = np.zeros(len(points), np.int64)
    piece[ok] = labels[tuple(points[ok].astype(np.int64).T)]
    out = attach_nearest_bone(points, bones)
    if n <= 1:
        return out
    owner = bone_pieces(bones, labels, points, piece)
    segs = bones.segments()
    for p in np.unique(piece[(piece > 0) & (owner[out] != piece)]):  # points whose nearest bone is another piece's
        mine = np.flatnonzero(owner == p)
        if len(mine):
            at = np.flatnonzero((piece == p) & (owner[out] != p))
            for s in range(0, len(at), CHUNK):
                out[at[s:s + CHUNK]] = mine[segment_distances(points[at[s:s + CHUNK]], segs[mine]).argmin(axis=1)]
        else:  # a piece no bone lies in: whole, to the bone nearest to any of its points
            at = np.flatnonzero(piece == p)
            best = np.full(len(bones), np.inf)
            for s in range(0, len(at), CHUNK):
                best = np.minimum(best, segment_distances(points[at[s:s + CHUNK]], segs).min(axis=0))
            out[at] = int(best.argmin())
    return out
