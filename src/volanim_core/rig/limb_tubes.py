"""Flesh a limb cannot carry goes to the bone above it: the ``fitted`` attachment (#60).

    points, radii (DT), bones, nearest bone per point
        --tube_profiles--> per bone, its tube's radius at the proximal and distal joint: a straight
                           line fitted to (distance from the bone + radius) of its points near its axis,
                           along the middle of the bone (0.15 < t < 0.85), where no other limb touches it
        --carry_up--> a point in the half of its bone next to the parent's joint whose ball reaches past
                      the bone's tube (by more than ``tolerance``) is given to the bone's parent, and on up
                      while that still holds; a root bone takes whatever reaches it

Why: nearest-bone attachment gives the armpit to the arm and the groin to the thigh -- their points lie
a few voxels from the limb's segment and twenty from the spine's -- so raising the arm swings a lump of
torso flesh with it (#60: 6.0 % of the arm at 90 degrees of abduction). The body's true parts (the
mannequin's capsules: a voxel belongs to the part it lies deepest in) give that flesh to the torso
because it lies outside the arm's own round tube. The tube is measured from the skeleton itself, so
no truth is needed: a limb's middle is its own, and its taper carries on to its ends. Only the half next
to the parent: a ball at a limb's far end that spills past the straight tube (a hand's, a foot's, the
crown of a head) is still that limb's flesh; carried up bone by bone it ended on the torso (mannequin-large:
151 hand points a side on the spine, 53 foot points on the pelvis; the head tilted 45 degrees left a 74 %
blob).

Measured (benchmarks/bench_shape.py, README): the arm's blob at 90 degrees falls from 6.0 % of the
arm to 1.2 % (the true parts: 1.0 %), the hip's worst from 5.0 % to 2.2 %; on mannequin-large the
shoulder's from 10.7 % to 1.5 %, the hip's from 11.2 % to 4.0 %. It is worse only at mannequin-large's
neck: the points under the chin are the torso's, but their balls reach into the head and stay when it nods.
"""

from __future__ import annotations

import numpy as np

from volanim_core.rig.bones import BoneSkeleton
from volanim_core.rig.nearest import segment_positions

#: voxels a ball may reach past its bone's tube and still be carried by it (the tube is a straight fit)
TOLERANCE = 2.0
MIDDLE = (0.15, 0.85)  # the part of a bone whose points fit its tube: away from both joints
MIN_POINTS = 4
NEAR_PARENT = 0.5  # a ball is carried up only from the half of its bone next to the parent's joint


def on_own_bone(points: np.ndarray, segments: np.ndarray, bone: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each point's position along and distance to its own bone's segment (``bone`` >= 0): one segment a
    point, so memory stays O(points) on a scan's million points (all bones at once would be O(points x bones))."""
    t, d = (np.empty(len(bone)) for _ in range(2))
    for k in np.unique(bone):
        at = np.flatnonzero(bone == k)
        tk, dk = segment_positions(points[at], segments[k:k + 1])
        t[at], d[at] = tk[:, 0], dk[:, 0]
    return t, d


def tube_profiles(points: np.ndarray, radii: np.ndarray, bones: BoneSkeleton, bone: np.ndarray) -> np.ndarray:
    """``(B, 2)``: each bone's tube radius at its proximal and distal joint, from the points attached to it
    (``bone``); NaN (no limit) for a bone with fewer than ``MIN_POINTS`` points near the axis of its middle."""
    radii = np.asarray(radii, np.float64)
    out = np.full((len(bones), 2), np.nan)
    on = bone >= 0
    t, d = on_own_bone(np.asarray(points)[on], bones.segments(), bone[on])
    r = radii[on]
    for k in range(len(bones)):
        # near the axis relative to the ball: the medial points of the limb's own middle
        sel = (bone[on] == k) & (t > MIDDLE[0]) & (t < MIDDLE[1]) & (d <= 0.5 * r + 1.0)
        if sel.sum() >= MIN_POINTS and np.ptp(t[sel]) > 0.1:
            slope, at0 = np.polyfit(t[sel], r[sel] + d[sel], 1)
            out[k] = (at0, at0 + slope)
    return out


def carry_up(points: np.ndarray, radii: np.ndarray, bones: BoneSkeleton, bone: np.ndarray,
             tolerance: float = TOLERANCE) -> np.ndarray:
    """``bone`` (one index per point, -1 unattached) with every ball its bone's tube cannot hold given to
    the bone's parent, and on up (see the module docstring)."""
    bone = np.asarray(bone).copy()
    if not len(bone):
        return bone
    points, radii = np.asarray(points), np.asarray(radii, np.float64)
    segments = bones.segments()
    tubes = tube_profiles(points, radii, bones, bone)
    parent = np.array([-1 if k is None else k for k in bones.parents()])
    todo = np.flatnonzero(bone >= 0)
    for _ in range(len(bones)):  # at most one step up per bone of the longest chain
        k = bone[todo]
        t, d = on_own_bone(points[todo], segments, k)
        tube = tubes[k, 0] + (tubes[k, 1] - tubes[k, 0]) * np.clip(t, 0.0, 1.0)
        # only near the joint with the parent: a ball at a limb's far end (a foot's toe, a head's crown) that
        # spills past the straight tube is still that limb's flesh, not its parent's
        over = (parent[k] >= 0) & (t < NEAR_PARENT) & (d + radii[todo] > tube + tolerance)  # NaN tube: fits
        if not over.any():
            break
        todo = todo[over]
        bone[todo] = parent[bone[todo]]
    return bone
