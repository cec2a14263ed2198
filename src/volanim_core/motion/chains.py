"""A figure read as chains, the same way from a clip and from a rig, and one matched chain to chain (#86).

    a rooted tree of points (a clip's joints and End Sites; a rig's joints)
      --from each end inwards to the first fork-->  end chains (fork first)
      --two at one fork, the same number of segments, reaches within TWINS-->  twin pairs
      --the two longest pairs, and any other whose ends stand as low-->  legs
    legs  -> up: from the feet to where the legs leave the body
          -> spine: the tree path from the hind pair's fork to the front pair's
    the other end chains, by the spine end they hang from -> head (the end whose chains end highest
                                                             along up) and tail (the other), each what
                                                             the paths out of its end share
    sides -> the figure's left is up x forward (forward: hind fork -> front fork)
    kind  -> quadruped: two pairs of legs reaching across the spine; many-legged: three or more

    rig figure, clip figure --the same kind, as many legs--> each of our bones on a chain takes the clip's
                                                             segment at the same share of that chain's
                                                             length (legs, from their two longest steps
                                                             down; left with left; the spine), or at the
                                                             same step from the body (head, tail)

Why chains and not names: an auto-rig's bones are named by where they lie in the volume (``ANT2_1``),
a clip's by its rigging tool; the shape is what the two have in common. A bone driven by a clip joint
takes that joint's world rotation (:mod:`.retarget`), so a chain of three bones can follow a chain of
four joints: each bone turns as the segment beside it does. Bones on no chain (a second horn, an ear)
follow their parent.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from volanim_core.io.bvh_files import Motion

from .body import TWINS, nearest_axis

ACROSS = 40.0  # a quadruped's legs stand within this of square to its spine (kind.py's rule too)
LOW = 0.25  # another pair is a pair of legs when its ends stand this share of a leg's reach from the floor


@dataclass
class Figure:
    """A tree of points read as a body: node paths (fork first), its up and forward, and its kind."""

    points: np.ndarray  # (N, 3) rest positions
    parent: np.ndarray  # (N,) each point's parent, -1 for the root
    names: list[str] = field(default_factory=list)  # each point's joint name (a clip's End Sites: "")
    legs: list[dict[str, list[int]]] = field(default_factory=list)  # hind pair first: {"L": path, "R": path}
    spine: list[int] = field(default_factory=list)  # hind fork -> front fork
    head: list[int] = field(default_factory=list)  # front fork -> the head's end
    tail: list[int] = field(default_factory=list)  # hind fork -> the tail's end
    up: np.ndarray | None = None
    forward: np.ndarray | None = None
    kind: str = "other"
    reason: str = ""

    def chains(self) -> dict[str, list[int]]:
        """Name -> node path: ``hind L leg``, ``front R leg`` (``middle 1 L leg`` between them), spine, head,
        tail."""
        out = {}
        for i, pair in enumerate(self.legs):
            which = "hind" if i == 0 else "front" if i == len(self.legs) - 1 else f"middle {i}"
            for side, path in pair.items():
                out[f"{which} {side} leg"] = path
        for name in ("spine", "head", "tail"):
            if len(getattr(self, name)) >= 2:
                out[name] = getattr(self, name)
        return out

    def lengths(self, path: list[int]) -> np.ndarray:
        """Each step's length along a path."""
        return np.linalg.norm(np.diff(self.points[path], axis=0), axis=1)

    def reach(self, path: list[int]) -> float:
        return float(self.lengths(path).sum())


