"""The curve skeleton: a skeleton's balls made one solid body, thinned to a tree, spurs pruned.

    Skeleton (points, dt at thinness T)
      --solid-->  the union of its balls painted on a coarse grid (at most COARSE_VOXELS),
                  gaps under CLOSE voxels closed, cavities filled: a porous segmentation
                  (the frog's tissues: closing grows it by over POROUS) has gaps up to PORE x its
                  thickest radius closed too, and becomes one body whose thickness means something
      --thin-->   scikit-image's 3-D thinning: a curve, radius = the solid's distance
                  transform (a flat torso is a curve, not the medial sheet voxels give); a rod it
                  removes whole (even widths, scikit-image#3757) is thinned again one voxel wider
      --link-->   an edge where two curve balls overlap: the segment between their centres
                  lies inside the body (every point of it is inside one ball or the other)
      --bridge--> a piece cut off by a small gap (a mesh made of parts, like the ant's legs)
                  joined to the body by its shortest gap, up to BRIDGE of the body's length
      --pieces--> the largest piece by volume; small ones (specks, loose organs) are left out
                  and counted; a second large piece is refused (the object is not one body)
      --tree-->   the minimum spanning tree, an edge costing length / (sum of radii), so the
                  tree runs along thick routes
      --prune-->  leaf branches that are not limbs: a tip sticking out of its fork's ball by less
                  than PROTRUDE of its own radius (a bump), a thin one shorter than SPUR x its fork's
                  radius (Pinocchio's rule, Baran & Popovic 2007), any shorter than LIMB of the body's
                  longest path (its own scale): a stubby paw survives, a hair does not
      CurveTree (nodes, radii, edges, the solid body for rays to the surface)

:mod:`volanim_core.rig.autorig` cuts the tree into chains and bones.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from volanim_core.skeleton.points import Skeleton

SPUR = 3.0  # a thin leaf branch shorter than this x its fork's radius is pruned ...
STUB = 0.25  # ... thin: its radius under this x its fork's
PROTRUDE = 0.6  # a leaf branch whose tip sticks out of its fork's ball by less than this x its radius is a spur
LIMB = 0.1  # ... and so does one shorter than this x the body's longest path (judged at the body's own scale)
LARGE_PIECE = 0.2  # a second piece with this fraction of the largest one's volume is refused
BRIDGE = 0.08  # a bridge may cross background this fraction of the body's length (at least 6 voxels)
GAP = 3.0  # balls this many voxels apart still link (a coarse voxel's slack)
SPREAD = 4  # a coarse voxel may be this many times the thickest ball's radius, no more
COARSE_VOXELS = 8_000_000  # the solid body is remade on a grid of at most this many voxels
CLOSE = 4.0  # gaps narrower than this many voxels are closed (unlabelled seams between tissues) ...
CLOSE_SHARE = 0.12  # ... or than this x the thickest ball's radius: a mesh voxelized finer has wider gaps in voxels
POROUS = 0.05  # a body that closing grows by more than this fraction is porous (a dissected frog's tissues) ...
PORE = 1.2  # ... and its gaps narrower than this x its thickest ball's radius are closed too


@dataclass
class Body:
    """The skeleton's balls painted solid on a coarse grid: voxel ``i`` is at ``(i - pad) * step + lo``."""

    grid: np.ndarray
    lo: np.ndarray
    step: int
    pad: int
    painted: np.ndarray | None = None  # the balls as painted, before gaps were closed (None: the grid)
    porous: bool = False  # closing the seams grew the body by more than POROUS: a noisy surface

    def outline(self) -> Body:
        """The body as its balls paint it, narrow gaps open: an armpit's apex, not its closing."""
        return self if self.painted is None else Body(self.painted, self.lo, self.step, self.pad)

    def inside(self, points: np.ndarray) -> np.ndarray:
        """Whether each of ``points`` (skeleton voxel coordinates) lies in the body."""
        idx = np.rint((np.atleast_2d(points) - self.lo) / self.step + self.pad).astype(int)
        out = (idx >= 0).all(axis=1) & (idx < self.grid.shape).all(axis=1)
        out[out] = self.grid[tuple(idx[out].T)]
        return out

    def exit(self, start: np.ndarray, direction: np.ndarray) -> np.ndarray:
        d = direction / (np.linalg.norm(direction) or 1)
        t = np.arange(0, 4 * max(self.grid.shape) * self.step, 0.5 * self.step)
        for k in range(0, len(t), 64):  # most rays leave within a few steps: walk them a piece at a time
            ray = start + t[k: k + 65, None] * d
            out = np.flatnonzero(~self.inside(ray))
            if len(out):
                return ray[out[0] - 1] if out[0] > 0 else (start if k == 0 else ray[0])
        return start

    def clear(self, a: np.ndarray, b: np.ndarray) -> bool:
        """Whether the segment from ``a`` to ``b`` runs inside the body all the way."""
        n = int(np.linalg.norm(b - a) / (0.5 * self.step)) + 2
        return bool(self.inside(a + np.linspace(0, 1, n)[:, None] * (b - a)).all())


