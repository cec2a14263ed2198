"""One piece, proved from the spheres alone: the clip scan's way past the voxels of a whole frame (#65).

    the rest frame (once):  each sphere's candidate partners -- a spanning forest of each bone's
                            surely-overlapping spheres, and the pairs of different bones that overlap
    each frame:             every candidate pair tested at its posed centres; the spheres joined by
                            the pairs that surely share a voxel; all joined --> one piece, proved
                            (not all joined: unknown -- the caller reconstructs and counts)

A scan's frame is a coarse bone reconstruction whose pieces are counted
(:mod:`.scan`); almost every frame of a clip is one piece, and proving it from
a few thousand sphere pairs costs a tenth of making the voxels. The proof,
for a Euclidean frame on its own grid (every sphere inside it):

* A sphere's voxels (lattice points q with ``fl(|q - c|^2) < r^2``, the
  kernels' predicate) are 26-connected. Radius < 1: all lie within 1 of the
  centre, so any two differ by at most 1 on each axis. Radius >= 1: from any of
  them, stepping each coordinate that is at least 1/2 from the centre's one
  voxel towards it never increases a coordinate's distance (nor, rounding being
  monotone, the computed sum), and ends among the voxels within 1/2 of the
  centre on every axis -- all 26-adjacent and inside (|q - c|^2 <= 3/4 < r^2);
  so such a sphere has voxels.
* Two spheres with ``d + sqrt(3) + MARGIN < r_i + r_j`` (the smaller one of
  radius >= 1) make one connected set: if the smaller lies inside the larger
  with ``d + r_s + MARGIN / 2 <= r_l``, all its voxels are the larger one's;
  otherwise the two balls' lens holds a ball of radius ``> sqrt(3)/2 + MARGIN / 4``
  (when ``d < r_l - r_s`` the lens is the smaller ball itself), and any ball that
  big holds a lattice point -- inside both by MARGIN / 4, far beyond the
  predicate's rounding: a shared voxel.
* A small sphere (radius < BIG = 2: the skin's and thin tips' points, which the
  lemma cannot join) is tested voxel by voxel (a few dozen at most): it has no
  voxel, or one of its voxels is next to (or is) a voxel of a sphere already
  joined (big, or small and joined before it: a finger tip's chain) -- the
  kernels' own predicate, exactly.
* The big spheres all joined, every small one joined or empty: the frame's
  voxels (their union) are one piece.

Nothing is assumed of a pose: the pairs are tested at each frame's posed
centres (bones that stretch, smooth joints), so a pair that parted only fails to
prove -- never proves wrongly. The rest frame only chooses which pairs to try.
"""

from __future__ import annotations

import numpy as np

from volanim_core.reconstruct._whole_kernels import touches_any
from volanim_core.reconstruct.plan import posed_centres
from volanim_core.reconstruct.radii import radius_squared
from volanim_core.rig.connectivity import Tskel

MARGIN = 0.05  # voxels: what a shared voxel is inside both spheres by, at least
SURE = np.sqrt(3.0) + MARGIN  # r_i + r_j - d beyond it: the two spheres are joined
NEAREST = 16  # partners tried per sphere, nearest first
BIG = 2.0  # radius: a smaller sphere's voxels are tested one by one (_whole_kernels.py), not proved by the lemma


