"""Auto-rig: a bone skeleton proposed from the volume's own skeleton.

    Skeleton (.mskel) --at(thinness)--> points, dt
      --curve_tree-->    CurveTree: nodes, radii, tree edges (rig/curve_skeleton.py)
      --template-->      humanoid / quadruped: ends matched by symmetry, joints at the template's
                         forks, bends and narrowings, named as the template names them (rig/templates.py)
      --or chains-->     none: a joint at every fork and end, and where a branch bends or its
                         thickness changes (a split of the branch as a curve in x, y, z and 2 x radius,
                         Douglas-Peucker); chains named by side and direction from the root
      --root order-->    from the root (the template's, or the thickest fork), parents before children
      Proposal (BoneSkeleton on the skeleton's grid, the template used, notes)

Left and right follow the scanner's convention: ``L_`` is the side towards +x in physical (LPS)
space, the patient's left, whatever the voxel axes are.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

import numpy as np

from volanim_core.rig.bones import Bone, BoneSkeleton
from volanim_core.rig.curve_skeleton import NotRiggable, curve_tree
from volanim_core.rig.tree_walks import Tree, splits
from volanim_core.skeleton.points import Skeleton

TEMPLATES = ("auto", "humanoid", "quadruped", "none")
FORK_BALL = 1.5  # no joint within this x the fork's radius of a fork: the limb is leaving the fork's ball
STRAIGHT = 0.08  # a branch of a porous body bends only where it strays this x its length (tree_walks.splits)
WIDER = 1.5  # a limb gets a joint where it leaves its fork's ball when the ball is this x its radius


@dataclass
class Proposal:
    """A proposed bone skeleton, the template that named it, and what the user should know."""

    bones: BoneSkeleton
    template: str
    notes: list[str] = field(default_factory=list)

    def __str__(self) -> str:
        return (f"{len(self.bones.bones)} bones, {len(self.bones.joints)} joints ({self.template})"
                + "".join(f"\n  {n}" for n in self.notes))


def _keys(tree: Tree) -> list[int]:
    return [i for i in range(len(tree.p)) if tree.degree(i) != 2]


def _branches(tree: Tree, root: int) -> list[list[int]]:
    """The tree cut at forks and ends into branches (node paths), each from the root's side outwards,
    in breadth-first order from the root."""
    parent = tree.parents(root)
    keys = set(_keys(tree)) | {root}
    out, todo = [], deque([root])
    while todo:
        start = todo.popleft()
        for nxt in tree.adj[start]:
            if parent[nxt] != start:
                continue
            path = [start, nxt]
            while path[-1] not in keys:
                path.append(next(k for k in tree.adj[path[-1]] if parent[k] == path[-1]))
            out.append(path)
            todo.append(path[-1])
    return out


def _direction_name(v: np.ndarray, tree: Tree, geometry) -> str:
    """SUP/INF/ANT/POST for the larger of a branch's vertical and front-back runs (LPS)."""
    d = np.asarray(geometry.direction, float).reshape(3, 3) @ (np.asarray(geometry.spacing) * v)
    if abs(d[2]) >= abs(d[1]):
        return "SUP" if d[2] > 0 else "INF"
    return "POST" if d[1] > 0 else "ANT"


