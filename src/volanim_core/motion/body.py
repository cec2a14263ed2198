"""A clip's body, read from its shape and its motion, names aside: parts, up, facing, size.

    OFFSET lengths  -> segment lengths (true whatever the rest pose: LAFAN's rest lies along x)
    the tree        -> upper body (the root's branch with most joints), legs (its other long branches),
                       the fork where neck and arms part, head and arm chains
    sampled frames  -> up: from the feet to the upper body, over the clip (feet are lowest)
       (FK)            facing: where the feet point (ankle -> toe), else where the clip travels
                       sides: the figure's left is up x facing
    chains          -> parts by length: upper arm and forearm are an arm's two longest consecutive
                       segments, thigh and shin a leg's

:func:`read_body` gives the parts it could place; :func:`frame_axes` finds up
and facing from any parts (the names' or the shape's), so named clips and
unnamed ones are set upright the same way.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from volanim_core.io.bvh_files import Motion

from .presets import part_key

SAMPLES = 64  # frames looked at: enough to see a stride, cheap on a 7000-frame clip
TWINS = 0.15  # two branches are twins when their reaches differ by less than this share


@dataclass
class Sampled:
    """Joint and End Site positions at evenly spread frames, in the clip's units and axes."""

    frames: np.ndarray  # (S,) frame indices
    joints: np.ndarray  # (S, J, 3)
    tips: np.ndarray  # (S, J, 3): each joint's far end (its longest child, its End Site, else itself)
    rotations: np.ndarray  # (S, J, 3, 3) world rotations


def sample(motion: Motion, count: int = SAMPLES) -> Sampled:
    frames = np.unique(np.linspace(0, motion.frames - 1, min(count, motion.frames)).round().astype(int))
    rot, pos = motion.forward_kinematics(frames)
    tips = pos.copy()
    kids = children(motion)
    for j in range(len(motion.names)):
        if kids[j]:
            tips[:, j] = pos[:, max(kids[j], key=lambda c: np.linalg.norm(motion.offsets[c]))]
        elif j in motion.end_sites:
            tips[:, j] = pos[:, j] + rot[:, j] @ motion.end_sites[j]
    return Sampled(frames, pos, tips, rot)


def children(motion: Motion) -> list[list[int]]:
    kids: list[list[int]] = [[] for _ in motion.names]
    for j, p in enumerate(motion.parents):
        if p >= 0:
            kids[p].append(j)
    return kids


def reach(motion: Motion) -> np.ndarray:
    """Per joint: the length of its longest path down to an end (OFFSET lengths, End Sites included)."""
    kids = children(motion)
    out = np.zeros(len(motion.names))
    for j in reversed(range(len(motion.names))):  # parents come first in file order
        ends = [np.linalg.norm(motion.offsets[c]) + out[c] for c in kids[j]]
        if j in motion.end_sites:
            ends.append(float(np.linalg.norm(motion.end_sites[j])))
        out[j] = max(ends, default=0.0)
    return out


def sizes(motion: Motion) -> np.ndarray:
    """Per joint: how many joints its branch holds, itself included."""
    out = np.ones(len(motion.names), np.int64)
    for j in reversed(range(len(motion.names))):  # parents come first in file order
        if motion.parents[j] >= 0:
            out[motion.parents[j]] += out[j]
    return out


def twins(motion: Motion, size: np.ndarray, far: np.ndarray, branches: list[int]) -> tuple[int, int] | None:
    """The longest pair of mirror-twin branches: the same number of joints (``size``, :func:`sizes`),
    reaches (``far``, :func:`reach`) within TWINS."""
    def length(j):
        return far[j] + float(np.linalg.norm(motion.offsets[j]))

    pairs = [(a, b) for i, a in enumerate(branches) for b in branches[i + 1:]
             if size[a] == size[b] and abs(length(a) - length(b)) <= TWINS * max(length(a), length(b), 1e-9)
             and min(length(a), length(b)) > 0]
    return max(pairs, key=lambda p: length(p[0]) + length(p[1]), default=None)


def longest_path(motion: Motion, start: int, far: np.ndarray, kids) -> list[int]:
    path = [start]
    while kids[path[-1]]:
        path.append(max(kids[path[-1]], key=lambda c: np.linalg.norm(motion.offsets[c]) + far[c]))
    return path


def _segments(motion: Motion, path: list[int]) -> np.ndarray:
    """Length from each joint of ``path`` to the next (the last: to its End Site)."""
    lengths = [np.linalg.norm(motion.offsets[c]) for c in path[1:]]
    last = path[-1]
    lengths.append(float(np.linalg.norm(motion.end_sites[last])) if last in motion.end_sites else 0.0)
    return np.array(lengths)


