"""The walks auto-rig and its templates take on a curve skeleton's tree, and where a branch bends.

    CurveTree (rig/curve_skeleton.py) --Tree--> paths between nodes, ends, forks, one walk per root
    a branch's points and radii --splits--> where it bends or its thickness changes (Douglas-Peucker on the
                                            smoothed curve x, y, z, 2 r)

Used by rig/autorig.py (chains) and rig/templates.py (the humanoid and quadruped fits); apart from both so
neither imports the other.
"""

from __future__ import annotations

from collections import deque

import numpy as np

from volanim_core.rig.curve_skeleton import CurveTree

THICKNESS_WEIGHT = 2.0  # a radius change of 1 voxel counts as a bend of 2 voxels
BEND = 0.6  # a branch is split where it strays more than this x its radius from its chord (at least 2 voxels)
TIP_REACH = 3.0  # an end is extended to the surface only when that is within this x its radius


class Tree:
    """A CurveTree with the walks autorig needs: paths between nodes, ends, forks."""

    def __init__(self, curve: CurveTree, left: np.ndarray, adj: list[list[int]] | None = None):
        self.p, self.r = curve.points, curve.radius
        self.adj = curve.neighbours() if adj is None else adj
        self.curve = curve
        self.left = left / np.linalg.norm(left)  # +x physical, in voxel index space
        self._parents: dict[int, np.ndarray] = {}  # one breadth-first walk per root, however many paths

    def with_adjacency(self, adj: list[list[int]]) -> Tree:
        """The same nodes with other edges (a trimmed copy)."""
        return Tree(self.curve, self.left, adj)

    def degree(self, i: int) -> int:
        return len(self.adj[i])

    def ends(self) -> list[int]:
        return [i for i in range(len(self.p)) if self.degree(i) == 1]

    def parents(self, root: int) -> np.ndarray:
        """Each node's parent walking from ``root`` (-1 at the root, -2 where unreachable)."""
        if root in self._parents:
            return self._parents[root]
        parent = np.full(len(self.p), -2)
        parent[root] = -1
        todo = deque([root])
        while todo:
            a = todo.popleft()
            for b in self.adj[a]:
                if parent[b] == -2:
                    parent[b] = a
                    todo.append(b)
        self._parents[root] = parent
        return parent

    def path(self, a: int, b: int) -> list[int]:
        """Node indices from ``a`` to ``b`` along the tree."""
        parent = self.parents(a)
        out = [b]
        while out[-1] != a:
            out.append(int(parent[out[-1]]))
        return out[::-1]

    def length(self, path) -> np.ndarray:
        """Arc length at each node of ``path``."""
        steps = np.linalg.norm(np.diff(self.p[path], axis=0), axis=1)
        return np.concatenate([[0.0], np.cumsum(steps)])

    def median(self, a: int, b: int, c: int) -> int:
        """The node where the paths between three nodes meet."""
        on_ab = set(self.path(a, b))
        for n in self.path(c, a):
            if n in on_ab:
                return n
        return a

    def tip(self, end: int, inset: bool = False) -> np.ndarray:
        """An end extended along its branch to the body's surface: thinning stops short of the tip.
        With ``inset``, one end radius short of the surface, where a limb's last ball is centred
        (the end of a finger's or a toe's axis), but never behind the end itself. An end whose ball
        overlaps another end's is its own tip: the body goes on there (a ring cut where the tree's two
        ends meet; Bob voxelized at 320 voxels drew each end 73 voxels into the other chain's flesh, the
        last bones crossed and one, turned 45 degrees, tore the ring)."""
        if self.meets_an_end(end):
            return self.p[end].astype(np.float64)
        back = self.branch(end)
        s = self.length(back)
        k = int(np.searchsorted(s, max(self.r[end], 2.0)))
        k = min(k, len(back) - 1)
        direction = self.p[end] - self.p[back[k]]
        surface = self.curve.surface(self.p[end], direction)
        if np.linalg.norm(surface - self.p[end]) > TIP_REACH * self.r[end] + 2:
            surface = self.p[end]  # a curled end points back along its limb: its ray runs inside, far
        if not inset:
            return surface
        reach = np.linalg.norm(surface - self.p[end])
        return self.p[end] + (surface - self.p[end]) * max(0.0, reach - self.r[end]) / (reach or 1)

    def meets_an_end(self, end: int) -> bool:
        """Whether another end's ball overlaps this end's."""
        ends = [i for i in range(len(self.p)) if i != end and self.degree(i) == 1]
        return any(np.linalg.norm(self.p[i] - self.p[end]) < self.r[i] + self.r[end] for i in ends)

    def branch(self, end: int) -> list[int]:
        """Nodes from ``end`` along its branch to the first node that is not a plain link (a fork, or
        the far end of a lone chain), both included. Walks the edges as they are now (no cache)."""
        out = [end]
        prev, cur = end, self.adj[end][0] if self.adj[end] else end
        while self.degree(cur) == 2:
            out.append(cur)
            prev, cur = cur, next(k for k in self.adj[cur] if k != prev)
        return out + [cur] if cur != end else out