def chains(tree: Tree, geometry, *, bones: int | None = None) -> BoneSkeleton:
    """Bones with no template: joints at forks and ends, and where branches bend or thin; the root is the
    thickest fork (the thickest node of a lone chain)."""
    forks = [i for i in range(len(tree.p)) if tree.degree(i) >= 3]
    root = max(forks or range(len(tree.p)), key=lambda i: tree.r[i])
    alias: dict[int, int] = {}  # a fork a voxel or two from its parent fork is the same junction
    branches = []
    for path in _branches(tree, root):
        span = float(tree.length(path)[-1])
        if tree.degree(path[-1]) >= 3 and span < max(2.0, tree.r[path[0]], tree.r[path[-1]]):
            alias[path[-1]] = alias.get(path[0], path[0])
        elif not (tree.degree(path[-1]) == 1 and span + tree.r[path[-1]] < FORK_BALL * tree.r[path[0]]):
            branches.append(path)  # (else the far side of the root's own ball, not a limb)
    if bones is not None and bones < len(branches):
        raise NotRiggable(f"--bones {bones} is fewer than the skeleton's {len(branches)} branches")
    # split points per branch, the largest deviations first when a count is asked for
    straight = STRAIGHT if tree.curve.body is not None and tree.curve.body.porous else 0.0
    cuts = {k: splits(tree.p[b], tree.r[b], skip=FORK_BALL * tree.r[b[0]], straight=straight)
            for k, b in enumerate(branches)}
    if bones is not None:
        cuts = _share(tree, branches, bones - len(branches))
    else:
        cuts = {k: _with_exit(tree, b, cuts[k]) for k, b in enumerate(branches)}
    joints: dict[str, np.ndarray] = {"ROOT": tree.p[root]}
    name_of = {root: "ROOT"}
    out: list[Bone] = []
    used: dict[str, int] = {}
    for k, path in enumerate(branches):
        start = name_of[alias.get(path[0], path[0])]
        rel = tree.p[path[-1]] - tree.p[path[0]]
        side = rel @ tree.left
        prefix = "L_" if side > tree.r[root] else "R_" if side < -tree.r[root] else ""
        label = prefix + _direction_name(rel, tree, geometry)
        used[label] = used.get(label, 0) + 1
        label += str(used[label]) if used[label] > 1 else ""
        stops = [path[i] for i in cuts[k]] + [path[-1]]
        prev = start
        for n, node in enumerate(stops, 1):
            name = f"{label}_{n}"
            is_end = node == path[-1] and tree.degree(node) == 1
            joints[name] = tree.tip(node) if is_end else tree.p[node]
            if node == path[-1]:
                name_of[node] = name
            out.append(Bone(prev, name, name))
            prev = name
    if not out:
        raise NotRiggable("the skeleton has no branches longer than it is thick: nothing to bend (a ball, a box "
                          "or a flat sheet?); autorig needs a body with limbs; draw the bones in the studio instead")
    return BoneSkeleton(joints, out)


def _with_exit(tree: Tree, path: list[int], cuts: list[int]) -> list[int]:
    """``cuts`` with one more where a limb (a branch that ends) leaves its fork's ball: the limb then
    turns about the body's surface, as a shoulder does, not about a point deep in the trunk that would
    swing the trunk's flesh with it. The ball must be ``WIDER`` than the limb (a T of one tube is its
    own joint) and the limb must reach past it by its radius. Bend splits closer to that joint than
    the limb's radius give way to it."""
    if tree.degree(path[-1]) != 1 or tree.degree(path[0]) < 3:
        return cuts
    out = np.linalg.norm(tree.p[path] - tree.p[path[0]], axis=1) > tree.r[path[0]]
    if not out.any():
        return cuts
    k = int(np.argmax(out))
    arc = tree.length(path)
    rest = float(np.mean(tree.r[path[k:]]))
    if arc[k] < max(2.0, WIDER * rest) or arc[-1] - arc[k] < max(2.0, rest):
        return cuts  # a fork no thicker than its limbs (a T of one tube) is a joint already
    return sorted([k] + [c for c in cuts if abs(arc[c] - arc[k]) >= rest])


def _share(tree: Tree, branches, extra: int) -> dict[int, list[int]]:
    """``extra`` splits, each to the branch whose pieces are longest, where it bends most (Douglas-Peucker
    with a count); refused when the branches have no room left (no piece shorter than it is thick)."""
    cuts: dict[int, list[int]] = {k: [] for k in range(len(branches))}
    for _ in range(extra):
        best = None
        for k, b in enumerate(branches):
            trial = splits(tree.p[b], tree.r[b], count=len(cuts[k]) + 1, skip=FORK_BALL * tree.r[b[0]])
            if len(trial) > len(cuts[k]):
                gain = len(b) / (len(cuts[k]) + 1)
                if best is None or gain > best[0]:
                    best = (gain, k, trial)
        if best is None:
            made = len(branches) + sum(len(c) for c in cuts.values())
            raise NotRiggable(f"--bones {len(branches) + extra}: only {made} bones fit this skeleton "
                              "(no bone shorter than it is thick)")
        cuts[best[1]] = best[2]
    return cuts


