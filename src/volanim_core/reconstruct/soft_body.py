"""The rest body read as the smooth shape its voxels sample, not as stairs: what the ownership warp reads between
voxels (#84).

    Ownership.labels [x, y, z] --> body (labels > 0)
        --blurred by 1 4 6 4 1 / 16 along x, y and z (a Gaussian of sigma 1 voxel; _soft_kernels.soft_field),
          x 255-->  a smooth field, 0..255
        --clamped: body voxels >= 128, outside voxels <= 127--> soft [x, y, z] uint8 (Fortran, as the labels)
    reconstruct/_owned_kernels.claims_point: a rest point is body where the trilinear sum of ``soft`` over its
    8 voxels is over HALF (127.5), the same rule as a binary body's "more than half"

Why: a voxel segmentation is a sampled smooth surface; read trilinearly as 0 and 1 it comes back as stairs
rounded off at every turn. Smoothed first, its half-level runs where the smooth surface ran. The clamp keeps the
rest pose exact: at a voxel centre the read is that voxel's own value, over HALF inside and under it outside,
so the identity pose gives the input back voxel for voxel. Measured (#84, ``bench_shape.py --floor``: the
mannequin's true capsules read back at each bone's inverse): the walk's frame 1050, Dice 0.9855 read binary,
0.9905 smoothed at sigma 1; the spine twisted 60 degrees 0.9902 -> 0.9942 (sigma 0.7: 0.9938; 1.5: 0.9888).
"""

from __future__ import annotations

import numba
import numpy as np

from volanim_core.reconstruct._soft_kernels import soft_field, soft_refusals

HALF = 127.5  # the read's threshold in soft's units: a body voxel is >= 128, an outside one <= 127


def packed_body(labels: np.ndarray, flags: np.ndarray, threads: int | None = None
                ) -> tuple[np.ndarray, int, np.ndarray]:
    """``(packed, shift, flags)``: each voxel's label and its soft value above it (``label | soft << shift``, ``[x, y,
    z]`` in the labels' layout, an unsigned integer twice the labels' width), and a copy of the labels' ``flags``
    (Ownership.flags) whose bit 8 (a read nearest the voxel is refused unread) holds for reads of the soft body
    (_soft_kernels.soft_refusals). The soft value: the body (``labels > 0``) blurred by ``1 4 6 4 1`` / 16 along
    each axis (a Gaussian of sigma 1 voxel; outside the array: empty), x 255 rounded, each body voxel raised to
    at least 128 and each other one lowered to at most 127. ``threads``: numba's."""
    labels = np.asfortranarray(labels)
    shift = 8 * labels.dtype.itemsize
    packed = np.zeros(labels.shape, np.uint16 if shift == 8 else np.uint32, order="F")
    box = np.empty((labels.shape[2], 4), np.int64)
    soft_field(labels, packed, shift, max(1, int(threads or numba.get_num_threads())), box)
    kept = np.asfortranarray(flags).copy(order="F")
    soft_refusals(kept, packed, shift, HALF, box)
    return packed, shift, kept


def soft_body(labels: np.ndarray, threads: int | None = None) -> np.ndarray:
    """The soft values alone (:func:`packed_body`), ``[x, y, z]`` uint8."""
    labels = np.asfortranarray(labels)
    shift = 8 * labels.dtype.itemsize
    packed = np.zeros(labels.shape, np.uint16 if shift == 8 else np.uint32, order="F")
    soft_field(labels, packed, shift, max(1, int(threads or numba.get_num_threads())),
               np.empty((labels.shape[2], 4), np.int64))
    return np.asfortranarray((packed >> shift).astype(np.uint8))