class NotRiggable(ValueError):
    """The skeleton cannot be rigged (no points, or a body in pieces); the message says where."""


@dataclass
class CurveTree:
    """Tree nodes (skeleton voxel coordinates), their radii and the tree's edges."""

    points: np.ndarray  # (M, 3) float64
    radius: np.ndarray  # (M,)
    edges: np.ndarray  # (M - 1, 2) int
    dropped: list[tuple[int, np.ndarray]] = field(default_factory=list)  # (points, centre) of pieces left out
    body: Body | None = None  # the solid body the tree was thinned from
    pruned: list[tuple[float, np.ndarray]] = field(default_factory=list)  # (length, tip) of branches cut off

    def surface(self, start: np.ndarray, direction: np.ndarray) -> np.ndarray:
        """Where the ray from ``start`` along ``direction`` leaves the body (``start`` without a body)."""
        if self.body is None:
            return start
        return self.body.exit(start, direction)

    def neighbours(self) -> list[list[int]]:
        adj: list[list[int]] = [[] for _ in range(len(self.points))]
        for a, b in self.edges:
            adj[a].append(int(b))
            adj[b].append(int(a))
        return adj


def _link(p: np.ndarray, r: np.ndarray, k: int = 24):
    """Sparse graph of overlapping balls among each ball's ``k`` nearest, cost length / (r_a + r_b)."""
    from scipy.sparse import coo_matrix
    from scipy.spatial import cKDTree

    n = len(p)
    k = min(k, n - 1)
    d, j = cKDTree(p).query(p, k + 1)
    i = np.repeat(np.arange(n), k + 1)
    d, j = d.ravel(), j.ravel()
    ok = (j != i) & (j < n) & (d <= r[i] + r[np.minimum(j, n - 1)] + GAP)
    i, j, d = i[ok], j[ok], d[ok]
    cost = np.maximum(d, 1e-9) / (r[i] + r[j])
    return coo_matrix((cost, (i, j)), shape=(n, n)).tocsr()


def _where(p: np.ndarray) -> str:
    return "(" + ", ".join(f"{v:.0f}" for v in p) + ")"