def smooth(xyz: np.ndarray, width: int = 2) -> np.ndarray:
    """A moving average over ``2 width + 1`` nodes (ends kept): the thinned curve's voxel stairs are not bends."""
    if len(xyz) <= 2 * width + 1:
        return xyz
    kernel = np.ones(2 * width + 1) / (2 * width + 1)
    out = xyz.astype(np.float64).copy()
    for axis in range(xyz.shape[1]):
        out[width:-width, axis] = np.convolve(xyz[:, axis], kernel, mode="valid")
    return out


def splits(xyz: np.ndarray, r: np.ndarray, *, count: int | None = None, skip: float = 0.0,
           straight: float = 0.0) -> list[int]:
    """Interior indices where a branch should bend: Douglas-Peucker on the smoothed curve (x, y, z, 2 r).

    With ``count``, up to that many splits (the largest deviations first); otherwise every split whose
    deviation exceeds BEND x the branch's mean radius (at least 2 voxels) and ``straight`` x its length
    (on a porous body, whose surface is noise: a frog's hind leg, 700 voxels at radius 7, bends at its
    folds, not at every wobble). No
    piece is made shorter than the branch's mean radius (a bone is longer than it is thick), and none
    within ``skip`` of the start: a limb thins where it leaves its fork's ball, which is not a joint.
    """
    curve = smooth(np.column_stack([xyz, THICKNESS_WEIGHT * np.asarray(r)]))
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(xyz, axis=0), axis=1))])
    shortest = float(np.mean(r))
    tol = max(2.0, BEND * float(np.mean(r)), straight * float(arc[-1]))
    chosen: list[int] = []
    first = min(int(np.searchsorted(arc, skip)), len(curve) - 1)  # the chord starts out of the fork's ball
    spans = [(first, len(curve) - 1)]
    while spans:
        best = None
        for a, b in spans:
            if b - a < 2:
                continue
            dev = _deviation(curve[a:b + 1])
            room = (arc[a:b + 1] - arc[a] >= shortest) & (arc[b] - arc[a:b + 1] >= shortest)
            if not room.any():
                continue
            dev = np.where(room, dev, -1.0)
            k = int(np.argmax(dev))
            if best is None or dev[k] > best[0]:
                best = (dev[k], a, b, a + k)
        if best is None or (count is None and best[0] <= tol) or (count is not None and len(chosen) >= count):
            break
        _, a, b, k = best
        chosen.append(k)
        spans.remove((a, b))
        spans += [(a, k), (k, b)]
    return sorted(chosen)


def _deviation(curve: np.ndarray) -> np.ndarray:
    a, b = curve[0], curve[-1]
    ab = b - a
    n2 = float(ab @ ab)
    if n2 == 0:
        return np.linalg.norm(curve - a, axis=1)
    t = np.clip((curve - a) @ ab / n2, 0, 1)
    return np.linalg.norm(curve - (a + t[:, None] * ab), axis=1)
