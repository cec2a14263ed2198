"""Flesh a limb cannot carry goes to the bone above it: the ``fitted`` attachment (#60).

    points, radii (DT), bones, nearest bone per point
        --tube_profiles--> per bone, its tube's radius at the proximal and distal joint: a straight
                           line fitted to (distance from the bone + radius) of its points near its axis,
                           along the middle of the bone (0.15 < t < 0.85), where no other limb touches it
        --carry_up--> a point whose ball reaches past its bone's tube (by more than ``tolerance``) is
                      given to the bone's parent, and on up while it still does not fit; a root bone
                      takes whatever reaches it

Why: nearest-bone attachment gives the armpit to the arm and the groin to the thigh -- their points lie
a few voxels from the limb's segment and twenty from the spine's -- so raising the arm swings a lump of
torso flesh with it (#60: 6.0 % of the arm at 90 degrees of abduction). The body's true parts (the
mannequin's capsules: a voxel belongs to the part it lies deepest in) give that flesh to the torso
because it lies outside the arm's own round tube. The tube is measured from the skeleton itself, so
no truth is needed: a limb's middle is its own, and its taper carries on to its ends.

Measured (benchmarks/bench_shape.py, README): the arm's blob at 90 degrees falls from 6.0 % of the
arm to 1.2 % (the true parts: 1.0 %), the thigh's from 4.9 % to 3.4 %.
"""

from __future__ import annotations

import numpy as np

from volanim_core.rig.bones import BoneSkeleton

#: voxels a ball may reach past its bone's tube and still be carried by it (the tube is a straight fit)
TOLERANCE = 2.0
MIDDLE = (0.15, 0.85)  # the part of a bone whose points fit its tube: away from both joints
MIN_POINTS = 4


def along(points: np.ndarray, segments: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(N, B)`` position along each segment (0 at the proximal joint, 1 at the distal; not clipped) and
    distance to it."""
    p = np.asarray(points, np.float64)[:, None, :]
    a, b = segments[None, :, 0, :], segments[None, :, 1, :]
    ab = b - a
    t = ((p - a) * ab).sum(-1) / np.maximum((ab * ab).sum(-1), 1e-12)
    d = np.linalg.norm(p - (a + np.clip(t, 0.0, 1.0)[..., None] * ab), axis=-1)
    return t, d


def tube_profiles(points: np.ndarray, radii: np.ndarray, bones: BoneSkeleton, bone: np.ndarray,
                  t: np.ndarray | None = None, d: np.ndarray | None = None) -> np.ndarray:
    """``(B, 2)``: each bone's tube radius at its proximal and distal joint; NaN (no limit) for a bone with
    fewer than ``MIN_POINTS`` points near the axis of its middle."""
    if t is None or d is None:
        t, d = along(points, bones.segments())
    radii = np.asarray(radii, np.float64)
    out = np.full((len(bones), 2), np.nan)
    for k in range(len(bones)):
        tk, dk = t[:, k], d[:, k]
        # near the axis relative to the ball: the medial points of the limb's own middle
        sel = (bone == k) & (tk > MIDDLE[0]) & (tk < MIDDLE[1]) & (dk <= 0.5 * radii + 1.0)
        if sel.sum() >= MIN_POINTS and np.ptp(tk[sel]) > 0.1:
            slope, at0 = np.polyfit(tk[sel], radii[sel] + dk[sel], 1)
            out[k] = (at0, at0 + slope)
    return out


def carry_up(points: np.ndarray, radii: np.ndarray, bones: BoneSkeleton, bone: np.ndarray,
             tolerance: float = TOLERANCE) -> np.ndarray:
    """``bone`` (one index per point, -1 unattached) with every ball its bone's tube cannot hold given to
    the bone's parent, and on up (see the module docstring)."""
    bone = np.asarray(bone).copy()
    if not len(bone):
        return bone
    t, d = along(points, bones.segments())
    tubes = tube_profiles(points, radii, bones, bone, t, d)
    parent = np.array([next((k for k, o in enumerate(bones.bones) if o.distal == b.proximal), -1)
                       for b in bones.bones])
    radii = np.asarray(radii, np.float64)
    rows = np.arange(len(bone))
    todo = bone >= 0
    for _ in range(len(bones)):  # at most one step up per bone of the longest chain
        k = np.where(todo, bone, 0)
        tube = tubes[k, 0] + (tubes[k, 1] - tubes[k, 0]) * np.clip(t[rows, k], 0.0, 1.0)
        over = todo & (parent[k] >= 0) & (d[rows, k] + radii > tube + tolerance)  # NaN tube: fits
        if not over.any():
            break
        bone[over] = parent[bone[over]]
        todo = over
    return bone
