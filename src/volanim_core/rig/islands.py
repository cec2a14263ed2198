"""Each bone's flesh in one piece: a bone's stray islands go to the bone they touch (#62).

    points, radii, bone of each point
      --each bone's balls painted alone, as the reconstruction paints them, 26-connected parts-->
                                          its islands (exact at rest: what a pose moves as one piece)
      --k nearest of each size, balls touching on the voxel grid-->  links between bones
      every island but the bone's largest --> of the bones its balls touch, most first, the first whose
                                              largest island its voxels touch: it joins that flesh
                                              (a few rounds, until none moves)

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

from volanim_core.skeleton.points import voxel_keys

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
    count, island, *_ = _painted_islands(points, radius, bone, np.ones(len(bone)))
    return count, island


def _painted_islands(points, radius, bone, weight):
    """:func:`bone_islands`, and what :func:`one_piece_each` asks of them, one bone's grid at a time:
    ``main`` (bone -> its largest island by ``weight``, the first on a tie), ``voxels`` (every other
    island -> its voxels, None for a ball too thin to paint its centre) and ``surface`` (bone -> the
    :func:`_keys` of its largest island's voxels that touch a voxel outside it: all an island beside it
    can touch)."""
    from scipy import ndimage

    from volanim_core.rig._curve_kernels import paint_balls

    island = np.zeros(len(bone), np.int64)
    count = 0
    main, voxels, surface = {}, {}, {}
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
        labels, at = np.unique(at, return_inverse=True)
        island[idx] = count + at
        largest = int(np.argmax(np.bincount(at, weights=weight[idx])))
        main[int(b)] = count + largest
        boxes = ndimage.find_objects(label)
        for local, v in enumerate(labels):
            if local == largest:
                if v <= k:
                    box = boxes[v - 1]
                    inside = label[box] == v
                    edge = inside & ~ndimage.binary_erosion(inside, cube, border_value=0)
                    at = np.argwhere(edge) + lo.astype(np.int64) + [t.start for t in box]
                    surface[int(b)] = np.sort(voxel_keys(at))
            else:
                box = boxes[v - 1] if v <= k else None
                voxels[count + local] = None if box is None else \
                    np.argwhere(label[box] == v) + lo.astype(np.int64) + [t.start for t in box]
        count += len(labels)
    return count, island, main, voxels, surface


def _touching(vox: np.ndarray | None, own: int, surface: dict) -> set[int]:
    """The bones other than ``own`` whose largest island the voxels ``vox`` touch (26-neighbours or shared
    voxels): where an island joins that bone's flesh when given to it."""
    if vox is None:
        return set()
    near = np.unique(voxel_keys((vox[:, None, :] + _CUBE[None]).reshape(-1, 3)))
    return {b for b, keys in surface.items() if b != own and np.isin(near, keys, assume_unique=True).any()}


_CUBE = np.argwhere(np.ones((3, 3, 3), bool)) - 1


def one_piece_each(points: np.ndarray, radius: np.ndarray, bone: np.ndarray) -> np.ndarray:
    """``bone`` (each point's, >= 0) with every bone's islands but its largest (by ball volume) given to
    the bone it touches most (by :func:`links`) among those whose largest island its painted voxels touch,
    so it joins that bone's flesh; an island touching none stays. ``(N,)``, a new array.

    Why the painted voxels decide: an island touching a bone's balls within the slack but not its voxels
    stays an island of that bone too, and went back the next round (the frog: 5931 points between two
    bones every round, so the four rounds left them all where they began)."""
    bone = np.asarray(bone, np.int64).copy()
    n = len(bone)
    if n < 2:
        return bone
    r = np.maximum(np.asarray(radius, np.float64), 0.5)
    i, j = links(np.asarray(points, np.float64), r)
    weight = r**3
    nb = int(bone.max()) + 1
    for _ in range(ROUNDS):
        count, island, main, voxels, surface = _painted_islands(points, r, bone, weight)
        stray = np.ones(count, bool)
        stray[list(main.values())] = False
        across = (bone[i] != bone[j]) & stray[island[i]]
        if not across.any():
            break
        keys, hits = np.unique(island[i[across]] * nb + bone[j[across]], return_counts=True)
        isl, other = keys // nb, keys % nb
        order = np.lexsort((-hits, isl))  # per stray island, the bones it touches, most first
        isl, other = isl[order], other[order]
        owner = np.zeros(count, np.int64)
        owner[island] = bone
        target = np.full(count, -1)
        for x, start, stop in _runs(isl):
            joins = _touching(voxels[x], int(owner[x]), surface)
            target[x] = next((int(o) for o in other[start:stop] if int(o) in joins), -1)
        moved = target[island]
        if not (moved >= 0).any():
            break
        bone[moved >= 0] = moved[moved >= 0]
    return bone


def _runs(sorted_values: np.ndarray):
    """``(value, start, stop)`` of each run of equal values in a sorted array."""
    cut = np.flatnonzero(np.r_[True, sorted_values[1:] != sorted_values[:-1], True])
    return [(int(sorted_values[a]), int(a), int(b)) for a, b in zip(cut[:-1], cut[1:])]
