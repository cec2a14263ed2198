"""How well a bent joint keeps the body's shape, measured on voxels (rigid and smooth joints alike).

    posed bone volumes (smooth, rigid), the limb's matrix M, the joint J
        --far_limb_dice--> Dice of the limb's voxels far from J (taken back through M): smooth against rigid
    posed volume, a plane through J --cross_section--> voxels in that plane within a radius (area)

Neither looks at blend weights: they compare what the reconstruction drew with
what a rigid limb draws, so a blend that leaks along the limb or a twist that
collapses the joint shows as a number.
"""

from __future__ import annotations

import numpy as np

from volanim_core.reconstruct.engine import Reconstruction
from volanim_core.rig.pose import apply_matrices


def _voxels(recon: Reconstruction, label: int | None = None) -> np.ndarray:
    v = np.asarray(recon.volume)
    return np.argwhere(v > 0 if label is None else v == label) + np.asarray(recon.origin)


def far_limb_dice(posed_bone: Reconstruction, rigid_bone: Reconstruction, bone: int, matrix: np.ndarray,
                  joint: np.ndarray, far: float) -> float:
    """Dice of bone ``bone``'s voxels in two bone-mode reconstructions of one pose (smooth joints against
    rigid), counting only voxels whose rest position (back through the bone's ``matrix``) is farther
    than ``far`` from ``joint``. 1 when the limb beyond the joint is exactly its rigid self: comparing two
    reconstructions of the same pose, the rotated grid's rounding is the same in both."""
    sets = []
    for recon in (posed_bone, rigid_bone):
        q = _voxels(recon, bone + 1)
        back = apply_matrices(q.astype(np.float64), np.zeros(len(q), np.int64), np.linalg.inv(matrix)[None])
        sets.append({tuple(p) for p in q[np.linalg.norm(back - joint, axis=1) > far].tolist()})
    a, b = sets
    return 2.0 * len(a & b) / max(len(a) + len(b), 1)


def cross_section(recon: Reconstruction, point: np.ndarray, axis: np.ndarray, radius: float) -> int:
    """Filled voxels within half a voxel of the plane through ``point`` normal to ``axis`` and within
    ``radius`` of ``point``: the body's cross-section area there, in voxels."""
    q = _voxels(recon).astype(np.float64) - point
    u = np.asarray(axis, np.float64) / np.linalg.norm(axis)
    along = q @ u
    return int(np.count_nonzero((np.abs(along) <= 0.5) & (np.linalg.norm(q - along[:, None] * u, axis=1) <= radius)))
