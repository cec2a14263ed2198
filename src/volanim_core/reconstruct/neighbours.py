"""Same-bone neighbour lists: which spheres may clip each sphere (the overdraw cut).

    connectivity --sphere_neighbours (cKDTree per bone)--> (N, k) indices, -1 padded
    reconstruct() --cached_neighbours--> the lists of the last few connectivities, remembered
                  --reorder_neighbours--> lists a caller passed, after it grouped points by bone

Same-bone neighbours keep their distances under any pose (a bone moves
rigidly), so the lists depend only on the connectivity. ``reconstruct()``
remembers them (:func:`cached_neighbours`): callers pass nothing, and every
frame of a clip, every studio preview and the rest frame share one set.
"""

from __future__ import annotations

import numpy as np

from volanim_core.memo import Recent, content_key
from volanim_core.reconstruct.radii import radius_squared
from volanim_core.rig.connectivity import Connectivity

HALFSPACES = 8  # nearest same-bone neighbours per sphere whose planes clip it (bisector or power plane)
# Below it, clipping rows costs more than the short runs it saves (the frog's mass of small spheres
# sweeps its boxes faster). 10 served full-resolution frames, but a half-resolution one halves every
# radius: the mannequin's live previews and scans then cut nothing (overdraw 160, #65); at 6 they cut
# (overdraw 37, 2x faster; mannequin-large's half-size frame 105 -> 15, 1.7x) and full-resolution
# frames stay as fast (benchmarks/bench_live.py).
CUT_MIN_RADIUS = 6.0


def sphere_neighbours(tskel: Connectivity, k: int = HALFSPACES, min_radius: float = CUT_MIN_RADIUS) -> np.ndarray:
    """For each sphere of radius >= ``min_radius``, its ``k`` nearest spheres of the same bone (any radius:
    a larger one cuts it at their bisector, a smaller one at their power plane).

    ``(N, k)`` int32, -1 where there are fewer. Same-bone neighbours keep their
    distances under any pose (a bone moves rigidly), so this depends only on
    the connectivity: :func:`reconstruct` remembers it (:func:`cached_neighbours`).

    Only spheres of at least ``min_radius`` get lists: the kernel clips no smaller
    sphere (its rows are too short to gain).
    """
    from scipy.spatial import cKDTree

    n = len(tskel)
    out = np.full((n, k), -1, np.int32)
    _, big = _big_spheres(tskel, min_radius)
    bones = np.asarray(tskel.bone)
    for b in np.unique(bones[big]):
        every = np.flatnonzero(bones == b)  # the tree: every sphere of the bone, small ones too
        idx = big[bones[big] == b]
        if len(every) < 2:
            continue
        q = min(len(every), k + 1)
        _, nn = cKDTree(tskel.points[every]).query(tskel.points[idx], k=q, workers=-1)
        nn = every[nn.reshape(len(idx), q)]  # global indices, nearest first (self among them)
        ok = nn != idx[:, None]
        rank = np.cumsum(ok, axis=1) - 1
        keep = ok & (rank < k)
        rows, cols = np.nonzero(keep)
        out[idx[rows], rank[rows, cols]] = nn[rows, cols]
    return out


def _big_spheres(tskel: Connectivity, min_radius: float, r2: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Every sphere's squared radius (``r2`` when the caller has it), and the indices of those the
    kernel clips (radius >= ``min_radius``)."""
    r2 = radius_squared(tskel.dt) if r2 is None else r2
    return r2, np.flatnonzero(r2 >= radius_squared(np.array([float(min_radius)]))[0])


CACHED_CONNECTIVITIES = 4
_RECENT = Recent(CACHED_CONNECTIVITIES)


def cached_neighbours(tskel: Connectivity, k: int = HALFSPACES, min_radius: float = CUT_MIN_RADIUS, *,
                      r2: np.ndarray | None = None) -> np.ndarray:
    """:func:`sphere_neighbours`, remembered for the last few connectivities (read-only result).

    A caller who reconstructs frame after frame without passing lists gets them made
    once: the key is a hash of exactly what they depend on -- which spheres are at least
    ``min_radius``, every centre and bone, and the point count.
    A pose is not part of it (same-bone distances survive any pose), so every frame of a
    clip, the studio's live and full previews and the rest frame share one set.
    ``r2``: the spheres' :func:`radius_squared`, when the caller has them.
    """
    r2, big = _big_spheres(tskel, min_radius, r2)
    # every sphere's centre and bone (any may be a big one's neighbour); the radii only say which are big.
    # Hashed in their own dtypes: converting the frog's 137 k centres to float64 first doubled the bytes
    # hashed every frame (9 ms a lookup)
    key = content_key(np.array([len(tskel), k], np.int64), big, tskel.points, tskel.bone)

    def make() -> np.ndarray:
        lists = sphere_neighbours(tskel, k, min_radius)
        lists.setflags(write=False)
        return lists

    return _RECENT.get(key, make)


def check_neighbours(neighbours, n: int) -> None:
    """Neighbour lists must be ``(n, k)`` integers in ``-1..n-1`` (else the kernels would read out of bounds)."""
    arr = np.asarray(neighbours)
    if arr.ndim != 2 or arr.shape[0] != n or arr.dtype.kind not in "iu":
        raise ValueError(f"neighbours must be an (N, k) integer array with N = {n} points, "
                         f"got shape {arr.shape} of {arr.dtype}")
    if arr.size and (arr.min() < -1 or arr.max() >= n):
        raise ValueError(f"neighbours must be point indices 0..{n - 1} (or -1 for none), "
                         f"got values {arr.min()}..{arr.max()}")


def reorder_neighbours(neighbours: np.ndarray, order: np.ndarray | None) -> np.ndarray:
    """Neighbour lists given in the caller's point order, re-expressed after ``order`` was applied."""
    neighbours = np.asarray(neighbours, np.int32)
    if order is None:
        return neighbours
    new_index = np.empty(len(order), np.int32)
    new_index[order] = np.arange(len(order), dtype=np.int32)
    moved = neighbours[order]
    return np.where(moved >= 0, new_index[np.maximum(moved, 0)], -1).astype(np.int32)
