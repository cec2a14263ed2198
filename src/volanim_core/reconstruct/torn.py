"""Which posed pieces the pose tore off, and which of them are only specks let go where the rest pose's lie.

    per rest voxel: its rest piece, and the posed piece its image lands in (pieces_at)
      --homes: each rest piece's home, the posed piece most of its voxels land in
      --torn_off: the posed pieces that are no rest piece's home
      --loose_specks: those of at most SPECK_VOXELS voxels within SPECK_REACH voxels of their home
    --> breakage.py: pieces torn off (the verdict's "BROKEN") and specks (listed, not breakage)

Why such specks are not breakage: every sphere is grown on the voxel grid, so two spheres that touch only
by a corner at rest can part by a voxel when both move by the *same* matrix (their centres land on other
fractions of a voxel; tests/core/reconstruct/test_torn.py shows one), and a one-voxel sphere weighted a
hundredth differently from the flesh it lies on drifts a voxel more at a 90-degree bend. The rest pose
itself is full of such specks: Bob voxelized at 320 re-grows 76 of 1-8 voxels around its body, 53 of them
2 voxels from it (Chebyshev: one empty voxel between), 22 at 3 and 1 at 4, and the verdict already says
"nothing torn off (the rest pose too is 77 pieces)". Its leaf bent 45 and 90 degrees with smooth joints let
one or two more go, 2 and 3 voxels off, and was called BROKEN. A speck carried away (a wrong bone's, the
shoulder's specks moved rigidly while the flesh blended, #42) lands farther and is still a piece torn off;
so is anything larger.
"""

from __future__ import annotations

import numpy as np

from volanim_core.reconstruct import _label_kernels as L

#: the most voxels a let-go speck has: a 2 x 2 x 2 cube (a one-voxel sphere's ball is 7)
SPECK_VOXELS = 8
#: a speck within this many voxels of its home (Chebyshev: two empty voxels between) lies where the rest pose's do
SPECK_REACH = 3
_AROUND = np.stack(np.meshgrid(*[np.arange(-SPECK_REACH, SPECK_REACH + 1)] * 3, indexing="ij"), -1).reshape(-1, 3)


def pieces_at(labels: tuple, volume: np.ndarray, points: np.ndarray) -> np.ndarray:
    """The piece number (``labels``: :func:`~volanim_core.reconstruct.breakage._components`' runs of
    ``volume``) of each voxel ``points`` ``(K, 3)`` (array coordinates ``[x, y, z]``; 0: empty or outside
    the grid)."""
    first, x0, x1, piece, _ = labels
    shape = np.array(np.shape(volume)[::-1], np.int64)
    return L.piece_at(first, x0, x1, piece, shape, np.ascontiguousarray(np.asarray(points, np.int64)[:, ::-1]))


def homes(rest_piece: np.ndarray, posed_piece: np.ndarray, n_posed: int) -> np.ndarray:
    """Per rest piece (0..max), the posed piece most of its voxels land in (0: none lands anywhere).

    ``rest_piece``/``posed_piece``: per rest voxel, the rest piece it belongs to and the posed piece its
    image under its bone lands in (0: empty)."""
    out = np.zeros(int(rest_piece.max(initial=0)) + 1, np.int64)
    hit = posed_piece > 0
    keys, counts = np.unique(rest_piece[hit] * (n_posed + 1) + posed_piece[hit], return_counts=True)
    r, p = keys // (n_posed + 1), keys % (n_posed + 1)
    order = np.lexsort((-counts, r))  # per rest piece, its most-hit posed piece first
    first = np.r_[True, r[order][1:] != r[order][:-1]] if len(order) else np.zeros(0, bool)
    out[r[order][first]] = p[order][first]
    return out


def torn_off(home: np.ndarray, n_posed: int) -> np.ndarray:
    """The posed pieces the pose tore off: those that are no rest piece's home (``home``: :func:`homes`).

    A rest piece split by the pose leaves its other parts homeless. A body already in several pieces at
    rest (the frog's 6,069 specks) whose pose keeps them apart tears nothing off; two rest pieces the pose
    joins share a home, which is not breakage either. Returns the torn-off posed piece numbers (1..n),
    ascending."""
    torn = np.ones(n_posed + 1, bool)
    torn[0] = False
    torn[home] = False
    return np.flatnonzero(torn)


def loose_specks(torn, sizes: dict, home: np.ndarray, rest_piece: np.ndarray, posed_piece: np.ndarray,
                 images: np.ndarray, labels: tuple, volume: np.ndarray) -> set:
    """The torn-off posed pieces (``torn``) that are specks let go where they were: at most
    :data:`SPECK_VOXELS` voxels (``sizes``: posed piece -> voxels), with the home (``home``: :func:`homes`) of
    a rest piece they came from within :data:`SPECK_REACH` voxels. ``images``: each rest voxel's posed array
    coordinates ``[x, y, z]``; ``labels``: the posed volume's runs."""
    small = np.array([k for k in torn if sizes[k] <= SPECK_VOXELS], np.int64)
    if not len(small):
        return set()
    at = np.flatnonzero(np.isin(posed_piece, small))  # one pass over the rest voxels, not one a speck
    out = set()
    for k in small:
        mine = at[posed_piece[at] == k]
        theirs = np.unique(home[rest_piece[mine]])
        around = (images[mine][:, None, :] + _AROUND[None]).reshape(-1, 3)
        if np.isin(pieces_at(labels, volume, around), theirs[theirs > 0]).any():
            out.add(int(k))
    return out
