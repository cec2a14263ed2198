"""Each bone's flesh in one piece: a bone's stray islands go to the bone they touch (#62).

    points, radii, bone of each point
      --each bone's balls painted alone, as the reconstruction paints them, 26-connected parts-->
                                          its islands (exact at rest: what a pose moves as one piece)
      --k nearest of each size, balls touching on the voxel grid-->  links between bones
      every island but the bone's largest --> the bone its balls touch most (a few rounds, until none
                                              moves)

Why: a bone moves its balls as one rigid piece, so flesh of its that touches the rest of its flesh only
through another bone's balls is cut loose by any pose of either. Spot the cow's front leg bent 45 degrees
tore off an 8-voxel speck: one ball of radius 1 at the knee, given to the shin by its distance to the
bone, touching 43 balls of the thigh and trunk and none of the shin's. Given to the bone it touches,
it stays on. The islands are the painted voxels' own, not a guess from the balls' distances: a rule of
thumb (centres within the two radii and 1.8 voxels) called Bob's one-voxel ball at a 90-degree bend
joined to its bone when its voxels were not, and left it to be torn off.
"""

from __future__ import annotations

import numpy as np

NEIGHBOURS = 8  # balls compared with each ball: its nearest ones of each size class
SLACK = 1.8  # voxels: two balls whose painted voxels touch (26-connected) may be this much further apart
ROUNDS = 4  # an island given to a bone may join an island of that bone's: a few rounds settle it


def links(points: np.ndarray, radius: np.ndarray, k: int = NEIGHBOURS) -> tuple[np.ndarray, np.ndarray]:
    """``(i, j)``: pairs of touching balls among each ball's ``k`` nearest of every size class.

    By centre distance alone a small ball's nearest are small balls that miss it, while the big ball it
    lies in is far off: so the balls are binned by radius (powers of two) and each asks every bin."""
    from scipy.spatial import cKDTree

    n = len(points)
    size = np.floor(np.log2(radius)).astype(np.int64)
    ii, jj = [], []
    for c in np.unique(size):
        members = np.flatnonzero(size == c)
        kc = min(k, len(members))
        d, j = cKDTree(points[members]).query(points, kc)
        d, j = d.reshape(n, kc), members[j.reshape(n, kc)]
        i = np.repeat(np.arange(n), kc).reshape(n, kc)
        ok = (j != i) & (d <= radius[i] + radius[j] + SLACK)
        ii.append(i[ok])
        jj.append(j[ok])
    i, j = np.concatenate(ii), np.concatenate(jj)
    return np.concatenate([i, j]), np.concatenate([j, i])  # both ways: a big ball need not ask a small one


def bone_islands(points: np.ndarray, radius: np.ndarray, bone: np.ndarray) -> tuple[int, np.ndarray]:
    """``(count, island)``: each point's island, the 26-connected part of its bone's painted balls (a voxel
    is painted when its centre is nearer a ball's centre than the radius, as the reconstruction paints)
    that holds its centre; numbered 0..count-1 across all bones."""
    from scipy import ndimage

    from volanim_core.rig._curve_kernels import paint_balls

    island = np.zeros(len(bone), np.int64)
    count = 0
    cube = ndimage.generate_binary_structure(3, 3)
    for b in np.unique(bone):
        idx = np.flatnonzero(bone == b)
        c, r = np.asarray(points[idx], np.float64), np.asarray(radius[idx], np.float64)
        lo = np.floor((c - r[:, None]).min(axis=0)) - 1
        hi = np.ceil((c + r[:, None]).max(axis=0)) + 1
        grid = np.zeros(tuple((hi - lo + 1).astype(np.int64)), bool)
        paint_balls(c - lo, np.maximum(r - 1e-9, 0.0), grid)  # strictly inside, as the kernels paint
        label, k = ndimage.label(grid, cube)
        at = label[tuple(np.rint(c - lo).astype(np.int64).T)]
        at = np.where(at > 0, at, k + 1 + np.arange(len(idx)))  # a ball too thin to paint its centre: alone
        _, at = np.unique(at, return_inverse=True)
        island[idx] = count + at
        count += int(at.max()) + 1
    return count, island


def one_piece_each(points: np.ndarray, radius: np.ndarray, bone: np.ndarray) -> np.ndarray:
    """``bone`` (each point's, >= 0) with every bone's islands but its largest (by ball volume) given to
    the bone whose balls they touch most; an island touching no other bone stays. ``(N,)``, a new array."""
    bone = np.asarray(bone, np.int64).copy()
    n = len(bone)
    if n < 2:
        return bone
    r = np.maximum(np.asarray(radius, np.float64), 0.5)
    i, j = links(np.asarray(points, np.float64), r)
    weight = r**3
    nb = int(bone.max()) + 1
    for _ in range(ROUNDS):
        same = bone[i] == bone[j]
        count, island = bone_islands(points, r, bone)
        size = np.bincount(island, weights=weight, minlength=count)
        owner = np.zeros(count, np.int64)
        owner[island] = bone
        order = np.lexsort((-size, owner))  # per bone, its largest island first
        stray = np.ones(count, bool)
        stray[order[np.r_[True, owner[order][1:] != owner[order][:-1]]]] = False
        across = ~same & stray[island[i]]
        if not across.any():
            break
        keys, hits = np.unique(island[i[across]] * nb + bone[j[across]], return_counts=True)
        isl, other = keys // nb, keys % nb
        order = np.lexsort((-hits, isl))  # per stray island, the bone it touches most first
        pick = np.r_[True, isl[order][1:] != isl[order][:-1]]
        target = np.full(count, -1)
        target[isl[order][pick]] = other[order][pick]
        moved = target[island]
        if not (moved >= 0).any():
            break
        bone[moved >= 0] = moved[moved >= 0]
    return bone