def _bridge(graph, p, r):
    """The graph with each piece joined to the body by its shortest gap when that gap is at most BRIDGE
    of the body's length: a segmentation (or a mesh made of parts, like pyvista's ant) that cuts a limb
    off at a thin joint still gives the limb to the body, its nearest end to the nearest ball."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    count, label = connected_components(graph, directed=False)
    if count == 1:
        return graph
    volume = np.bincount(label, weights=r**3, minlength=count)
    body = label == int(np.argmax(volume))
    rows, cols, costs = [], [], []
    reach = max(6.0, BRIDGE * float(np.ptp(p, axis=0).max()))
    changed = True
    while changed:
        changed = False
        tree = cKDTree(p[body])
        index = np.flatnonzero(body)
        for c in np.argsort(-volume):
            members = np.flatnonzero(label == c)
            if body[members[0]]:
                continue
            d, k = tree.query(p[members], k=min(8, len(index)))
            d, k = np.atleast_2d(d.T).T, np.atleast_2d(k.T).T
            gap = d - r[members][:, None] - r[index[k]]
            i, j = np.unravel_index(int(np.argmin(gap)), gap.shape)
            if gap[i, j] <= reach:
                a, b = members[i], index[k[i, j]]
                rows.append(a)
                cols.append(b)
                costs.append(max(d[i, j], 1e-9) / (r[a] + r[b]))
                body[members] = True
                changed = True
    if not rows:
        return graph
    extra = coo_matrix((costs, (rows, cols)), shape=graph.shape).tocsr()
    return graph + extra


def _largest_piece(graph, p, r):
    from scipy.sparse.csgraph import connected_components

    count, label = connected_components(graph, directed=False)
    volume = np.bincount(label, weights=r**3, minlength=count)
    order = np.argsort(-volume)
    main = order[0]
    big = [c for c in order[1:] if volume[c] >= LARGE_PIECE * volume[main]]
    if big:
        where = "; ".join(f"{np.count_nonzero(label == c)} balls around {_where(p[label == c].mean(axis=0))}"
                          for c in [main, *big])
        raise NotRiggable(f"the skeleton is in {count} pieces, {1 + len(big)} of them large ({where}): rig each "
                          "body separately, or lower --thinness so that thin parts join them")
    dropped = [(int(np.count_nonzero(label == c)), p[label == c].mean(axis=0)) for c in order[1:]]
    return label == main, dropped


def _diameter(adj: list[set], p: np.ndarray) -> float:
    """The length of the tree's longest path (two Dijkstra sweeps): the body's own scale."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import dijkstra

    rows = np.array([a for a in range(len(adj)) for _ in adj[a]], np.int64)
    cols = np.array([b for a in range(len(adj)) for b in adj[a]], np.int64)
    if len(rows) == 0:
        return 0.0
    graph = coo_matrix((np.linalg.norm(p[rows] - p[cols], axis=1) + 1e-9, (rows, cols)), shape=(len(p),) * 2)
    graph = graph.tocsr()
    first = dijkstra(graph, indices=int(rows[0]))
    far = int(np.argmax(np.where(np.isfinite(first), first, -1)))
    second = dijkstra(graph, indices=far)
    return float(np.max(second[np.isfinite(second)]))


def _prune(adj: list[set], p: np.ndarray, r: np.ndarray, factor: float,
           floor: float = 0.0) -> list[tuple[float, np.ndarray]]:
    """Remove leaf branches that are not limbs, in place, round by round; return the (length, tip) of
    each removed branch that stuck out as a limb does (thin or short: what the proposal says it dropped).

    A leaf branch is a limb when its tip sticks out of its fork's ball by ``PROTRUDE`` of its own
    radius: a stubby paw does, a thinning's spur (a bump of the surface) does not. A thin branch (its
    radius under ``STUB`` of its fork's) must also be ``factor`` x its fork's radius long (Pinocchio's
    rule, Baran & Popovic 2007): a hair of noise is not a limb however far it reaches. A fork keeps at
    least two branches (its longest short ones), so a limb ending in a Y keeps one tip."""
    dropped = []
    while True:
        at_fork: dict[int, list[tuple[float, list[int], bool]]] = {}
        for leaf in [i for i in range(len(adj)) if len(adj[i]) == 1]:
            path, prev, cur, length = [leaf], leaf, next(iter(adj[leaf])), 0.0
            length += float(np.linalg.norm(p[cur] - p[prev]))
            while len(adj[cur]) == 2:
                prev, cur = cur, next(k for k in adj[cur] if k != prev)
                path.append(prev)
                length += float(np.linalg.norm(p[cur] - p[prev]))
            if len(adj[cur]) < 3:
                continue
            own = float(np.median(r[path]))
            out = float(np.linalg.norm(p[leaf] - p[cur])) - r[cur]
            stub = out < PROTRUDE * own
            if stub or length < floor or (own < STUB * r[cur] and length < factor * r[cur]):
                at_fork.setdefault(cur, []).append((length, path, not stub))
        removed = False
        for fork, branches in at_fork.items():
            branches.sort(key=lambda b: b[0])
            keep = max(0, 2 - (len(adj[fork]) - len(branches)))  # branches that must stay
            for length, path, limb_like in branches[: len(branches) - keep]:
                if limb_like:  # it stuck out like a limb: say so
                    dropped.append((length, p[path[0]]))
                for a in path:
                    for b in adj[a]:
                        adj[b].discard(a)
                    adj[a].clear()
                removed = True
        if not removed:
            return dropped


