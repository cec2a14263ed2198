"""Attaching skeleton points to bones (connectivity).

``attach_nearest_bone`` is the simple rule the demo assets are built with:
each point goes to the bone segment nearest to it. It ignores the shape, so a
point in the armpit may go to the torso or the arm by a hair; the studio's
auto-connect refines it with a path-inside-the-volume check.
"""

from __future__ import annotations

import numpy as np

from .bones import BoneSkeleton
from .connectivity import Connectivity
from .pose import root_bones
from .skeleton import Skeleton


def segment_distances(points: np.ndarray, segments: np.ndarray) -> np.ndarray:
    """``(N, B)`` distances from points ``(N, 3)`` to segments ``(B, 2, 3)``."""
    p = np.asarray(points, np.float64)[:, None, :]
    a, b = segments[None, :, 0, :], segments[None, :, 1, :]
    ab = b - a
    denom = np.maximum((ab * ab).sum(-1), 1e-12)
    t = np.clip(((p - a) * ab).sum(-1) / denom, 0.0, 1.0)
    return np.linalg.norm(p - (a + t[..., None] * ab), axis=-1)


def attach_nearest_bone(points: np.ndarray, bones: BoneSkeleton) -> np.ndarray:
    """Index of the nearest bone segment for each point (ties: first in root order)."""
    if not len(bones):
        raise ValueError("the bone skeleton has no bones to attach to")
    out = np.empty(len(points), np.int32)
    segs = bones.segments()
    for s in range(0, len(points), 65536):  # bounded memory: (chunk, B) at a time
        out[s : s + 65536] = segment_distances(points[s : s + 65536], segs).argmin(1)
    return out


def connect_nearest(skeleton: Skeleton, bones: BoneSkeleton) -> Connectivity:
    """A connectivity attaching every skeleton point to its nearest bone."""
    bone = attach_nearest_bone(skeleton.points, bones)
    conn = Connectivity(root_bones(bones), skeleton.points, skeleton.dt, skeleton.thinness, bone,
                        skeleton.metric)
    return conn.grouped()
