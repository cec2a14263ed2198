"""numba kernels of the reconstruction (ReconstructEuclid, done properly).

Layout: output and source are C-ordered ``[z, y, x]`` arrays (the transposes
of our ``[x, y, z]`` volumes), so an x-run is contiguous memory. The stencil
(each voxel's best distance so far) is one ``[y, x]`` slice per thread, not a
grid: one thread fills a slice from its first sphere to its last, so the
stencil only has to live for that slice -- it stays in cache, and the grid
costs no memory beyond the output. The stencil is never initialised: where the
output still holds 0 (no sphere has won the voxel; every relaxing mode writes
values >= 1) its value is ignored, as if it were inf. Growing an initialised
span row by row cost 17 % of the frog's kernel (a short, badly predicted loop
per row); the extra test is one lane-wise compare on data already loaded.

    (slice_lists, build_halfspaces: _plan_kernels.py, made by plan.py before the fill)
    fill_slices  for each slice (threads take slices round-robin), for each of
                 its spheres, for each row y: the exact x-run of the circle;
                 per voxel: distance vs stencil, and on a win write the mode's
                 value (sampled mode: the bone, as in bone mode); the voxel
                 loop is branch-free over a row slice, which LLVM vectorises.
                 A sphere without planes (below CUT_MIN_RADIUS: the frog's
                 mass of small ones) sweeps the x-box of its slice's disc
                 instead, the oracle's predicate per voxel (_rows_in_box):
                 no per-row end points, 20-28 % off the frog's kernel; it
                 counts nothing per voxel (filled voxels are counted once at
                 the slice's end from the output: another 14 %). Each sphere's
                 centre and radius are prefetched a few spheres ahead
                 (_prefetch.py): a slice lists spheres from all over the arrays
    sample_rows  sampled mode's second pass: each filled voxel once, the source
                 position stepped along the row (p = p_row + x * step) with the
                 winning bone's inverse -- no matrix product per voxel, and no
                 source read for voxels that a closer sphere wins later

Why this is exact and thread-independent: the run end points are found with
the very predicate the oracle uses (``((dx*dx + dy*dy) + dz*dz) < R2`` in
float64, or the integer chamfer distance), and a voxel changes owner only on a
strictly smaller float32 distance, visiting spheres in file order -- so each
voxel ends with the smallest ``(distance, file index)`` whichever thread
filled which slice.

Overdraw cut (Euclid, all modes but hotspot): sphere i skips the voxels q of
its ball that a neighbour j provably covers and wins, found by one plane:
* ``r_j >= r_i``, q closer to c_j than to c_i (past their bisector plane):
  |q - c_j| < |q - c_i| < r_i <= r_j, so j covers q and beats i there;
* ``r_j < r_i``, q past their *power* plane (|q - c_j|^2 - r_j^2 <
  |q - c_i|^2 - r_i^2 < 0): j covers q, and is closer than i by at least
  r_i^2 - r_j^2 > 0. Without this plane a big sphere visited every voxel the
  small spheres near the body's surface win -- the bulk of mannequin-large's
  overdraw (#65): on its posed frame 214 of the 352 visits per voxel an
  uncut fill makes.
Both are one half-space ``|q - c_i|^2 - |q - c_j|^2 <= max(0, r_i^2 - r_j^2)``
that clips each x-run in O(1). The owner of q is never cut at q (a cut needs a
sphere that covers q and beats it), so it visits q and wins whatever else was
skipped. A margin (2^-20 r_i^2 + 1e-6 in squared distance) keeps
the cut clear of float32 ties, so every voxel's owner is provably the same as
without the cut; the oracle tests check it. Planes are written in the sphere's
own frame (small numbers: rounding far below the margin wherever the grid
lies) and chosen per slice: one that misses the slice's disc costs nothing
per row, one that covers it skips the slice, and only the rows every
plane's kept part of the disc reaches are visited (slice_cuts: a full-size walk
frame tested 142 M rows for 34 M runs; 83 M with it, 15 % of its time). A sphere below radius 10
(ROW_CUT_R2) stops there: it sweeps the slices no plane covers as a sphere
without planes does -- clipping rows of a dozen voxels cost more than they
saved (the mannequin's half-size frames, whose radii are halved, #65).
Skipping a cut is always exact (more visits, same owners); only cutting needs
the margin.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from volanim_core.reconstruct._prefetch import prefetch1, prefetch2

BINARY, MOTTLED, BONE, SAMPLED, HOTSPOT = 0, 1, 2, 3, 4
VECTOR = 4  # float64 lanes of the voxel loop (AVX2's, and AVX-512's as LLVM uses it here)
ROW_CUT_R2 = 100.0  # spheres of radius < 10 clip no rows, only skip the slices a plane covers (fill_slices)
AHEAD = 8  # spheres prefetched ahead in a slice's list (6 to 12 measure alike on the frog)
EUCLID, CHAMFER = 0, 1


@njit(cache=True, inline="always")
def _distance(metric, dx, dy, dz, dy2, dz2):
    if metric == EUCLID:
        return (dx * dx + dy2) + dz2
    a, b, c = abs(dx), abs(dy), abs(dz)
    if a < b:
        a, b = b, a
    if b < c:
        b, c = c, b
    if a < b:
        a, b = b, a
    return 3.0 * a + b + c


@njit(cache=True, inline="always")
def _inside(metric, dx, dy, dz, dy2, dz2, r2, r):
    """The oracle's predicate: squared distance < r2 (Euclid) or chamfer distance < r."""
    d = _distance(metric, dx, dy, dz, dy2, dz2)
    return d < r2 if metric == EUCLID else d < r