def solid(skeleton: Skeleton, *, close: float = CLOSE, step=None) -> tuple[np.ndarray, np.ndarray, Body]:
    """The medial points ``(points, radii)`` of the body the skeleton's balls make, remade solid.

    The balls are painted on a grid coarse enough to hold at most ``COARSE_VOXELS`` voxels, gaps
    narrower than ``close`` voxels (or ``CLOSE_SHARE`` of the thickest ball's radius) are closed, cavities
    filled, and the solid is thinned to a curve
    (scikit-image's ``skeletonize``, Lee's 3-D thinning) with its distance transform as radius: a
    porous segmentation (the frog's tissues, unlabelled seams between muscles) becomes one body
    whose thickness means something, and a flat part (a torso) a curve rather than a sheet.
    ``step()``, if given, is called once the solid is made, before it is thinned (the two long stages).
    """
    import edt
    from scipy import ndimage

    from volanim_core.rig._curve_kernels import paint_balls

    lo = np.floor(skeleton.points.min(axis=0) - skeleton.dt.max() - 1)
    hi = skeleton.points.max(axis=0) + skeleton.dt.max() + 1
    h = max(1, int(np.ceil((np.prod(hi - lo) / COARSE_VOXELS) ** (1 / 3))))
    if h > SPREAD * max(float(skeleton.dt.max()), 1.0):  # two balls 2^30 voxels apart thinned for minutes
        raise NotRiggable(f"the skeleton's points span {' x '.join(f'{v:.0f}' for v in hi - lo)} voxels while its "
                          f"thickest ball's radius is {skeleton.dt.max():.3g} voxels: on a grid coarse enough to hold "
                          f"that span its body would vanish; parts this far apart are not one body (crop the "
                          "scan to the creature)")
    # the gap between a rabbit's tail and its body is a voxel or two at 160 voxels along the rabbit, twice that at
    # 320, where a closing of CLOSE voxels left it open: no chain reached the tail or a hind foot (#86). Every
    # body at 160 voxels and the scans (the thickest radius 13-33 voxels) close CLOSE voxels, as before
    close = max(close, CLOSE_SHARE * float(skeleton.dt.max())) if close else 0.0
    steps = max(1, int(round(close / 2 / h)))  # a closing by k steps bridges gaps of about 2 k
    pad = steps + 1
    shape = tuple(int(v) for v in np.ceil((hi - lo) / h) + 1 + 2 * pad)
    grid = np.zeros(shape, bool)
    centres = (skeleton.points - lo) / h + pad
    paint_balls(centres, np.maximum(skeleton.dt, 0.5) / h + 0.5, grid)
    painted, porous = grid, False
    cross = ndimage.generate_binary_structure(3, 1)
    if close:
        grid = ndimage.binary_fill_holes(ndimage.binary_closing(painted, cross, iterations=steps))
        porous = grid.sum() > (1 + POROUS) * painted.sum()
        if porous:  # tissues with seams everywhere: close the pores too
            pores = max(steps, int(round(PORE * skeleton.dt.max() / 2 / h)))
            painted = np.pad(painted, pores - steps)  # room for the wider closing at the borders
            grid = ndimage.binary_closing(painted, cross, iterations=pores)
            pad += pores - steps
    grid = ndimage.binary_fill_holes(grid)
    if step is not None:
        step()
    dist = edt.edt(grid)
    curve = _thin(grid, dist)
    idx = np.argwhere(curve)
    return (idx - pad) * h + lo, dist[curve] * h, Body(grid, lo, h, pad, painted, porous)


