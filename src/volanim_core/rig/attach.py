"""Attaching skeleton points to bones (connectivity).

The rules, measured against the mannequin's ground-truth limb membership
(``benchmarks/bench_connect.py``; README gives the error rates):

* ``attach_nearest_bone`` -- the nearest segment. Ignores the shape: a point
  in the armpit may go to the torso or the arm by a hair.
* ``auto_connect(method="path")`` -- the nearest segment whose straight path
  from the point to the segment's closest point stays inside the segmented
  volume (sampled every half voxel); otherwise the next nearest. The default.
* ``auto_connect(method="path-or-nearest")`` -- the same, and points with no
  such path (an object made of separate parts, like the frog's organs) go to
  the nearest bone; the report counts them.
* ``auto_connect(method="geodesic")`` -- the seed pipeline's graph idea done
  as shortest paths: a k-nearest-neighbour graph of the skeleton points (edges
  inside the mask), seeded by the points nearest to each bone; every point
  takes the bone whose seed it reaches by the shortest path.

* ``auto_connect(method="fitted")`` -- nearest, then every point whose ball reaches past its bone's
  own tube (fitted along the limb's middle) goes to the bone above: the armpit to the torso, not the
  arm (:mod:`.limb_tubes`; #60).

* ``auto_connect(method="pieces")`` -- a body in separate pieces (limbs that are shells of their own):
  each piece's points go to the nearest of the bones lying in that piece (:mod:`.pieces`; #62), then
  each bone's flesh is made one piece: a ball touching only other bones' balls goes to the bone it
  touches most (:mod:`.islands`), so no pose of either floats it off as a speck.

``auto_connect`` never overwrites points already attached unless asked, and
reports how many it left unattached and why -- it never fails silently.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from volanim_core.progress import Reporter
from volanim_core.rig.bones import BoneSkeleton
from volanim_core.rig.connectivity import Connectivity
from volanim_core.rig.islands import one_piece_each
from volanim_core.rig.limb_tubes import carry_up
from volanim_core.rig.nearest import attach_nearest_bone, segment_distances
from volanim_core.rig.pieces import attach_by_piece
from volanim_core.rig.pose import root_bones
from volanim_core.skeleton.points import Skeleton

UNATTACHED = -1
PART = 131072  # points attached between two progress reports (nearest, path): a few tenths of a second


def connect_nearest(skeleton: Skeleton, bones: BoneSkeleton) -> Connectivity:
    """A connectivity attaching every skeleton point to its nearest bone."""
    bone = attach_nearest_bone(skeleton.points, bones)
    conn = Connectivity(root_bones(bones), skeleton.points, skeleton.dt, skeleton.thinness, bone,
                        skeleton.metric, geometry=skeleton.geometry)
    return conn.grouped()


@dataclass
class AutoConnectReport:
    """What auto-connect did: counts and, for points it could not attach, why."""

    attached: int = 0
    kept: int = 0  # already attached and not overwritten
    unattached: int = 0
    fallback: int = 0  # path-or-nearest: attached to the nearest bone for want of a path
    reasons: dict = field(default_factory=dict)

    def __str__(self) -> str:
        text = f"attached {self.attached} points"
        if self.kept:
            text += f", kept {self.kept} existing attachments"
        if self.fallback:
            text += f" ({self.fallback} with no straight path inside the volume went to the nearest bone)"
        if self.unattached:
            why = "; ".join(f"{n}: {r}" for r, n in self.reasons.items())
            text += f", left {self.unattached} unattached ({why})"
        return text


def _path_method(points, bones, mask):
    from volanim_core.rig._attach_kernels import first_reachable

    segs = bones.segments()
    order = np.empty((len(points), len(bones)), np.int64)
    for s in range(0, len(points), 65536):
        order[s : s + 65536] = np.argsort(segment_distances(points[s : s + 65536], segs), axis=1, kind="stable")
    out = np.empty(len(points), np.int32)
    first_reachable(np.ascontiguousarray(points, np.int64), np.ascontiguousarray(segs), order,
                    np.ascontiguousarray(mask, np.bool_), 0.5, out)
    return out


def _geodesic_method(points, bones, mask, k=10):
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import dijkstra
    from scipy.spatial import cKDTree

    from volanim_core.rig._attach_kernels import _path_inside_many

    n = len(points)
    tree = cKDTree(points)
    dist, nbr = tree.query(points, k=min(k + 1, n))
    rows = np.repeat(np.arange(n), nbr.shape[1] - 1)
    cols = nbr[:, 1:].ravel()
    w = dist[:, 1:].ravel()
    ok = np.isfinite(w) & (cols < n)
    rows, cols, w = rows[ok], cols[ok], w[ok]
    inside = _path_inside_many(np.ascontiguousarray(points, np.float64), rows, cols,
                               np.ascontiguousarray(mask, np.bool_), 0.5)
    rows, cols, w = rows[inside], cols[inside], w[inside]
    graph = coo_matrix((np.r_[w, w], (np.r_[rows, cols], np.r_[cols, rows])), shape=(n, n)).tocsr()
    d = segment_distances(points, bones.segments())
    near = d.argmin(1)
    seeds = np.flatnonzero(d.min(1) <= 1.5)  # points on a bone seed it
    if not len(seeds):
        return np.full(n, UNATTACHED, np.int32)
    _, _, source = dijkstra(graph, directed=False, indices=seeds, min_only=True, return_predecessors=True)
    out = np.full(n, UNATTACHED, np.int32)
    reached = source >= 0
    out[reached] = near[source[reached]]
    return out


def auto_connect(points: np.ndarray, bones: BoneSkeleton, mask: np.ndarray, *, method: str = "path",
                 current: np.ndarray | None = None, overwrite: bool = False,
                 which: np.ndarray | None = None, radii: np.ndarray | None = None, progress=None, cancel=None
                 ) -> tuple[np.ndarray, AutoConnectReport]:
    """Attach points to bones, checking that the attachment runs inside the object.

    Parameters
    ----------
    points : (N, 3) int ndarray, voxel coordinates
    bones : BoneSkeleton
    mask : (X, Y, Z) bool ndarray, the segmented object
    method : {'path', 'path-or-nearest', 'geodesic', 'nearest', 'fitted', 'pieces'}
    current : (N,) int ndarray, optional
        Existing attachments (-1 = none); kept unless ``overwrite``.
    which : (N,) bool ndarray, optional
        Only these points are considered (a cube or lasso selection).
    radii : (N,) ndarray, the points' distance transform (needed by ``fitted``: the limbs' tubes are
        measured on every point, whichever are attached)
    progress, cancel : optional
        ``progress(done, total)`` in points, ``cancel()`` returning True stops it (:class:`Cancelled`);
        the nearest and path methods go in parts of ``PART`` points, the others (which weigh every point
        together) report their start and end

    Returns
    -------
    bone : (N,) int32 ndarray, -1 where unattached
    report : AutoConnectReport
    """
    if not len(bones):
        raise ValueError("the bone skeleton has no bones to attach to")
    points = np.asarray(points)
    n = len(points)
    current = np.full(n, UNATTACHED, np.int32) if current is None else np.asarray(current, np.int32).copy()
    which = np.ones(n, bool) if which is None else np.asarray(which, bool)
    todo = which & ((current == UNATTACHED) | overwrite)
    report = AutoConnectReport(kept=int((which & ~todo).sum()))
    if not todo.any():
        return current, report
    sub = points[todo]
    step = Reporter(progress, cancel)
    step(0, len(sub))
    if method in ("nearest", "path", "path-or-nearest"):  # each point on its own: in parts, with progress
        found = np.empty(len(sub), np.int32)
        for s in range(0, len(sub), PART):
            part = sub[s:s + PART]
            found[s:s + PART] = attach_nearest_bone(part, bones) if method == "nearest" else \
                _path_method(part, bones, mask)
            step(min(s + PART, len(sub)), len(sub))
        if method == "path-or-nearest":
            lost = found == UNATTACHED
            found[lost] = attach_nearest_bone(sub[lost], bones)
            report.fallback = int(lost.sum())
    elif method == "geodesic":
        found = _geodesic_method(sub, bones, mask)
    elif method == "pieces":
        found = attach_by_piece(sub, bones, mask)
        if radii is not None and len(radii) == n:
            found = one_piece_each(sub, radii[todo], found)
    elif method == "fitted":
        if radii is None or len(radii) != n:
            raise ValueError("the 'fitted' method needs every point's radius (its distance transform)")
        found = carry_up(points, radii, bones, attach_nearest_bone(points, bones))[todo]
    else:
        raise ValueError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
    step(len(sub), len(sub))
    if mask is not None and method not in ("nearest", "fitted", "pieces"):
        outside = ~mask[tuple(sub.T)]
        if outside.any():
            report.reasons["the point itself lies outside the segmented volume"] = int(outside.sum())
    missing = found == UNATTACHED
    no_path = int(missing.sum()) - sum(report.reasons.values())
    if no_path > 0:
        report.reasons[("no bone reachable by a straight path inside the volume" if method == "path"
                        else "not connected to any bone through the skeleton graph")] = no_path
    current[todo] = found
    report.attached = int((~missing).sum())
    report.unattached = int(missing.sum())
    return current, report


METHODS = ("nearest", "path", "path-or-nearest", "geodesic", "fitted", "pieces")
NEEDS_MASK = ("path", "path-or-nearest", "geodesic", "pieces")


def connect(skeleton: Skeleton, bones: BoneSkeleton, *, method: str = "nearest",
            mask: np.ndarray | None = None, progress=None, cancel=None) -> tuple[Connectivity, AutoConnectReport]:
    """Attach a skeleton's points to bones by ``method`` (the studio's auto-connect, all points).

    ``mask`` (the segmented object on the skeleton's voxel grid) is needed by the methods in ``NEEDS_MASK``:
    a path must run inside it, or its pieces are the body's. Unattached points are left out of the connectivity
    (a ``.connect`` lists attached points only) and counted in the report.
    """
    if method not in METHODS:
        raise ValueError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
    if method in NEEDS_MASK and mask is None:
        why = "its pieces are the body's" if method == "pieces" else "a path must run inside it"
        raise ValueError(f"the {method!r} method needs the segmented volume ({why})")
    if mask is not None and len(skeleton) and (skeleton.points.max(axis=0) >= np.array(mask.shape)).any():
        raise ValueError(f"the segmented volume ({'x'.join(map(str, mask.shape))} voxels) does not hold the "
                         "skeleton's points: give the scan the skeleton was made from")
    bone, report = auto_connect(skeleton.points, bones, mask, method=method, radii=skeleton.dt, progress=progress,
                                cancel=cancel)
    keep = bone != UNATTACHED
    conn = Connectivity(root_bones(bones), skeleton.points[keep], skeleton.dt[keep], skeleton.thinness[keep],
                        bone[keep], skeleton.metric, geometry=skeleton.geometry)
    return conn.grouped(), report