@njit(cache=True, inline="always")
def _sample(source, px, py, pz, weights, half):
    sz, sy, sx = source.shape
    ix = int(np.floor(px + 0.5))
    iy = int(np.floor(py + 0.5))
    iz = int(np.floor(pz + 0.5))
    if half == 0:
        if 0 <= ix < sx and 0 <= iy < sy and 0 <= iz < sz:
            return np.float64(source[iz, iy, ix])
        return 0.0
    total = 0.0
    k = 2 * half + 1
    for c in range(k):
        zz = iz + c - half
        if zz < 0 or zz >= sz:
            continue
        for b in range(k):
            yy = iy + b - half
            if yy < 0 or yy >= sy:
                continue
            for a in range(k):
                xx = ix + a - half
                if 0 <= xx < sx:
                    total += weights[c, b, a] * source[zz, yy, xx]
    return total


@njit(cache=True, inline="always")
def slice_cuts(i, dz, yhalf, plane_start, planes, cut_ay, cut_e, cut_inv, cut_side):
    """Sphere i's planes that cut its disc on a slice (``dz`` from its centre, disc radius ``yhalf``),
    written to ``cut_*``: ``x <= cx + (ay dy + e) / -ax`` (right ends), ``x >= ...`` (left ends), or
    the whole row when ``ax = 0``. Returns their number (-1 when one plane covers the whole disc: the
    slice is skipped; a plane that keeps the whole disc is dropped) and ``dy_lo <= dy <= dy_hi``,
    the rows relative to the centre that each plane's part of the disc reaches, widened by a row on
    each side -- a row beyond is a voxel or more past a plane, so cut whole (the rows between cost a
    test each: 72 % of them held nothing on mannequin-large's walk at half size).
    Planes are written in the sphere's own frame ``u = q - c`` (Voronoi half-spaces against larger
    neighbours): ``a.u + w <= 0`` keeps q."""
    n_cut = 0
    dy_lo, dy_hi = -yhalf, yhalf
    for h in range(plane_start[i], plane_start[i + 1]):
        e = planes[h, 2] * dz + planes[h, 3]  # the plane's value at the disc's centre
        norm = planes[h, 4]  # |(ax, ay)|
        reach = norm * yhalf
        if e + reach <= 0.0:
            continue
        if e - reach > 0.0:
            return -1, dy_lo, dy_hi
        ax, ay = planes[h, 0], planes[h, 1]
        cut_ay[n_cut] = ay
        cut_e[n_cut] = e
        cut_inv[n_cut] = -1.0 / ax if ax != 0.0 else 0.0
        cut_side[n_cut] = 1 if ax > 0.0 else (-1 if ax < 0.0 else 0)
        n_cut += 1
        # the kept part of the disc: its chord's ends, and the disc's top or bottom where kept
        half = np.sqrt(max(yhalf * yhalf - (e / norm) ** 2, 0.0)) * abs(ax) / norm
        mid = -e * ay / (norm * norm)
        lo_h = -yhalf if e - ay * yhalf <= 0.0 else mid - half
        hi_h = yhalf if e + ay * yhalf <= 0.0 else mid + half
        dy_lo = max(dy_lo, lo_h - 1.0)
        dy_hi = min(dy_hi, hi_h + 1.0)
    return n_cut, dy_lo, dy_hi