def read_figure(points: np.ndarray, parent: np.ndarray, hips: int | None = None, names=()) -> Figure:
    """The figure of a tree of points (module docstring; a forest: the trees are read together, a path
    between two of them is none). ``hips``: the point a clip's hierarchy starts at, which is its hind end
    when nothing else tells head from tail. ``names``: each point's joint name."""
    points, parent = np.asarray(points, np.float64), np.asarray(parent, np.int64)
    fig = Figure(points, parent, list(names))
    nbrs: list[list[int]] = [[] for _ in range(len(points))]
    for c, p in enumerate(parent):
        if p >= 0:
            nbrs[c].append(int(p))
            nbrs[int(p)].append(c)
    ends = _end_chains(nbrs)
    if not ends:
        fig.reason = "the tree does not fork"
        return fig
    pairs = _pairs(fig, ends)
    if len(pairs) < 2:
        fig.reason = f"{'one pair' if pairs else 'no pair'} of twin limbs, not two"
        return fig
    legs = pairs[:2]
    up = -np.mean([_unit(points[p[-1]] - points[p[0]]) for pair in legs for p in pair], axis=0)
    up = _unit(up)
    floor = min(points[p[-1]] @ up for pair in legs for p in pair)
    leg_reach = np.mean([fig.reach(p) for pair in legs for p in pair])
    legs += [pair for pair in pairs[2:] if max(points[p[-1]] @ up for p in pair) - floor <= LOW * leg_reach]
    if not _mirrored(points, legs):
        fig.reason = f"{len(legs)} pairs of limbs, but not mirror images of each other across one plane"
        return fig
    forks = [pair[0][0] for pair in legs]
    used = {n for pair in legs for p in pair for n in p[1:]}
    fig.up = up
    a, b = max(((x, y) for x in forks for y in forks), key=lambda xy: len(_path(nbrs, *xy)))
    if a == b:
        along = _one_fork(fig, nbrs, ends, legs, a, used)
        if along is None:
            return fig
    else:
        spine = _path(nbrs, a, b)
        if not spine or not set(forks) <= set(spine):
            fig.reason = "the limbs do not leave the body along one spine"
            return fig
        axis = points[b] - points[a]  # pairs at one fork of the spine: by where their hips lie along it
        legs.sort(key=lambda pair: (spine.index(pair[0][0]), np.mean([points[p[1]] @ axis for p in pair])))
        out = {a: [], b: []}  # each spine end: paths out from it through no leg and no other spine point
        for path in ends:
            if path[-1] in used or parent[path[-1]] < 0:  # a root with one child: the file's wrapper (the
                continue  # Fox's _rootJoint, at the floor under its hips), no head or tail: it voided the tail
            way = _path(nbrs, path[-1], a)
            hit = next((n for n in way if n in spine), None)  # None: a tree apart from the body's
            if hit in out and not set(way[:way.index(hit)]) & (set(spine) | used):
                out[hit].append(_path(nbrs, hit, path[-1]))
        # how high each end's chains end: a head is held up, a tail hangs (the Fox's tail leaves its hips
        # higher than its neck leaves its shoulders, and every point of a chain read its head as its tail)
        high = {e: max((points[p[-1]] @ up for p in paths), default=points[e] @ up) for e, paths in out.items()}
        if high[a] == high[b] and hips is not None:  # nothing tells: a clip's hierarchy starts at its hips
            front = b if len(_path(nbrs, hips, a)) <= len(_path(nbrs, hips, b)) else a
        else:
            front = a if high[a] > high[b] else b
        hind = b if front == a else a
        if spine[0] != hind:
            spine.reverse()
            legs.reverse()
        fig.spine, fig.head, fig.tail = spine, _common(out[front]), _common(out[hind])
        along = points[front] - points[hind]
        fig.forward = _unit(_flat(along, up))
        fig.legs = legs
    legs = fig.legs
    left = np.cross(up, fig.forward)
    fig.legs = [dict(zip("LR", sorted(pair, key=lambda p: -(points[p[1:]].mean(axis=0) - points[p[0]]) @ left)))
                for pair in legs]
    # all legs' mean: an insect's front legs reach forward and its hind legs back, square to the body together
    leg = np.mean([_unit(points[p[-1]] - points[p[0]]) for pair in fig.legs for p in pair.values()], axis=0)
    angle = float(np.degrees(np.arccos(np.clip(_unit(leg) @ _unit(along), -1, 1))))  # the body as it lies
    said = f"{len(fig.legs)} pairs of legs, at {angle:.0f} degrees from the spine"
    if abs(angle - 90.0) > ACROSS:
        fig.reason = f"the legs do not reach across the spine ({said})"
    else:
        fig.kind = "quadruped" if len(fig.legs) == 2 else "many-legged"
        fig.reason = said
    return fig


def _unit(v: np.ndarray) -> np.ndarray:
    n = float(np.linalg.norm(v))
    return v / n if n > 1e-12 else v


def _flat(v: np.ndarray, up: np.ndarray) -> np.ndarray:
    return v - (v @ up) * up


