"""Cracks: sphere pairs of different bones that overlap at rest and part in a pose (breakage.py's report).

    rest frame --touching_pairs (each sphere against its 16 nearest)--> pairs (i, j) and their radii's sum
    posed frame --posed_centres, posed_radii--> the gap of each pair as grown
      --> open pairs (one parted only by spheres smaller than at rest: where nothing fills its gap)
      --> cracks: rest midpoints and gaps

A crack is where the posed spheres of two bones that touched at rest part. Its
rest midpoint says where (the breakage report ranks joints by their cracks'
gaps); the scan counts them per frame without reconstructing.
"""

from __future__ import annotations

import numpy as np

from volanim_core.reconstruct.engine import posed_centres
from volanim_core.rig.connectivity import Tskel
from volanim_core.rig.skinning import posed_radii
from volanim_core.rig.thin_spheres import deepest_sphere


def touching_pairs(tskel: Tskel) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Sphere pairs ``(i, j, touch)`` of different bones that overlap at rest (pose-independent).

    ``touch`` is the sum of the radii: a posed pair further apart than that has cracked.
    """
    from scipy.spatial import cKDTree

    if len(tskel) < 2:
        return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0)
    p = tskel.points.astype(np.float64)
    # cracks are local: each sphere against its nearest neighbours (all pairs would be
    # ~10^8 on the frog's 137 k spheres)
    k = min(17, len(p))
    _, nn = cKDTree(p).query(p, k=k, workers=-1)
    i = np.repeat(np.arange(len(p)), k - 1)
    j = nn[:, 1:].ravel()
    keep = (j < len(p)) & (i < j)
    i, j = i[keep], j[keep]
    keep = tskel.bone[i] != tskel.bone[j]
    i, j = i[keep], j[keep]
    touch = tskel.dt[i] + tskel.dt[j]
    overlap = np.linalg.norm(p[i] - p[j], axis=1) < touch
    return i[overlap], j[overlap], touch[overlap]


def cracks(tskel: Tskel, min_gap: float = 0.5, pairs=None) -> tuple[np.ndarray, np.ndarray]:
    """Sphere pairs of different bones that overlap at rest and are ``min_gap`` apart in the pose.

    Returns the pairs' rest midpoints ``(K, 3)`` and their gaps ``(K,)`` in voxels.
    ``pairs``: :func:`touching_pairs` of the same points, when the caller scans many frames.

    The gap is between the spheres as the frame grows them: with smooth joints a stretched medial
    sheet's thin (:func:`~volanim_core.rig.skinning.posed_radii`). A pair that parts only because its
    spheres are smaller than at rest (``touch``) is a crack only where no other sphere fills the middle
    of the gap: in a sheet the spheres between the two do (mannequin-large's crotch at a 120-degree
    hip: one such pair, its gap filled from end to end).
    """
    i, j, touch = touching_pairs(tskel) if pairs is None else pairs
    if not len(i):
        return np.zeros((0, 3)), np.zeros(0)
    p = tskel.points.astype(np.float64)
    c = posed_centres(tskel)
    r = posed_radii(tskel, c)  # tskel.dt unless a sheet thinned; with dt, r[i] + r[j] is touch and none thinned
    dist = np.linalg.norm(c[i] - c[j], axis=1)
    gap = dist - (r[i] + r[j])
    open_ = gap > min_gap
    thinned = np.flatnonzero(open_ & (dist - touch <= min_gap))
    if len(thinned):
        a, b = i[thinned], j[thinned]
        middle = c[a] + (c[b] - c[a]) * ((r[a] + gap[thinned] / 2) / dist[thinned])[:, None]
        deepest = deepest_sphere(c, r, middle)
        open_[thinned] = ((middle - c[deepest]) ** 2).sum(axis=1) > r[deepest] ** 2
    return (p[i[open_]] + p[j[open_]]) / 2.0, gap[open_]