def _thin(grid: np.ndarray, dist: np.ndarray) -> np.ndarray:
    """Lee's 3-D thinning of ``grid``, mended where scikit-image removes a whole piece: a bar of even width
    (scikit-image#3757: a 4 x 4 rod leaves nothing), a box, a flat sheet. Such a piece that is long (a rod, a
    tail: its length over twice its width) is thinned again grown by one voxel along one or more axes, which
    changes its widths' parity; any other piece keeps its deepest voxel, a ball (a box has nothing to bend),
    so two boxes are still two pieces."""
    from scipy import ndimage
    from skimage.morphology import skeletonize as thin

    curve = thin(grid).astype(bool)
    labels, _ = ndimage.label(grid)
    kept = set(np.unique(labels[curve]).tolist())
    for piece, box in enumerate(ndimage.find_objects(labels), 1):
        if piece in kept:
            continue
        mask = labels[box] == piece
        line = _thin_grown(mask) if _long(mask) else None
        if line is None:
            line = np.zeros_like(mask)
            line[np.unravel_index(np.argmax(np.where(mask, dist[box], 0)), mask.shape)] = True
        curve[box] |= line
    return curve


def _long(mask: np.ndarray) -> bool:
    """A piece whose longest principal spread is over twice its next: a rod, not a box or a sheet."""
    spread = np.sort(np.linalg.eigvalsh(np.cov(np.argwhere(mask).T.astype(float)))) if mask.sum() > 3 else None
    return spread is not None and spread[2] > 4 * max(spread[1], 0.25)


def _thin_grown(mask: np.ndarray) -> np.ndarray | None:
    """The thinning of ``mask`` grown by one voxel along x, y, z or two or three of them (the first that leaves
    a curve), cut back to ``mask``; None if none does."""
    from skimage.morphology import skeletonize as thin

    padded = np.pad(mask, 1)
    for axes in ((0,), (1,), (2,), (0, 1), (0, 2), (1, 2), (0, 1, 2)):
        grown = padded.copy()
        for axis in axes:
            grown[(slice(None),) * axis + (slice(1, None),)] |= grown[(slice(None),) * axis + (slice(None, -1),)]
        line = thin(grown).astype(bool)[1:-1, 1:-1, 1:-1] & mask
        if line.any():
            return line
    return None


def curve_tree(skeleton: Skeleton, *, spur: float = SPUR, step=None) -> CurveTree:
    """The curve skeleton of ``skeleton`` (all its points: pass ``skeleton.at(thinness)``); ``step()``, if
    given, is called after each of its stages (the solid made, thinned, linked into a tree): three calls."""
    from scipy.sparse.csgraph import minimum_spanning_tree

    if len(skeleton) == 0:
        raise NotRiggable("the skeleton has no points at this thinness: lower --thinness")
    step = step or (lambda: None)
    p, r, body = solid(skeleton, step=step)
    step()
    if len(p) == 1:
        return CurveTree(p, r, np.zeros((0, 2), np.int64), body=body)
    graph = _bridge(_link(p, r), p, r)
    main, dropped = _largest_piece(graph, p, r)
    p, r = p[main], r[main]
    sub = graph[main][:, main]
    mst = minimum_spanning_tree(sub + sub.T).tocoo()
    adj = [set() for _ in range(len(p))]
    for a, b in zip(mst.row, mst.col):
        adj[a].add(int(b))
        adj[b].add(int(a))
    pruned = _prune(adj, p, r, spur, LIMB * _diameter(adj, p))
    step()
    alive = np.array([len(a) > 0 for a in adj]) if len(p) > 1 else np.ones(1, bool)
    renum = np.cumsum(alive) - 1
    edges = np.array(sorted((renum[a], renum[b]) for a in range(len(adj)) for b in adj[a] if a < b),
                     np.int64).reshape(-1, 2)
    return CurveTree(p[alive], r[alive], edges, dropped, body, pruned)


def balls(skeleton: Skeleton) -> np.ndarray:
    """The union of the skeleton's balls on its own voxel grid: the body its rest pose re-grows."""
    from volanim_core.rig._curve_kernels import paint_balls

    if len(skeleton) == 0:
        return np.zeros((1, 1, 1), bool)
    shape = tuple(int(v) for v in np.ceil(skeleton.points.max(axis=0) + skeleton.dt.max()) + 2)
    out = np.zeros(shape, bool)
    paint_balls(skeleton.points.astype(np.float64), np.maximum(skeleton.dt, 0.5), out)
    return out