def _mirrored(points: np.ndarray, legs) -> bool:
    """Whether the pairs are mirror images across one plane: each pair's ends differ across it (along one
    normal, within 25 degrees) and meet on it (their middle within a quarter of their distance of the plane
    through the pair's fork). A rabbit's tail, as long as its legs at the point they all leave, made a
    "pair" with a hind leg: its ends differ along the body, not across it."""
    diffs = [points[a[-1]] - points[b[-1]] for a, b in legs]
    n = _unit(diffs[0])
    n = _unit(np.sum([d if d @ n >= 0 else -d for d in diffs], axis=0))
    for (a, b), d in zip(legs, diffs):
        size = float(np.linalg.norm(d))
        middle = (points[a[-1]] + points[b[-1]]) / 2 - points[a[0]]
        if size <= 1e-9 or abs(d @ n) < np.cos(np.radians(25)) * size or abs(middle @ n) > 0.25 * size:
            return False
    return True


def _one_fork(fig: Figure, nbrs, ends, legs, fork: int, used: set) -> np.ndarray | None:
    """Every leg leaves one point (an insect's thorax; the rabbit's hips and shoulders, rigged as one): the
    spine is that point, the head and the tail the two longest ways out of it through no leg (the head's
    reaching higher), the legs ordered hind to front by where their hips lie along them. The body's
    direction, tail end to head end; None (and the reason said) when fewer than two such ways leave it."""
    points, up = fig.points, fig.up
    ways: dict[int, list[list[int]]] = {}
    for path in ends:
        way = _path(nbrs, fork, path[-1]) if path[-1] not in used and path[-1] != fork else []
        if way:
            ways.setdefault(way[1], []).append(way)
    if len(ways) < 2:
        fig.reason = "every leg leaves one point, and no body runs through it"
        return None
    two = sorted(ways.values(), key=lambda ps: -max(fig.reach(p) for p in ps))[:2]
    head, tail = sorted(two, key=lambda ps: -max(points[n] @ up for p in ps for n in p[1:]))
    fig.spine, fig.head, fig.tail = [fork], _common(head), _common(tail)
    far = [max(ps, key=fig.reach)[-1] for ps in (head, tail)]
    fig.forward = _unit(_flat(points[far[0]] - points[far[1]], up))
    fig.legs = sorted(legs, key=lambda pair: np.mean([points[p[1]] @ fig.forward for p in pair]))
    return points[far[0]] - points[far[1]]


def _common(paths: list[list[int]]) -> list[int]:
    """What the paths out of one spine end share: the whole path when there is one; the trunk before they
    part when there are several (Spot's neck, before its horns and its snout part: those follow it)."""
    if len(paths) <= 1:
        return paths[0] if paths else []
    n = 0
    while all(len(p) > n and p[n] == paths[0][n] for p in paths):
        n += 1
    return paths[0][:n] if n >= 2 else []


def _end_chains(nbrs: list[list[int]]) -> list[list[int]]:
    """From each end (one neighbour) inwards to the first fork (three or more): the path, fork first. A
    tree without a fork (a lone bone beside the body) has none: it used to void the whole figure."""
    out = []
    for end in (n for n in range(len(nbrs)) if len(nbrs[n]) == 1):
        path, prev = [end], -1
        while len(nbrs[path[-1]]) <= 2:
            nxt = [n for n in nbrs[path[-1]] if n != prev]
            if not nxt:
                break  # the other end of a path without a fork
            prev = path[-1]
            path.append(nxt[0])
        else:
            out.append(path[::-1])
    return out


def _pairs(fig: Figure, ends: list[list[int]]) -> list[tuple[list[int], list[int]]]:
    """Twin end chains at one fork (as many segments, reaches within TWINS), the longest pairs first. Where
    four or more such chains leave one fork (an insect's legs from its thorax) a chain's twin is the one
    across the body from it: their hips differ least along the body (the line its forks lie on; with one
    fork, the line the hips lie on); the leg beside it, a step along that line, is as long but no twin.
    There the segments may differ by a quarter (at least one): an auto-rig finds the bends of twin legs only
    roughly alike, and the ant voxelized at 320 voxels got 9 and 8 in its front legs, so each leg was
    paired with the one beside it."""
    out = []
    forks = np.array([fig.points[f] for f in sorted({p[0] for p in ends})])
    body = np.linalg.svd(forks - forks.mean(axis=0))[2][0] if len(forks) >= 2 else None
    for fork in {p[0] for p in ends}:
        here = sorted((p for p in ends if p[0] == fork), key=lambda p: -fig.reach(p))
        hips = np.array([fig.points[p[1]] for p in here])
        axis = (body if body is not None else np.linalg.svd(hips - hips.mean(axis=0))[2][0]) \
            if len(here) >= 4 else None
        while len(here) >= 2:
            a = here.pop(0)
            slack = max(1, round(0.25 * (len(a) - 1))) if axis is not None else 0
            like = [b for b in here if abs(len(b) - len(a)) <= slack and fig.reach(b) >= (1 - TWINS) * fig.reach(a)]
            if axis is not None and len(like) >= 2:
                like.sort(key=lambda b: abs(_unit(fig.points[a[1]] - fig.points[b[1]]) @ axis))
            if like:
                here.remove(like[0])
                out.append((a, like[0]))
    return sorted(out, key=lambda pair: -(fig.reach(pair[0]) + fig.reach(pair[1])))


