"""The nearest bone: each point's distance and position along every bone's segment.

    points (N, 3), segments (B, 2, 3) --segment_positions--> t (N, B) along each segment, d (N, B) to it
    points, bones --attach_nearest_bone--> the nearest segment per point (in bounded chunks)

The measures every attachment rule starts from (:mod:`.attach`, :mod:`.pieces`, :mod:`.limb_tubes`) and
the shape reports use (:mod:`volanim_core.reconstruct.lumps`): below them all, so none imports another.
"""

from __future__ import annotations

import numpy as np

from volanim_core.rig.bones import BoneSkeleton


def segment_positions(points: np.ndarray, segments: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(N, B)`` position of points ``(N, 3)`` along segments ``(B, 2, 3)`` (0 at the first end, 1 at the
    second; not clipped) and their distance to each segment."""
    p = np.asarray(points, np.float64)[:, None, :]
    a, b = segments[None, :, 0, :], segments[None, :, 1, :]
    ab = b - a
    t = ((p - a) * ab).sum(-1) / np.maximum((ab * ab).sum(-1), 1e-12)
    return t, np.linalg.norm(p - (a + np.clip(t, 0.0, 1.0)[..., None] * ab), axis=-1)


def segment_distances(points: np.ndarray, segments: np.ndarray) -> np.ndarray:
    """``(N, B)`` distances from points ``(N, 3)`` to segments ``(B, 2, 3)``."""
    return segment_positions(points, segments)[1]


def attach_nearest_bone(points: np.ndarray, bones: BoneSkeleton) -> np.ndarray:
    """Index of the nearest bone segment for each point (ties: first in root order)."""
    if not len(bones):
        raise ValueError("the bone skeleton has no bones to attach to")
    out = np.empty(len(points), np.int32)
    segs = bones.segments()
    for s in range(0, len(points), 65536):  # bounded memory: (chunk, B) at a time
        out[s : s + 65536] = segment_distances(points[s : s + 65536], segs).argmin(1)
    return out