@njit(cache=True, inline="always")
def row_run(metric, cx, dy, dz, dy2, dz2, r2, r, nx, n_cut, cut_ay, cut_e, cut_inv, cut_side):
    """The x-run ``xa..xb`` of a sphere's voxels on one row, within the grid and its cut planes
    (``xa > xb``: none), its ends settled with the oracle's predicate."""
    if metric == EUCLID:
        if dy2 + dz2 >= r2:
            return 0, -1
        xhalf = np.sqrt(r2 - dy2 - dz2)
    else:
        xhalf = r / 3.0
    # The sqrt estimate is exact unless a run end lies within 1e-7 of a voxel
    # centre; only then settle it with the oracle's own predicate.
    lo_edge = cx - xhalf
    hi_edge = cx + xhalf
    xa = int(np.ceil(lo_edge))
    xb = int(np.floor(hi_edge))
    if metric == CHAMFER or xa - lo_edge < 1e-7 or lo_edge - (xa - 1) < 1e-7:
        while _inside(metric, xa - 1 - cx, dy, dz, dy2, dz2, r2, r):
            xa -= 1
        while xa <= xb and not _inside(metric, xa - cx, dy, dz, dy2, dz2, r2, r):
            xa += 1
    if metric == CHAMFER or hi_edge - xb < 1e-7 or (xb + 1) - hi_edge < 1e-7:
        while _inside(metric, xb + 1 - cx, dy, dz, dy2, dz2, r2, r):
            xb += 1
        while xb >= xa and not _inside(metric, xb - cx, dy, dz, dy2, dz2, r2, r):
            xb -= 1
    if xa < 0:
        xa = 0
    if xb > nx - 1:
        xb = nx - 1
    for h in range(n_cut):
        f = cut_ay[h] * dy + cut_e[h]  # the plane's value at u = (0, dy, dz)
        # where it crosses this row, kept within -1..nx before the integer conversion
        lim = max(min(cx + f * cut_inv[h], nx + 1.0), -2.0)
        if cut_side[h] > 0:
            xb = min(xb, int(np.floor(lim)))
        elif cut_side[h] < 0:
            xa = max(xa, int(np.ceil(lim)))
        elif f > 0.0:
            xa = xb + 1
    return xa, xb


@njit(cache=True)
def _rows_in_box(stencil, out, z, ya, yb, cx, cy, dz2, r2, yhalf, value, lo_z, hi_z):
    """A sphere without planes on slice z (Euclid, a relaxing mode): every row over the x-box of the
    slice's disc, with the oracle's predicate per voxel -- no square root, rounding or end-point
    checks per row (the box is at most 4/pi wider than the runs). Returns the box's voxels (the
    sphere's work; the sweep's round-up to whole vectors is not counted).
    It counts nothing per voxel: a sum in the voxel loop costs 16 % of the frog's kernel (rows of
    ~9 voxels run in the loop's scalar remainder), so a slice's filled voxels are counted once at
    its end (:func:`fill_slices`) and its visits are the box's voxels, counted per row.

    Its own function, not inline in :func:`fill_slices`' prange body: written there, numba's
    parfor pass miscompiled it (every win lost; the oracle comparison caught it)."""
    nx = out.shape[2]
    # the voxels strictly within yhalf of cx; the 1e-7 covers the rounding of yhalf and of the
    # oracle's sum (as in fill_slices' run ends)
    xa = max(int(np.floor(cx - yhalf - 1e-7)) + 1, 0)
    xb = min(int(np.ceil(cx + yhalf + 1e-7)) - 1, nx - 1)
    # The sweep is rounded up to whole vectors of VECTOR voxels: a voxel past the box lies outside
    # the disc, fails the predicate and is left as it was -- while a row's scalar remainder loop
    # (the frog's rows are ~10 voxels) cost as much as its vector loop.
    n = xb - xa + 1
    m = (n + VECTOR - 1) // VECTOR * VECTOR
    xs = min(xa, nx - m)  # near the grid's right edge, start further left instead
    if xs < 0:
        xs, m = xa, n
    x0 = xs - cx  # (xs - cx) + k is x - cx exactly (see fill_slices)
    n_visits = 0
    for y in range(ya, yb + 1):
        dy = y - cy
        dy2 = dy * dy
        if dy2 + dz2 >= r2:
            continue
        srow = stencil[y]
        lo_z[y] = min(lo_z[y], xa)
        hi_z[y] = max(hi_z[y], xb)
        n_visits += n
        srun = srow[xs:xs + m]
        orun = out[z, y, xs:xs + m]
        for k in range(m):
            ddx = x0 + k
            dd = (ddx * ddx + dy2) + dz2  # the oracle's sum, in its order
            d = np.float32(dd)
            old = srun[k]
            o = orun[k]
            win = (dd < r2) & ((d < old) | (o == 0))
            srun[k] = d if win else old
            orun[k] = value if win else o
    return n_visits


