"""Sampled mode's second pass: every filled voxel reads the rest-pose source through its
owner bone's inverse matrix (``_kernels.sample_rows``), grey or colour.

A colour source ``[x, y, z, 3]`` is sampled one channel at a time through the same
owner map, so the three channels move together. With a 3^3 or 5^3 kernel the
channels are averaged in linear light (sRGB decoded, averaged, encoded again):
averaging sRGB values directly darkens every edge between two colours.
"""

from __future__ import annotations

import numpy as np

from volanim_core.colour.space import from_linear, to_linear
from volanim_core.reconstruct import _kernels as K

#: Linear light in 0..65535 for each sRGB byte: the kernel rounds its average to a whole
#: number, which at this scale is far below one step of 8-bit sRGB.
LINEAR_SCALE = 65535.0
_LINEAR = (to_linear(np.arange(256)) * LINEAR_SCALE).astype(np.float32)


def gaussian_weights(kernel: int) -> np.ndarray:
    """Normalised ``kernel**3`` Gaussian weights (sigma = kernel / 4), ``[z, y, x]``."""
    half = kernel // 2
    g = np.exp(-0.5 * (np.arange(-half, half + 1) / (kernel / 4.0)) ** 2)
    w = g[:, None, None] * g[None, :, None] * g[None, None, :]
    return w / w.sum()


def sample_source(owner, source, minv, kernel, spans, nthreads, chunk, report) -> np.ndarray:
    """The sampled volume ``[z, y, x]`` (``[z, y, x, 3]`` for colour) from the owner map ``owner``
    (bone + 1 per voxel, 0 empty), read on each row's span ``spans = (row_lo, row_hi)``.
    ``report(done)`` is called with slices done, 0..nz."""
    nz = owner.shape[0]
    if np.ndim(source) == 3:
        src = np.ascontiguousarray(np.asarray(source).T)  # [z, y, x]; free for an F-ordered source
        out = owner if src.dtype == owner.dtype else np.zeros(owner.shape, src.dtype)
        return _sample(owner, out, src, minv, kernel, spans, nthreads, chunk, report)
    rgb = np.zeros((*owner.shape, 3), np.uint8)
    for c in range(3):
        def part(done, c=c):
            report((c * nz + done) // 3)

        channel = np.asarray(source[..., c]).T
        if kernel == 1:  # nearest voxel: the bytes themselves
            out = np.zeros(owner.shape, np.uint8)
            rgb[..., c] = _sample(owner, out, np.ascontiguousarray(channel), minv, kernel, spans, nthreads,
                                  chunk, part)
        else:
            out = np.zeros(owner.shape, np.float32)
            linear = np.ascontiguousarray(_LINEAR[channel])
            _sample(owner, out, linear, minv, kernel, spans, nthreads, chunk, part)
            rgb[..., c] = from_linear(out / LINEAR_SCALE)
    return rgb


def _sample(owner, out, src, minv, kernel, spans, nthreads, chunk, report) -> np.ndarray:
    weights = gaussian_weights(kernel) if kernel > 1 else np.ones((1, 1, 1))
    nz = owner.shape[0]
    for z0 in range(0, nz, chunk):
        z1 = min(nz, z0 + chunk)
        K.sample_rows(owner, out, z0, z1, nthreads, *spans, minv, src, weights, kernel // 2)
        report(z1)
    return out


def grid_to_source(minv_rest: np.ndarray, origin: np.ndarray, to_source: np.ndarray) -> np.ndarray:
    """Per bone: output-grid coordinates -> source-array coordinates (shift in, invert, then the
    frame's grid -> the source's grid, :meth:`Geometry.index_map`)."""
    shift_in = np.eye(4)
    shift_in[3, :3] = origin
    return np.ascontiguousarray(shift_in @ minv_rest @ to_source)
