"""Numba kernels of the ownership warp (reconstruct/owned.py): each output voxel read once per bone that can reach it.

    warp_owners(labels, flags, rest_lo, inv, boxes, out_lo, out, row_lo, row_hi, claims, count)
        every output voxel q, for each bone b whose posed box holds q (root order), at its rest point
        p = [q 1] @ inv[b]: q is b's (the first such bone keeps it) when the body fills more than half of p
        (trilinear over the 8 voxels around p) and p is b's (its nearest voxel's bone; outside the body, the
        largest share: :func:`claims_point`); a bone moved by whole voxels reads its own voxel, exactly
    posed_cells(cells, size, rest_lo, m, reach, out_lo, marks)
        the output cubes a turned bone's reads can find it in (warp_owners reads only there)
    splat_turned(voxels, bits, diagonals, rest_lo, m, bone, out_lo, out, row_lo, row_hi, claims, count)
        a turned bone's thin rest voxels (and midpoints to its diagonal neighbours) pushed to where they land
    close_joints(out, out_lo, centres, r2s, bones, row_lo, row_hi, claims)
        every empty voxel strictly inside a joint's ball goes to that ball's bone
    Each returns what it wrote (warp_owners: and its reads), summed into the frame's "filled".

Why an inverse warp: a forward one (each owned voxel pushed to its posed place) leaves holes wherever a
rotation spreads voxels apart; reading each output voxel from the rest voxel its bone brings it from writes
every output voxel at most once per bone and leaves none out. Why trilinear, not the nearest voxel: the body
is a voxel segmentation of a smooth shape, and reading it at the nearest voxel turns its surface into stairs
at every turn. The mannequin turned whole by the walk's root (no joint bent) comes back at Dice 0.979 against
its true shape read nearest, 0.985 trilinear (#84: the walk's goal is 0.98). At whole-voxel points both read
the rest labels exactly, so the identity pose gives them back voxel for voxel. ``claims`` counts the bones
(and balls) reaching a voxel: the hotspot mode.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numba import njit

ZB = 4  # output slices a thread takes at a time (warp_owners)


@njit(cache=True, nogil=True, parallel=True)
def warp_owners(labels, flags, spans, rest_lo, inv, shifts, turned, marks, cell, z_first, boxes, out_lo, out, row_lo,
                row_hi, claims, count, threads):
    """``out`` ``[z, y, x]`` (zeroed): each voxel's owning bone + 1. ``labels`` ``[x, y, z]``: the rest owners,
    voxel ``[0, 0, 0]`` at rest voxel ``rest_lo``. ``boxes[b]``: bone b's posed box ``x0 y0 z0 x1 y1 z1`` in
    output indices (empty when x1 < x0). ``row_lo/row_hi[z, y]``:
    each row's span of written voxels. ``count``: also count every bone reaching a voxel in ``claims``
    (hotspot), else stop at the first. ``spans[b, y, z]``: bone b's first and last x on rest row (y, z) of
    ``labels``. ``shifts[b]``: ``dx dy dz 1`` when bone b moves by whole voxels only (its
    voxels are read without rounding), else ``0 0 0 0``. A turned bone b reads only in the output cubes (``cell``
    voxels a side; the launch's first slice is the output's slice ``z_first``) that ``marks[turned[b]]`` holds
    (:func:`posed_cells`). ``threads``: the launch's threads.
    ``flags``: Ownership.flags(). Returns the voxel-bone reads and the voxels written (counted here: a
    count of the output after cost the frog's frame 7 %)."""
    nz, ny, nx = out.shape
    lx, ly, lz = labels.shape
    nb = inv.shape[0]
    nblocks = -(-nz // ZB)
    reads = np.zeros(threads, np.int64)
    wrote = np.zeros(threads, np.int64)
    # blocks of ZB slices dealt round the threads: a thread's share is spread over the launch (a limb fills few
    # slices: split in two halves, one thread had most of the work). Each block row by row, for the labels'
    # cache lines a turn about y shares between the slices; measured, it changes little (the frog's frame on
    # one thread, ZB 1 / 4 / 8: 1.11 / 1.07 / 1.08 times the sphere frame)
    # The two row readers stay inline: as inline helpers returning the row's span they cost the frog's frame
    # 14 % (1.16 -> 1.34 times the sphere frame on one thread)
    for t in numba.prange(threads):
        n = 0
        w = 0
        for k in range(t, nblocks, threads):
            for y in range(ny):
                qy = y + out_lo[1]
                for z in range(k * ZB, min(nz, k * ZB + ZB)):
                    qz = z + out_lo[2]
                    lo_x, hi_x = nx, -1
                    for b in range(nb):
                        if z < boxes[b, 2] or z > boxes[b, 5] or y < boxes[b, 1] or y > boxes[b, 4]:
                            continue
                        m = inv[b]
                        # the rest point of x = 0 and its step per x: a row is a straight line in the rest frame
                        bx = qy * m[1, 0] + qz * m[2, 0] + m[3, 0] - rest_lo[0]
                        by = qy * m[1, 1] + qz * m[2, 1] + m[3, 1] - rest_lo[1]
                        bz = qy * m[1, 2] + qz * m[2, 2] + m[3, 2] - rest_lo[2]
                        x0, x1 = boxes[b, 0], boxes[b, 3]
                        # moved by whole voxels only (most bones of a pose: not at all): no rounding
                        if shifts[b, 3] == 1:
                            iy, iz = qy - shifts[b, 1] - rest_lo[1], qz - shifts[b, 2] - rest_lo[2]
                            if iy < 0 or iz < 0 or iy >= ly or iz >= lz or x1 < x0:
                                continue
                            dx = out_lo[0] - shifts[b, 0] - rest_lo[0]
                            x0, x1 = max(x0, spans[b, iy, iz, 0] - dx), min(x1, spans[b, iy, iz, 1] - dx)
                            n += max(0, x1 - x0 + 1)
                            for x in range(x0, x1 + 1):
                                if labels[x + dx, iy, iz] == b + 1 and (count or out[z, y, x] == 0) and _take(
                                        out, claims, z, y, x, b + 1, count):
                                    lo_x, hi_x = min(lo_x, x), max(hi_x, x)
                                    w += 1
                            continue
                        # the cubes of this row the turned bone can land in
                        row = marks[turned[b], (z + z_first) // cell, y // cell]
                        for c in range(x0 // cell, x1 // cell + 1):
                            if row[c] == 0:
                                continue
                            for x in range(max(x0, c * cell), min(x1, c * cell + cell - 1) + 1):
                                qx = x + out_lo[0]
                                n += 1
                                if not count and out[z, y, x] != 0:
                                    continue
                                if claims_point(labels, flags, bx + qx * m[0, 0], by + qx * m[0, 1],
                                                bz + qx * m[0, 2], b + 1, lx, ly, lz) and _take(out, claims, z, y, x,
                                                                                                b + 1, count):
                                    lo_x, hi_x = min(lo_x, x), max(hi_x, x)
                                    w += 1
                    row_lo[z, y] = min(row_lo[z, y], lo_x)
                    row_hi[z, y] = max(row_hi[z, y], hi_x)
        reads[t] = n
        wrote[t] = w
    return reads.sum(), wrote.sum()


@njit(cache=True, nogil=True, parallel=True)
def zeroed(out):
    """``out`` (``[z, y, x]``, fresh from np.empty) set to 0, slices in parallel: its pages are first touched here,
    by both threads, not one by one inside the warp."""
    for z in numba.prange(out.shape[0]):
        out[z] = 0
    return out


@njit(cache=True, nogil=True, inline="always")
def _take(out, claims, z, y, x, bone1, count):
    """Output voxel ``(z, y, x)`` to label ``bone1`` where no bone has it; in hotspot mode (``count``) one claim
    more either way. Whether it was written (the row's written span then holds x)."""
    wrote = out[z, y, x] == 0
    if wrote:
        out[z, y, x] = bone1
    if count:
        claims[z, y, x] += 1
    return wrote


@njit(cache=True, nogil=True, inline="always")
def _label(labels, x, y, z, lx, ly, lz):
    return labels[x, y, z] if 0 <= x < lx and 0 <= y < ly and 0 <= z < lz else 0


@njit(cache=True, nogil=True, inline="always")
def claims_point(labels, flags, px, py, pz, bone1, lx, ly, lz):
    """Whether label ``bone1`` claims rest point ``p`` (voxel coordinates of ``labels``). The body (labels > 0)
    must fill more than half of p, trilinear over the 8 voxels around it; then p is the nearest voxel's bone, or,
    where the nearest voxel is outside the body, the bone with the largest share of the 8 (a tie to the lower
    label, as the first bone in root order keeps a voxel). Where the nearest voxel's 26 neighbours hold its
    label too (``flags`` bit 1), all 8 do: no interpolation. A nearest voxel of another bone ends the read at
    once: most reads of a bone's posed box fall in other bones' flesh."""
    rx, ry, rz = int(math.floor(px + 0.5)), int(math.floor(py + 0.5)), int(math.floor(pz + 0.5))
    inside = 0 <= rx < lx and 0 <= ry < ly and 0 <= rz < lz
    f = flags[rx, ry, rz] if inside else 0
    # outside the body with no face neighbour in it (bit 8, read before the labels: most refused reads need one
    # line of memory): the corners it shares an axis with are outside, and the others (two or three axes off,
    # each by at most half a voxel) weigh at most half: never more than half body
    if f & 8 or (not inside and (rx < -1 or ry < -1 or rz < -1 or rx > lx or ry > ly or rz > lz)):
        return False
    v = labels[rx, ry, rz] if inside else 0
    if v != 0 and v != bone1:
        return False
    if f & 1:
        return v == bone1
    x0, y0, z0 = int(math.floor(px)), int(math.floor(py)), int(math.floor(pz))
    tx, ty, tz = px - x0, py - y0, pz - z0
    body = 0.0
    mine = 0.0
    whole = x0 >= 0 and y0 >= 0 and z0 >= 0 and x0 + 1 < lx and y0 + 1 < ly and z0 + 1 < lz
    for k in range(8):
        ax, ay, az = k & 1, (k >> 1) & 1, (k >> 2) & 1
        c = labels[x0 + ax, y0 + ay, z0 + az] if whole else _label(labels, x0 + ax, y0 + ay, z0 + az, lx, ly, lz)
        if c == 0:
            continue
        w = (tx if ax else 1.0 - tx) * (ty if ay else 1.0 - ty) * (tz if az else 1.0 - tz)
        body += w
        if c == bone1:
            mine += w
        if v == bone1 and body > 0.5:  # the nearest voxel is the bone's: more than half body is all it needs
            return True
    if body <= 0.5:
        return False
    if v == bone1:
        return True
    if mine <= 0.0:
        return False
    for k in range(8):  # the nearest voxel is outside: any other label with a larger share (or as large and lower) wins
        ax, ay, az = k & 1, (k >> 1) & 1, (k >> 2) & 1
        c = _label(labels, x0 + ax, y0 + ay, z0 + az, lx, ly, lz)
        if c == 0 or c == bone1:
            continue
        other = 0.0
        for j in range(8):
            bx, by, bz = j & 1, (j >> 1) & 1, (j >> 2) & 1
            if _label(labels, x0 + bx, y0 + by, z0 + bz, lx, ly, lz) == c:
                other += (tx if bx else 1.0 - tx) * (ty if by else 1.0 - ty) * (tz if bz else 1.0 - tz)
        if other > mine or (other == mine and c < bone1):
            return False
    return True


@njit(cache=True, nogil=True, parallel=True)
def close_joints(out, out_lo, centres, r2s, bones, row_lo, row_hi, claims, count):
    """Every empty voxel of ``out`` strictly inside a ball (``centres[k]``, squared radius ``r2s[k]``, in rest-grid
    coordinates of the posed frame) is given to the ball's bone ``bones[k]`` (+ 1). Balls in order, the first
    to reach an empty voxel keeps it; ``count``: each ball adds one claim to the voxels it covers. One parallel
    pass over the slices, every ball in it (a pass per ball cost a thread barrier each: 60 ms of a live update's
    box on a busy machine). Returns the voxels written."""
    nz, ny, nx = out.shape
    nk = len(r2s)
    rad = np.sqrt(r2s)
    cs = np.empty((nk, 3))
    for k in range(nk):
        for a in range(3):
            cs[k, a] = centres[k, a] - out_lo[a]
    z_lo, z_hi = nz, -1
    for k in range(nk):
        z_lo = min(z_lo, max(0, int(math.ceil(cs[k, 2] - rad[k]))))
        z_hi = max(z_hi, min(nz - 1, int(math.floor(cs[k, 2] + rad[k]))))
    wrote = np.zeros(max(z_hi + 1, 0), np.int64)  # per slice: a sum over threads without a race
    for z in numba.prange(max(z_lo, 0), z_hi + 1):
        for k in range(nk):
            r, cx, cy, cz = rad[k], cs[k, 0], cs[k, 1], cs[k, 2]
            dz2 = (z - cz) ** 2
            if dz2 >= r2s[k]:
                continue
            for y in range(max(0, int(math.ceil(cy - r))), min(ny - 1, int(math.floor(cy + r))) + 1):
                rest = r2s[k] - dz2 - (y - cy) ** 2
                if rest <= 0:
                    continue
                h = math.sqrt(rest)
                for x in range(max(0, int(math.ceil(cx - h))), min(nx - 1, int(math.floor(cx + h))) + 1):
                    if (x - cx) ** 2 + (y - cy) ** 2 + dz2 >= r2s[k]:
                        continue
                    if count:
                        claims[z, y, x] += 1
                    if out[z, y, x] == 0:
                        out[z, y, x] = bones[k] + 1
                        row_lo[z, y] = min(row_lo[z, y], x)
                        row_hi[z, y] = max(row_hi[z, y], x)
                        wrote[z] += 1
    return wrote.sum()


@njit(cache=True, nogil=True, inline="always")
def _moved(m, px, py, pz):
    """Rest point p moved by the row-vector matrix ``m``: ``[p 1] @ m``, the same sums in every kernel (a
    rounding at .5 then lands alike everywhere)."""
    return (px * m[0, 0] + py * m[1, 0] + pz * m[2, 0] + m[3, 0], px * m[0, 1] + py * m[1, 1] + pz * m[2, 1] + m[3, 1],
            px * m[0, 2] + py * m[1, 2] + pz * m[2, 2] + m[3, 2])


@njit(cache=True, nogil=True, parallel=True)
def posed_cells(cells, size, rest_lo, m, reach, out_lo, marks):
    """Where one turned bone can be read: ``marks[kz, ky, kx]`` (uint8, an output cube of ``size`` voxels a side,
    its first voxel ``size * (kx, ky, kz)`` of the output) set to 1 for every output cube that holds a voxel within
    ``reach (3,)`` along each axis of a rest cube of the bone (``cells``: lower corners / size, on the labels' grid,
    voxel ``[0, 0, 0]`` at ``rest_lo``) moved by ``m`` (``[p 1] @ m``), its centre. A read finds the bone only
    among the 8 voxels around its point, each within a voxel of it along each axis, and a voxel lies within
    half a cube of its cube's centre: ``reach`` is that box moved (reconstruct/owned.cube_reach)."""
    nz, ny, nx = marks.shape
    h = (size - 1) / 2.0
    for i in numba.prange(len(cells)):  # threads may set one mark at once: each writes the same 1
        qx, qy, qz = _moved(m, cells[i, 0] * size + h + rest_lo[0], cells[i, 1] * size + h + rest_lo[1],
                            cells[i, 2] * size + h + rest_lo[2])
        qx, qy, qz = qx - out_lo[0], qy - out_lo[1], qz - out_lo[2]
        rx, ry, rz = reach[0], reach[1], reach[2]
        x0, x1 = max(0, int(math.floor((qx - rx) / size))), min(nx - 1, int(math.floor((qx + rx) / size)))
        y0, y1 = max(0, int(math.floor((qy - ry) / size))), min(ny - 1, int(math.floor((qy + ry) / size)))
        z0, z1 = max(0, int(math.floor((qz - rz) / size))), min(nz - 1, int(math.floor((qz + rz) / size)))
        for z in range(z0, z1 + 1):
            for y in range(y0, y1 + 1):
                for x in range(x0, x1 + 1):
                    marks[z, y, x] = 1


@njit(cache=True, nogil=True)
def splat_turned(voxels, bits, diagonals, rest_lo, m, bone, out_lo, out, row_lo, row_hi, claims, count):
    """Each thin rest voxel of a turned bone (``voxels``: Ownership.thin(), its bone's flesh one voxel thick along
    some axis) written at its posed place rounded, where no bone wrote yet; and the midpoint to each of its edge
    and corner neighbours ``diagonals[d]`` whose bit ``d`` of ``bits`` is set (Ownership.diagonals). The inverse
    read alone can step over a limb one voxel thin that a turn lays across the grid (the ant's legs came apart in single
    voxels); every such voxel pushed to where it lands keeps the limb in one piece: two face neighbours land at
    most one voxel apart on each axis, two diagonal ones with their midpoint between (the ant's leg tip, held on
    by a corner, came off at 90 degrees without it). Thick flesh is left to the read: pushed too, its surface
    came back in stairs (the walk's Dice 0.9762 -> 0.9738). Returns the voxels written."""
    nz, ny, nx = out.shape
    n = 0
    for i in range(len(voxels)):
        ax, ay, az = voxels[i, 0], voxels[i, 1], voxels[i, 2]
        for d in range(-1, len(diagonals)):
            if d < 0:  # the voxel itself
                px, py, pz = float(ax), float(ay), float(az)
            else:
                if not (bits[i] >> d) & 1:
                    continue
                px, py, pz = ax + 0.5 * diagonals[d, 0], ay + 0.5 * diagonals[d, 1], az + 0.5 * diagonals[d, 2]
            # rounded on the rest grid first, then made an index: the same voxel whatever the output's box
            vx, vy, vz = _moved(m, px + rest_lo[0], py + rest_lo[1], pz + rest_lo[2])
            x = int(math.floor(vx + 0.5)) - out_lo[0]
            y = int(math.floor(vy + 0.5)) - out_lo[1]
            z = int(math.floor(vz + 0.5)) - out_lo[2]
            if x < 0 or y < 0 or z < 0 or x >= nx or y >= ny or z >= nz or out[z, y, x] != 0:
                continue
            out[z, y, x] = bone + 1
            row_lo[z, y] = min(row_lo[z, y], x)
            row_hi[z, y] = max(row_hi[z, y], x)
            if count:
                claims[z, y, x] += 1
            n += 1
    return n
