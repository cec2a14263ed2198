"""Baselines for bench_reconstruct.py (not part of the library).

* ``cube_scan``: the thesis's old algorithm in numba -- scan each sphere's
  bounding cube, inverse-transform every voxel (a full matrix product), then
  test inclusion -- parallel over the same z-slabs with the same thread count.
* ``numpy_per_sphere``: the same work vectorised per sphere in plain NumPy.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange


@njit(cache=True, parallel=True)
def cube_scan(out, stencil, nthreads, offsets, ids, centres, r2s, minv, bone, source, sampled):
    nz, ny, nx = out.shape
    sz, sy, sx = source.shape
    for t in prange(nthreads):
        for z in range(t, nz, nthreads):
            for k in range(offsets[z], offsets[z + 1]):
                i = ids[k]
                cx, cy, cz = centres[i, 0], centres[i, 1], centres[i, 2]
                r2 = r2s[i]
                r = np.sqrt(r2)
                m = minv[bone[i]]
                dz = z - cz
                for y in range(max(0, int(np.floor(cy - r))), min(ny - 1, int(np.ceil(cy + r))) + 1):
                    dy = y - cy
                    for x in range(max(0, int(np.floor(cx - r))), min(nx - 1, int(np.ceil(cx + r))) + 1):
                        px = x * m[0, 0] + y * m[1, 0] + z * m[2, 0] + m[3, 0]
                        py = x * m[0, 1] + y * m[1, 1] + z * m[2, 1] + m[3, 1]
                        pz = x * m[0, 2] + y * m[1, 2] + z * m[2, 2] + m[3, 2]
                        dx = x - cx
                        d2 = (dx * dx + dy * dy) + dz * dz
                        if d2 < r2:
                            d = np.float32(d2)
                            if d < stencil[z, y, x]:
                                stencil[z, y, x] = d
                                if sampled:
                                    ix = int(np.floor(px + 0.5))
                                    iy = int(np.floor(py + 0.5))
                                    iz = int(np.floor(pz + 0.5))
                                    if 0 <= ix < sx and 0 <= iy < sy and 0 <= iz < sz:
                                        out[z, y, x] = source[iz, iy, ix]
                                    else:
                                        out[z, y, x] = 0
                                else:
                                    out[z, y, x] = 255


def prepare(tskel, bounds):
    from volanim_core.reconstruct import _plan_kernels as P
    from volanim_core.reconstruct.engine import check_matrices, posed_centres
    from volanim_core.reconstruct.radii import radius_squared

    origin = np.asarray(bounds.lo, float)
    centres = np.ascontiguousarray(posed_centres(tskel) - origin)
    r2s = radius_squared(tskel.dt)
    shift = np.eye(4)
    shift[3, :3] = origin
    minv = np.ascontiguousarray(shift @ check_matrices(tskel))
    nz = bounds.shape[2]
    zlo = np.floor(centres[:, 2] - tskel.dt).astype(np.int64) - 1
    zhi = np.ceil(centres[:, 2] + tskel.dt).astype(np.int64) + 1
    offsets, ids = P.slice_lists(zlo, zhi, nz)
    return centres, r2s, minv, offsets, ids


def run_cube_scan(tskel, bounds, source, sampled, threads):
    import numba

    centres, r2s, minv, offsets, ids = prepare(tskel, bounds)
    X, Y, Z = bounds.shape
    out = np.zeros((Z, Y, X), np.uint8)
    stencil = np.full((Z, Y, X), np.inf, np.float32)
    numba.set_num_threads(threads)
    cube_scan(out, stencil, threads, offsets, ids, centres, r2s, minv, tskel.bone,
              np.ascontiguousarray(source.T), sampled)
    return out.T


def numpy_per_sphere(tskel, bounds, source, sampled):
    from volanim_core.reconstruct.engine import check_matrices, posed_centres
    from volanim_core.reconstruct.radii import radius_squared

    lo = np.asarray(bounds.lo)
    shape = np.asarray(bounds.shape)
    out = np.zeros(tuple(shape), np.uint8)
    best = np.full(tuple(shape), np.inf, np.float32)
    centres = posed_centres(tskel) - lo
    r2s = radius_squared(tskel.dt)
    minv = check_matrices(tskel)
    for i in range(len(tskel)):
        c, r2 = centres[i], r2s[i]
        r = np.sqrt(r2)
        a = np.maximum(np.floor(c - r).astype(int), 0)
        b = np.minimum(np.ceil(c + r).astype(int), shape - 1)
        g = np.mgrid[a[0] : b[0] + 1, a[1] : b[1] + 1, a[2] : b[2] + 1].reshape(3, -1).T
        d2 = ((g - c) ** 2).sum(1)
        g, d = g[d2 < r2], d2[d2 < r2].astype(np.float32)
        win = d < best[g[:, 0], g[:, 1], g[:, 2]]
        g = g[win]
        best[g[:, 0], g[:, 1], g[:, 2]] = d[win]
        if sampled:
            m = minv[tskel.bone[i]]
            p = np.floor((g + lo) @ m[:3, :3] + m[3, :3] + 0.5).astype(int)
            ok = ((p >= 0) & (p < source.shape)).all(1)
            vals = np.zeros(len(p), np.uint8)
            vals[ok] = source[p[ok, 0], p[ok, 1], p[ok, 2]]
            out[g[:, 0], g[:, 1], g[:, 2]] = vals
        else:
            out[g[:, 0], g[:, 1], g[:, 2]] = 255
    return out