class WholeProof:
    """``proves(frame)``: True when the frame's reconstruction is surely one piece (see the module docstring);
    never True for a 3-4-5 frame (another predicate)."""

    def __init__(self, rest: Tskel):
        from scipy.spatial import cKDTree

        self.n = len(rest)
        self.usable = rest.metric == "euclid" and self.n > 0
        empty = np.zeros(0, np.int64)
        self.i = self.j = self.small = empty
        self.partners = np.zeros((0, NEAREST + 1), np.int64)
        self.r2 = radius_squared(rest.dt)
        if not self.usable or self.n < 2:
            return
        r = np.sqrt(self.r2)
        p = posed_centres(rest)
        big = self.big = r >= BIG
        self.small = np.flatnonzero(~big)
        k = min(NEAREST + 1, self.n)
        dist, nn = cKDTree(p).query(p, k=k, workers=-1)  # each sphere's nearest, itself first
        # a small sphere's partners: its nearest spheres, big or small (a finger tip's chain)
        self.partners = np.where(nn[self.small] == self.small[:, None], -1, nn[self.small])
        i = np.repeat(np.arange(self.n), k - 1)
        j, d = nn[:, 1:].ravel(), dist[:, 1:].ravel()
        pair = i < j
        i, j, d = i[pair], j[pair], d[pair]
        pair = big[i] & big[j] & (r[i] + r[j] - d > SURE)
        i, j = _joined_up(p, r, big, i[pair], j[pair])
        slack = r[i] + r[j] - np.linalg.norm(p[i] - p[j], axis=1)  # how deep each pair overlaps at rest
        same = rest.bone[i] == rest.bone[j]
        tree = _spanning_forest(self.n, i[same], j[same], slack[same])
        # each bone's spheres by a spanning forest of their deepest overlaps (a rigid bone keeps them all);
        # every pair of different bones' spheres (the joints: a pose may part some of them)
        self.i = np.concatenate([i[same][tree], i[~same]])
        self.j = np.concatenate([j[same][tree], j[~same]])

    def proves(self, frame: Tskel) -> bool:
        """True: ``frame`` (the rest frame's spheres, posed) reconstructs as one 26-connected piece."""
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components

        if not self.usable or len(frame) != self.n or frame.metric != "euclid":
            return False
        if self.n == 1:
            return True
        r2 = radius_squared(frame.dt)
        if not np.array_equal(r2, self.r2):
            return False  # other radii than the rest frame's: nothing was prepared for them
        r = np.sqrt(r2)
        c = posed_centres(frame)
        d = np.linalg.norm(c[self.i] - c[self.j], axis=1)
        ok = r[self.i] + r[self.j] - d > SURE
        graph = coo_matrix((np.ones(int(ok.sum()), np.int8), (self.i[ok], self.j[ok])), shape=(self.n, self.n))
        _, label = connected_components(graph, directed=False)
        big = self.big
        groups = np.unique(label[big])
        if len(groups) > 1:
            return False
        if not len(self.small):
            return True
        in_main = big & (label == groups[0]) if len(groups) else big
        state = np.zeros(len(self.small), np.int8)  # 0 not joined yet, 1 joined, 2 no voxel
        while touches_any(c, r2, self.small, self.partners, in_main, state):
            pass  # a pass joins what touches the group so far; the next, what touches those
        return bool((state != 0).all())


def _joined_up(p, r, big, i, j, rounds: int = 8):
    """The pairs ``i, j`` and, while the big spheres they join fall in several groups, pairs that join each
    smaller group to the largest one: a dense cluster's 16 nearest spheres are all its own, so the nearest
    alone left 65 groups on the mannequin (its big spheres reach far deeper)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    n = len(r)
    nodes = np.flatnonzero(big)
    for _ in range(rounds):
        graph = coo_matrix((np.ones(len(i), np.int8), (i, j)), shape=(n, n))
        _, label = connected_components(graph, directed=False)
        groups = np.unique(label[nodes])
        if len(groups) <= 1:
            break
        main = np.bincount(label[nodes]).argmax()
        inside = nodes[label[nodes] == main]
        outside = nodes[label[nodes] != main]
        k = min(NEAREST, len(inside))
        dist, nn = cKDTree(p[inside]).query(p[outside], k=k, workers=-1)
        nn = inside[nn.reshape(len(outside), k)]
        slack = r[outside, None] + r[nn] - dist.reshape(len(outside), k)
        a, b = np.nonzero(slack > SURE)
        if not len(a):
            break
        i = np.concatenate([i, np.minimum(outside[a], nn[a, b])])
        j = np.concatenate([j, np.maximum(outside[a], nn[a, b])])
    pairs = np.unique(np.stack([i, j], 1), axis=0)
    return pairs[:, 0], pairs[:, 1]


def _spanning_forest(n: int, i: np.ndarray, j: np.ndarray, slack: np.ndarray) -> np.ndarray:
    """Which pairs make a spanning forest of the deepest overlaps (a maximum spanning forest by ``slack``):
    each bone's spheres joined by as few pairs as possible, the ones a pose is least likely to part
    (a bone that stays rigid keeps them all)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import minimum_spanning_tree

    if not len(i):
        return np.zeros(0, bool)
    # minimum_spanning_tree drops zero weights: weights 1 .. 1 + spread, deepest overlap lightest
    weight = 1.0 + (slack.max() - slack)
    mst = minimum_spanning_tree(coo_matrix((weight, (i, j)), shape=(n, n)).tocsr()).tocoo()
    chosen = set(zip(mst.row.tolist(), mst.col.tolist()))
    return np.array([(a, b) in chosen or (b, a) in chosen for a, b in zip(i.tolist(), j.tolist())], bool)
