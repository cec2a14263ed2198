"""Specks of a bone's flesh cut off inside another's, given to the flesh around them: ownership's last step.

    labels [x, y, z] (1 + bone, 0 outside)
        --_run_kernels.label_runs (the rows' runs of one label, 26-connected pieces of each label, once)-->
        --_speck_kernels.piece_boxes (each piece's label, size, box)--> each bone's largest piece its main
          one, the others specks
        --_speck_kernels.speck_rings (each speck's ring on its box painted from the runs: the pieces of the
          voxels around it, counted)-->
        --rounds on the pieces' graph (union-find: a speck that joins a bone merges with the pieces of
          that bone it touches)--> each speck's new bone
        --_speck_kernels.relabel_runs--> labels, each speck's runs relabelled

Why a graph and not rounds on the volume: a speck that touches only other specks can only join once they
have; labelling the whole volume's pieces again for each such round cost the frog 0.7 s (three passes of
cc3d over 27 M voxels) where a skeletonize takes 0.4. The pieces' graph is a few hundred nodes. Why runs and
not cc3d's grid of pieces: the frog's box is 96 % empty; labelling every voxel into a 108 MB grid and reading it
again cost 0.10-0.24 s of its ownership, the runs 0.04 s (rig/_speck_kernels.py).
"""

from __future__ import annotations

import numpy as np

from volanim_core._run_kernels import label_runs, run_values
from volanim_core.rig._speck_kernels import paint_box, piece_boxes, relabel_runs, speck_rings


def join_specks(labels: np.ndarray, n_bones: int, rounds: int = 8) -> int:
    """Give each piece of a bone's voxels cut off from its largest piece (26-connected) to the bone its
    neighbours mostly belong to, in place; returns the voxels moved. Why: the tube rule can leave a speck
    of one bone inside another's flesh (a voxel of spine in the shoulder), which then stays behind, alone,
    when the limb around it moves.

    A speck joins, where it can, a neighbour's *largest* piece (or a speck that has joined one): two specks
    side by side would otherwise trade labels and leave a new speck (the ant's abdomen kept two voxels in a
    leg, torn off when the leg stepped). Specks that touch only specks wait a round, until their neighbours
    have joined; when no speck can join a main piece, each speck none of whose neighbours changed this round
    takes the bone most of its other-bone neighbours have.
    """
    return speck_runs(labels, n_bones, rounds)[0]


def speck_runs(labels: np.ndarray, n_bones: int, rounds: int = 8) -> tuple[int, tuple]:
    """:func:`join_specks`, and the labels' runs it read, as they are after: ``(moved, (first, x0, x1, value))``
    (volanim_core/_run_kernels.runs ``by_value`` over ``labels.T``; a run's value is its label). The tables
    every posed frame reads are made from them (rig/_table_kernels.py)."""
    zyx = labels.T  # rows along x: labels [x, y, z] are laid out x fastest (Fortran), so this view is C-ordered
    first, x0, x1, pieces, n = label_runs(zyx, True)
    ny = zyx.shape[1]
    value = run_values(zyx, first, x0)
    bone, sizes, boxes_all = piece_boxes(first, x0, x1, pieces, value, n, ny)
    main, has = np.zeros(len(sizes), bool), np.zeros(n_bones + 1, bool)
    for piece in np.argsort(sizes, kind="stable")[::-1]:  # each bone's first piece seen is its largest
        if piece and bone[piece] and not has[bone[piece]]:
            main[piece] = has[bone[piece]] = True
    specks = np.flatnonzero((bone > 0) & ~main)
    if not len(specks):
        return 0, (first, x0, x1, value)
    near = [_ring(first, x0, x1, pieces, ny, labels.shape, piece, boxes_all[piece]) for piece in specks]
    new = _rounds(specks, near, bone.copy(), main, rounds)
    changed = np.where(new != bone, new, 0)
    changed[0] = 0
    return int(relabel_runs(zyx, first, x0, x1, pieces, changed, value)), (first, x0, x1, value)


def _ring(first, x0, x1, pieces, ny, shape, piece: int, box: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Speck ``piece``'s ring (the pieces of the voxels 26-next to it, and how many of each), read on its box and
    a voxel around it (within the grid), painted from the runs."""
    lo = np.maximum(box[:3] - 1, 0)
    hi = np.minimum(box[3:] + 1, shape)
    grid = paint_box(first, x0, x1, pieces, ny, lo, hi)
    starts, ring = speck_rings(grid, np.array([piece], np.int64), (box - np.tile(lo, 2)).reshape(1, 6))
    return np.unique(ring, return_counts=True)


def _rounds(specks: np.ndarray, near: list, bone: np.ndarray, main: np.ndarray, rounds: int) -> np.ndarray:
    """Each piece's bone once the specks have joined (``near[k]``: speck k's ring, pieces and counts)."""
    root = np.arange(len(bone))

    def find(p):
        while root[p] != p:
            root[p] = root[root[p]]
            p = root[p]
        return p

    def join(piece, to):
        bone[piece] = to
        for q in near_of[piece][0]:  # it now touches the pieces of its new bone around it: one piece
            if q and bone[find(q)] == to:
                a, b = find(piece), find(q)
                if a != b:
                    root[b] = a
                    main[a] = main[a] or main[b]

    near_of = dict(zip(specks.tolist(), near))
    for _ in range(rounds):
        is_main = np.array([main[find(p)] for p in range(len(bone))])  # as the round starts
        joining = []
        for piece in specks:
            if is_main[piece]:
                continue
            q, n = near_of[piece]
            votes = np.bincount(bone[[find(p) for p in q]][is_main[q]], weights=n[is_main[q]],
                                minlength=len(bone))
            if votes.any():
                joining.append((piece, int(votes.argmax())))
        for piece, to in joining:
            join(piece, to)
        if joining:
            continue
        changed = np.zeros(len(bone), bool)  # specks touching only specks: their neighbours as they are
        for piece in specks:
            q, n = near_of[piece]
            if is_main[piece] or changed[q].any():
                continue  # the next round sees it
            other = (q != 0) & (bone[[find(p) for p in q]] != bone[piece])
            if other.any():
                votes = np.bincount(bone[[find(p) for p in q[other]]], weights=n[other], minlength=len(bone))
                join(piece, int(votes.argmax()))
                changed[piece] = True
        if not changed.any():
            break
    return bone