def _path(nbrs: list[list[int]], a: int, b: int) -> list[int]:
    """The tree path from ``a`` to ``b``; ``[]`` when they are in two trees."""
    prev = {a: -1}
    todo = [a]
    while todo and b not in prev:
        n = todo.pop()
        for m in nbrs[n]:
            if m not in prev:
                prev[m] = n
                todo.append(m)
    if b not in prev:
        return []
    path = [b]
    while path[-1] != a:
        path.append(prev[path[-1]])
    return path[::-1]


def rig_figure(bones) -> Figure:
    """Our bones' figure: a point per joint, named as the joint."""
    names = list(bones.joints)
    at = {n: k for k, n in enumerate(names)}
    parent = np.full(len(names), -1)
    for b in bones.bones:
        parent[at[b.distal]] = at[b.proximal]
    return read_figure(np.array([bones.joints[n] for n in names]), parent, names=names)


def clip_figure(motion: Motion) -> Figure:
    """A clip's figure at its OFFSET pose: its joints, then one point per End Site."""
    rest = motion.rest_positions()
    sites = sorted(motion.end_sites)
    points = np.vstack([rest, [rest[j] + motion.end_sites[j] for j in sites]]) if sites else rest
    parent = np.concatenate([np.asarray(motion.parents, np.int64), np.array(sites, np.int64)])
    return read_figure(points, parent, hips=0, names=list(motion.names) + [""] * len(sites))


def frame_of(fig: Figure) -> np.ndarray:
    """``(3, 3)`` columns forward, left, up, each snapped to the nearest axis: the figure's own axes."""
    up_name = nearest_axis(fig.up)[0]
    fwd_name = nearest_axis(fig.forward, exclude=up_name)[0]
    up, fwd = (np.eye(3)["xyz".index(n[-1])] * (-1.0 if n.startswith("-") else 1.0) for n in (up_name, fwd_name))
    return np.column_stack([fwd, np.cross(up, fwd), up])


@dataclass
class ChainMatch:
    mapping: dict[str, str]  # our bone label -> the clip joint that drives it
    how: dict[str, str]  # label -> which chain and where along it
    scale: float  # clip units -> voxels: the legs' reach, ours over the clip's
    rig: Figure
    rig_frame: np.ndarray  # (3, 3): the rig's forward, left and up (:func:`frame_of`)
    clip_frame: np.ndarray  # (3, 3): the clip's, in its axes
    clip_leg: float  # the clip's mean leg reach, in its units

    def axes(self, up: np.ndarray | None = None, forward: np.ndarray | None = None) -> np.ndarray:
        """``(3, 3)``: the clip's axes -> ours, its forward and up onto the rig's; ``up``, ``forward``: the
        clip's as the user gave them (unit axis vectors) instead of as its figure reads."""
        clip = self.clip_frame
        u = clip[:, 2] if up is None else np.asarray(up, np.float64)
        f = clip[:, 0] if forward is None else np.asarray(forward, np.float64)
        if abs(u @ f) > 0.5:  # a forward along the up given: the figure's own forward, square to it
            f = _unit(_flat(clip[:, 0], u)) if abs(clip[:, 0] @ u) < 0.9 else _unit(_flat(clip[:, 1], u))
        return self.rig_frame @ np.column_stack([f, np.cross(u, f), u]).T