@njit(cache=True, parallel=True)
def fill_slices(out, scratch, z0, z1, nthreads, offsets, ids, centres, r2s, radii, values, metric, mode,
                plane_start, planes, max_planes, row_lo, row_hi, filled, visits, box_sweep=True, ahead=AHEAD,
                row_cut_r2=ROW_CUT_R2):
    """Fill output slices ``z0 <= z < z1``; see the module docstring.

    ``centres`` are posed centres in output-grid coordinates.
    ``out`` must hold zeros (relaxing modes: a voxel's stencil counts only where ``out``
    is not 0). ``scratch[t]`` is thread t's stencil slice ``[y, x]`` (float32, never
    initialised, nothing reset between slices). ``row_lo[z, y] <= x <= row_hi[z, y]``
    receives the span of the runs that touched row y of slice z (callers pass
    ``row_lo > row_hi``, untouched); only those spans of the output are written, and
    the sampling pass and the filled count read only them.
    ``planes[plane_start[i]:plane_start[i + 1]]`` are sphere i's half-spaces
    (:func:`build_halfspaces`), at most ``max_planes`` per sphere.
    ``filled[z]`` and ``visits[z]`` receive per-slice counts. ``box_sweep``, ``ahead`` (0: no prefetch): speedups.
    """
    ny, nx = out.shape[1], out.shape[2]
    relax = mode != BINARY and mode != HOTSPOT
    for t in prange(nthreads):
        stencil = scratch[t]
        # the planes that cut this sphere's disc in this slice: x <= cx + (ay dy + e) / -ax
        # (right ends), x >= ... (left ends), or the whole row when ax = 0
        cut_ay = np.empty(max_planes)
        cut_e = np.empty(max_planes)
        cut_inv = np.empty(max_planes)
        cut_side = np.empty(max_planes, np.int8)
        for z in range(z0 + t, z1, nthreads):
            n_filled = 0
            n_visits = 0
            # binary and hotspot keep no spans (row_lo is one row): reading row z there read past the array,
            # which compiled code does not check (NUMBA_DISABLE_JIT's IndexError found it)
            lo_z = row_lo[z if relax else 0]
            hi_z = row_hi[z if relax else 0]
            end = offsets[z + 1]
            for k in range(offsets[z], end):
                if ahead and k + ahead < end:  # the sphere `ahead` places on: its data is anywhere in memory
                    j = ids[k + ahead]
                    prefetch2(centres, j, 0)
                    prefetch1(r2s, j)
                    prefetch1(radii, j)
                    prefetch1(plane_start, j)
                i = ids[k]
                cx, cy, cz = centres[i, 0], centres[i, 1], centres[i, 2]
                r2, r = r2s[i], radii[i]
                dz = z - cz
                dz2 = dz * dz
                n_cut = 0
                if metric == EUCLID:
                    # Rows (and slices) that cannot hold a voxel are skipped by a test the
                    # oracle's sum can never beat: fl(fl(dx^2 + dy^2) + dz^2) >= fl(dy^2 + dz^2).
                    if dz2 >= r2:
                        continue
                    yhalf = np.sqrt(r2 - dz2)
                    ya = max(int(np.floor(cy - yhalf)), 0)
                    yb = min(int(np.ceil(cy + yhalf)), ny - 1)
                    # Voronoi half-spaces against larger neighbours: one that cuts the whole disc drops the slice
                    n_cut, dy_lo, dy_hi = slice_cuts(i, dz, yhalf, plane_start, planes, cut_ay, cut_e, cut_inv,
                                                     cut_side)
                    if n_cut < 0:
                        continue
                    ya = max(ya, int(np.floor(cy + dy_lo)))
                    yb = min(yb, int(np.ceil(cy + dy_hi)))
                else:
                    yhalf = r / 3.0
                    ya = max(int(np.floor(cy - yhalf)) - 1, 0)
                    yb = min(int(np.ceil(cy + yhalf)) + 1, ny - 1)
                # a sphere below ROW_CUT_R2 uses its planes per slice only (above: a slice a plane covers is
                # skipped) and sweeps the rest: clipping a short row costs more than the voxels it saves
                if box_sweep and metric == EUCLID and relax and (n_cut == 0 or r2 < row_cut_r2):
                    n_visits += _rows_in_box(stencil, out, z, ya, yb, cx, cy, dz2, r2, yhalf, values[i], lo_z, hi_z)
                    continue
                for y in range(ya, yb + 1):
                    dy = y - cy
                    dy2 = dy * dy
                    xa, xb = row_run(metric, cx, dy, dz, dy2, dz2, r2, r, nx, n_cut, cut_ay, cut_e, cut_inv, cut_side)
                    if xa > xb:
                        continue
                    n_visits += xb - xa + 1
                    if mode == HOTSPOT:
                        for x in range(xa, xb + 1):
                            if out[z, y, x] == 0:
                                n_filled += 1
                            if out[z, y, x] < 65535:
                                out[z, y, x] += 1
                        continue
                    if relax:
                        srow = stencil[y]
                        lo_z[y] = min(lo_z[y], xa)
                        hi_z[y] = max(hi_z[y], xb)
                    if mode == BINARY:  # a union: no relaxation needed, so no stencil
                        for x in range(xa, xb + 1):
                            if out[z, y, x] == 0:
                                n_filled += 1
                                out[z, y, x] = values[i]
                        continue
                    value = values[i]
                    if metric == EUCLID:
                        # Branch-free over a row slice, x as xa + k: LLVM vectorises this (4x on long
                        # runs). (xa - cx) + k equals x - cx exactly: centres are multiples of 2^-20
                        # below 2^31, so every such difference fits a double's 53 bits.
                        srun = srow[xa:xb + 1]
                        orun = out[z, y, xa:xb + 1]
                        x0 = xa - cx
                        for k in range(xb - xa + 1):
                            ddx = x0 + k
                            d = np.float32((ddx * ddx + dy2) + dz2)
                            old = srun[k]
                            o = orun[k]
                            win = (d < old) | (o == 0)
                            srun[k] = d if win else old
                            orun[k] = value if win else o
                        continue
                    for x in range(xa, xb + 1):
                        d = np.float32(_distance(metric, x - cx, dy, dz, dy2, dz2))
                        old = srow[x]
                        if d < old or out[z, y, x] == 0:
                            srow[x] = d
                            out[z, y, x] = value
            if relax:  # filled = the non-zero output in the spans (see _rows_in_box for why not per voxel)
                for y in range(ny):
                    orow = out[z, y]
                    for x in range(lo_z[y], hi_z[y] + 1):
                        n_filled += orow[x] != 0
            filled[z] = n_filled
            visits[z] = n_visits