def _limb(path: list[int], lengths: np.ndarray, names: tuple[str, ...]) -> dict[str, int]:
    """Parts along a limb: ``names[1:3]`` at the two longest consecutive segments, ``names[0]`` before
    them (clavicle; hip joint for a leg: not used), the rest after."""
    if len(path) < 2:
        return {}
    pair = lengths[:-1] + lengths[1:]
    i = int(np.argmax(pair))
    out = {}
    for k, name in enumerate(names):
        at = i + k - 1
        if name and 0 <= at < len(path) and (k > 0 or at < i):
            out[name] = path[at]
    return out


@dataclass
class Body:
    """What the shape and motion say, in the clip's axes."""

    parts: dict[str, int]  # part key ("L_UPPERARM") -> joint index
    notes: list[str]


def read_body(motion: Motion, s: Sampled) -> Body:
    """The parts the clip's shape and motion place (see the module docstring)."""
    kids, far = children(motion), reach(motion)
    notes: list[str] = []
    root = 0
    while len(kids[root]) == 1:  # a reference joint above the hips
        root = kids[root][0]
    branches = kids[root]
    if len(branches) < 2:
        return Body({}, ["the hierarchy does not fork at the hips"])
    count = sizes(motion)
    upper = max(branches, key=lambda b: (count[b], far[b]))
    others = sorted((b for b in branches if b != upper), key=lambda b: -(far[b] + np.linalg.norm(motion.offsets[b])))
    longest = far[others[0]] + np.linalg.norm(motion.offsets[others[0]])
    pair = twins(motion, count, far, others)  # not a tail longer than the legs (a tailed biped, 3ds Max's)
    legs = list(pair) if pair else \
        [b for b in others[:2] if far[b] + np.linalg.norm(motion.offsets[b]) >= 0.5 * longest]
    fork = upper
    while len(kids[fork]) == 1:
        fork = kids[fork][0]
    arms, head = [], None
    if len(kids[fork]) >= 3:
        by_reach = sorted(kids[fork], key=lambda c: -far[c])
        arms, head = by_reach[:2], by_reach[2]
    elif len(kids[fork]) == 2:
        notes.append("the upper body forks in two, not three: arms not placed by shape")
    up = _up(s, [upper], [longest_path(motion, b, far, kids)[-1] for b in legs])
    forward = None
    leg_paths = [longest_path(motion, b, far, kids) for b in legs]
    leg_parts = [_limb(p, _segments(motion, p), ("", "THIGH", "SHIN", "FOOT", "TOE")) for p in leg_paths]
    best = 0  # the pose sides are told at: the most upright sampled frame
    if up is not None:
        feet = {f"{'LR'[k]}_{p}": j for k, lp in enumerate(leg_parts) for p, j in lp.items()}  # either order
        best = int(np.argmax([upright(s.joints[i], s.tips[i], {**feet, "SPINE": upper}, up)
                              for i in range(len(s.frames))]))
        only_feet = {k: j for k, j in feet.items() if k[2:] in ("FOOT", "TOE")}
        forward = facing_at(s.joints[best], s.tips[best], only_feet, up)[0]
    parts: dict[str, int] = {"SPINE": upper}
    if head is not None:
        head_path = longest_path(motion, head, far, kids)
        seg = _segments(motion, head_path)
        parts["NECK"] = head_path[0]
        # the head is the last joint with a long segment: not Mixamo's HeadTop_End (no length), not
        # Blender's "face" (a short bone pointing forward from the head)
        parts["HEAD"] = head_path[int(np.flatnonzero(seg >= 0.5 * seg.max())[-1])] if seg.max() > 0 else head_path[0]
    arm_parts = [_limb(p, _segments(motion, p), ("CLAVICLE", "UPPERARM", "FOREARM", "HAND"))
                 for p in (longest_path(motion, a, far, kids) for a in arms)]
    for group in (leg_parts, arm_parts):
        sided = _sides(s.joints[best], up, forward, group)
        if sided is None:
            notes.append("left and right not told apart by shape (no up or facing)")
            continue
        for side, limb in sided:
            parts.update({part_key(side, p): j for p, j in limb.items()})
    return Body(parts, notes)


def _up(s: Sampled, tops: list[int], bottoms: list[int]) -> np.ndarray | None:
    """Mean direction from the bottoms to the tops over the sampled frames (clip axes), or None."""
    if not tops or not bottoms:
        return None
    v = (s.joints[:, tops].mean(axis=1) - s.tips[:, bottoms].mean(axis=1)).mean(axis=0)
    n = np.linalg.norm(v)
    return v / n if n > 1e-9 else None