def left_axis(geometry) -> np.ndarray:
    """Physical +x (the patient's left, LPS) as a direction in the grid's voxel index space."""
    d = np.asarray(geometry.direction, float).reshape(3, 3)
    return d[0] / np.asarray(geometry.spacing, float)


STEPS = 4  # progress steps: the solid made, thinned, linked into a tree, the rig fitted


def autorig(skeleton: Skeleton, *, thinness: float | None = None, template: str = "auto",
            bones: int | None = None, progress=None, cancel=None) -> Proposal:
    """A bone skeleton for ``skeleton`` (at ``thinness``; default: all its points).

    ``template``: ``humanoid`` and ``quadruped`` name joints and bones as those rigs do (the humanoid's
    are the mannequin's); ``none`` names chains by position; ``auto`` takes the template that fits.
    ``bones`` (template ``none`` only) asks for that many bones, split where branches bend most.
    Raises :class:`~volanim_core.rig.curve_skeleton.NotRiggable` with where and why when the skeleton cannot be
    rigged. ``progress(done, total)`` after each of its ``STEPS`` stages; ``cancel()`` returning True stops it
    (:class:`~volanim_core.errors.Cancelled`).
    """
    from volanim_core.progress import Reporter
    from volanim_core.rig import templates

    if template not in TEMPLATES:
        raise ValueError(f"template must be one of {', '.join(TEMPLATES)}, got {template!r}")
    if bones is not None and template not in ("none", "auto"):
        raise ValueError("--bones sets the number of bones without a template: use --template none")
    skel = skeleton.at(thinness) if thinness is not None else skeleton
    report, done = Reporter(progress, cancel), iter(range(1, STEPS))
    report(0, STEPS)
    curve = curve_tree(skel, step=lambda: report(next(done), STEPS))
    notes = []
    if curve.dropped:
        n = sum(c for c, _ in curve.dropped)
        notes.append(f"left out {len(curve.dropped)} small piece(s) apart from the body ({n} points)")
    notes += _pruning_notes(curve)
    tree = Tree(curve, left_axis(skel.geometry))
    if len(tree.ends()) < 2:
        raise NotRiggable("the skeleton has no branches: nothing to bend (a ball, a box or a flat sheet?); "
                          "autorig needs a body with limbs; draw the bones in the studio instead")
    if template == "auto" and bones is None:
        fit = templates.best_fit(tree)
        if fit is not None:
            result, name, why = fit
            return _done(Proposal(_on(result, skel), name, notes + [why]), report)
        notes.append("no template fits (humanoid: 5 limbs, legs away from the head; quadruped: 4 legs "
                     "across the spine): chains named by position")
    elif template in ("humanoid", "quadruped"):
        result = templates.fit(tree, template)
        return _done(Proposal(_on(result, skel), template, notes), report)
    return _done(Proposal(_on(chains(tree, skel.geometry, bones=bones), skel), "none", notes), report)


def _pruning_notes(curve) -> list[str]:
    """What the curve skeleton's pruning did that a user may miss: a porous body closed, and the
    branches that stuck out of the body but were cut as noise (the longest, with where)."""
    out = []
    if curve.body is not None and curve.body.porous:
        out.append("porous body (closing its seams grew it by over 5 %): its pores were closed, and its limbs "
                   f"bend only where they stray {STRAIGHT:.0%} of their length from straight")
    if curve.pruned:
        length, tip = max(curve.pruned, key=lambda lt: lt[0])
        where = ", ".join(f"{v:.0f}" for v in tip)
        out.append(f"cut {len(curve.pruned)} short branch(es) as spurs, the longest {length:.0f} voxels to "
                   f"({where}): if one is a limb, add its bones by hand")
    return out


def _done(proposal: Proposal, report) -> Proposal:
    report(STEPS, STEPS)
    return proposal


def _on(bones: BoneSkeleton, skel: Skeleton) -> BoneSkeleton:
    return BoneSkeleton(bones.joints, bones.bones, skel.geometry)