@njit(cache=True, parallel=True)
def sample_rows(owner, out, z0, z1, nthreads, row_lo, row_hi, minv, source, weights, half):
    """Sampled mode's second pass: ``out[z, y, x] = source(T_b^-1 q)`` where ``owner`` holds
    the winning bone + 1 (0 = empty) on each row's span ``row_lo..row_hi`` (:func:`fill_slices`).
    ``owner`` and ``out`` may be the same array."""
    ny = owner.shape[1]
    for t in prange(nthreads):
        for z in range(z0 + t, z1, nthreads):
            for y in range(ny):
                last = -1
                rx = ry = rz = 0.0
                sx = sy = sz = 0.0
                for x in range(row_lo[z, y], row_hi[z, y] + 1):
                    b = np.int64(owner[z, y, x]) - 1
                    if b < 0:
                        continue
                    if b != last:  # the row's line through the source, for this bone
                        m = minv[b]
                        rx = y * m[1, 0] + z * m[2, 0] + m[3, 0]
                        ry = y * m[1, 1] + z * m[2, 1] + m[3, 1]
                        rz = y * m[1, 2] + z * m[2, 2] + m[3, 2]
                        sx, sy, sz = m[0, 0], m[0, 1], m[0, 2]
                        last = b
                    v = _sample(source, rx + x * sx, ry + x * sy, rz + x * sz, weights, half)
                    out[z, y, x] = np.floor(v + 0.5) if half else v