def _horizontal(v: np.ndarray, up: np.ndarray) -> np.ndarray | None:
    h = v - (v @ up) * up
    n = np.linalg.norm(h)
    return h / n if n > 1e-9 else None


def _sides(joints: np.ndarray, up, forward, limbs: list[dict[str, int]]):
    """Two limbs (or one) -> [(side, limb)] at one pose: the one further along up x forward is the left."""
    limbs = [lb for lb in limbs if lb]
    if not limbs:
        return []
    if up is None or forward is None:
        return None
    left = np.cross(up, forward)
    where = [float(joints[list(lb.values())].mean(axis=0) @ left) for lb in limbs]
    if len(limbs) == 1:
        return [("L" if where[0] >= 0 else "R", limbs[0])]
    order = np.argsort(where)[::-1]
    return [("L", limbs[order[0]]), ("R", limbs[order[1]])]


def up_over(s: Sampled, parts: dict[str, int]) -> np.ndarray | None:
    """Up (unit, clip axes) from placed parts over the sampled frames: from the feet (ankles; else
    knees) to the head (else neck, else spine). None when those are not placed."""
    top = [parts[k] for k in ("HEAD", "NECK", "SPINE") if k in parts][:1]
    bottoms = [parts[k] for k in ("L_FOOT", "R_FOOT") if k in parts] or \
              [parts[k] for k in ("L_SHIN", "R_SHIN") if k in parts]
    return _up(s, top, bottoms)


def facing_at(joints: np.ndarray, tips: np.ndarray, parts: dict[str, int], up: np.ndarray):
    """Where one pose faces (unit, horizontal, clip axes) and what told it, or (None, why not).

    One pose, not the clip's average: a clip that walks there and back faces both ways, and the
    axes must agree with the pose the rest differences are measured at. The feet point forward;
    else left and right (facing = left x up).
    """
    v = np.zeros(3)
    for side in "LR":
        if f"{side}_FOOT" in parts:
            ankle = parts[f"{side}_FOOT"]
            tip = tips[parts[f"{side}_TOE"]] if f"{side}_TOE" in parts else tips[ankle]
            v += tip - joints[ankle]
    h = _horizontal(v, up) if v.any() else None
    if h is not None:
        return h, "the feet"
    lefts = [parts[k] for k in parts if k.startswith("L_")]
    rights = [parts[k] for k in parts if k.startswith("R_")]
    if lefts and rights:
        side = _horizontal(joints[lefts].mean(axis=0) - joints[rights].mean(axis=0), up)
        if side is not None:
            return np.cross(side, up), "left and right"
    return None, "nothing tells the facing"


def upright(joints: np.ndarray, tips: np.ndarray, parts: dict[str, int], up: np.ndarray) -> float:
    """How upright a pose is: the head's height over the feet per unit of their distance (1: straight
    up). 1 when head or feet are not placed."""
    top = [parts[k] for k in ("HEAD", "NECK", "SPINE") if k in parts][:1]
    feet = [parts[k] for k in ("L_FOOT", "R_FOOT", "L_SHIN", "R_SHIN") if k in parts]
    if not top or not feet:
        return 1.0
    v = joints[top[0]] - tips[feet].mean(axis=0)
    n = np.linalg.norm(v)
    return float(v @ up / n) if n > 1e-9 else 0.0


def nearest_axis(v: np.ndarray, exclude: str | None = None) -> tuple[str, float]:
    """The signed axis name nearest to unit ``v`` (``"-y"``) and the cosine to it."""
    best, cos = "y", -2.0
    for k, a in enumerate("xyz"):
        if exclude and exclude.lstrip("+-") == a:
            continue
        for sign in (1.0, -1.0):
            c = sign * v[k]
            if c > cos:
                best, cos = ("" if sign > 0 else "-") + a, float(c)
    return best, cos


def chain_length(motion: Motion, start: int, end: int) -> float:
    """OFFSET length along the hierarchy from joint ``start`` down to ``end`` (0 when not below it)."""
    total, j = 0.0, end
    while j != start:
        if j < 0:
            return 0.0
        total += float(np.linalg.norm(motion.offsets[j]))
        j = int(motion.parents[j])
    return total


UNITS = {"metres": 0.85, "centimetres": 85.0, "millimetres": 850.0, "inches": 33.5, "decimetres": 8.5}


def units_of(leg: float) -> str:
    """A unit name for a clip whose thigh + shin measure ``leg`` (an adult's is about 0.85 m)."""
    if leg <= 0:
        return "unknown"
    return min(UNITS, key=lambda u: abs(np.log(leg / UNITS[u])))