def match_chains(bones, motion: Motion) -> tuple[ChainMatch | None, str]:
    """Our bones matched to the clip's chain by chain (module docstring), or None and why not."""
    rig, clip = rig_figure(bones), clip_figure(motion)
    if rig.kind == "other" or clip.kind == "other":
        return None, f"the rig: {rig.kind} ({rig.reason}); the clip: {clip.kind} ({clip.reason})"
    if len(rig.legs) != len(clip.legs):
        return None, f"the rig has {len(rig.legs)} pairs of legs, the clip {len(clip.legs)}"
    bone_of = {b.distal: k for k, b in enumerate(bones.bones)}  # a bone is the path step to its distal joint
    mapping, how = {}, {}
    theirs = clip.chains()
    for chain, path in rig.chains().items():
        other = theirs.get(chain)
        if other is None:
            continue
        parts = zip(_limb_parts(rig, path), _limb_parts(clip, other)) if chain.endswith("leg") else [(path, other)]
        for mine, its in parts:
            for k_step, ((u, v), t) in enumerate(_steps(rig, mine)):
                # a head or a tail step by step from the body (a cow's neck turns as an elephant's, not as the
                # trunk at the same share of a longer head); a leg or the spine at the same share of its length
                joint = _driver(clip, its, t) if chain.endswith("leg") or chain == "spine" else \
                    _driver_at_step(clip, its, k_step)
                k = path.index(u)  # the step's number along the whole chain
                bone = bones.bones[bone_of[rig.names[v if rig.parent[v] == u else u]]]
                if joint < len(motion.names) and bone.label not in mapping:
                    mapping[bone.label] = motion.names[joint]
                    how[bone.label] = f"chain: {chain}, {k + 1} of {len(path) - 1}"
    ours = np.mean([rig.reach(p) for pair in rig.legs for p in pair.values()])
    clips = np.mean([clip.reach(p) for pair in clip.legs for p in pair.values()])
    return ChainMatch(mapping, how, float(ours / clips) if clips > 1e-9 else 1.0, rig, frame_of(rig),
                      frame_of(clip), float(clips)), ""


def _limb_parts(fig: Figure, path: list[int]) -> list[list[int]]:
    """A leg as ``[before, limb]``: the limb from the first of its two longest consecutive steps (thigh and
    shin, upper arm and forearm) to the foot, and what leads to it (a clavicle, a scapula), so a clip's
    clavicle does not drive a rig's upper leg. ``before`` is ``[]`` when the limb starts at the fork.

    A step is measured across the body, its part along the body's forward left out: Khronos' Fox's shoulder
    joint sits 19.5 cm forward of its spine's, as long as its forearm, and that step was taken for the
    upper arm (the rig's upper arm turned with the spine, its forearm as the fox's upper arm). Twin legs
    are split alike, by their steps summed: the fox's auto-rig put one wrist 8 voxels higher than the
    other, and that leg alone was split a step lower."""
    twins = next((list(pair.values()) for pair in fig.legs if path in pair.values()), [path])
    lengths = sum(_across(fig, p) for p in twins if len(p) == len(path))
    if len(lengths) < 3:
        return [[], path]
    i = int(np.argmax(lengths[:-1] + lengths[1:]))
    return [path[:i + 1] if i else [], path[i:]]


def _across(fig: Figure, path: list[int]) -> np.ndarray:
    """Each step's length along a path, its part along the figure's forward left out."""
    steps = np.diff(fig.points[path], axis=0)
    return np.linalg.norm(steps - np.outer(steps @ fig.forward, fig.forward), axis=1)


def _steps(fig: Figure, path: list[int]) -> list[tuple[tuple[int, int], float]]:
    """``((u, v), t)`` per step of a path: its two points and the share of the path's length at its middle."""
    if len(path) < 2:
        return []
    lengths = fig.lengths(path)
    mids = (np.cumsum(lengths) - lengths / 2) / max(float(lengths.sum()), 1e-12)
    return [((path[k], path[k + 1]), float(mids[k])) for k in range(len(path) - 1)]


def _driver_at_step(fig: Figure, path: list[int], k: int) -> int:
    """The clip joint turning step ``k`` of ``path`` (its last step past the end): the step's upper point;
    a path with no step: its only point; none (``len(points)``, no joint) for an empty one."""
    k = min(k, len(path) - 2)
    if k < 0:
        return path[0] if path else len(fig.points)
    u, v = path[k], path[k + 1]
    return u if fig.parent[v] == u else v


def _driver(fig: Figure, path: list[int], t: float) -> int:
    """The clip joint turning the step of ``path`` at share ``t`` of its length (:func:`_driver_at_step`)."""
    if len(path) < 2:
        return _driver_at_step(fig, path, 0)
    lengths = fig.lengths(path)
    return _driver_at_step(fig, path, int(np.searchsorted(np.cumsum(lengths) / max(float(lengths.sum()), 1e-12), t)))
