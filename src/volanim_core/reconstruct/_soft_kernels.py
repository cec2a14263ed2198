"""numba kernel of the smoothed rest body (reconstruct/soft_body.py): a separable binomial blur of the body, clamped.

    soft_field(labels, out, shift, threads)
        each slice's body box --> blocks of SB slices dealt round the threads; in a block, each slice it needs
        (the block's and TAPS // 2 beyond each end) blurred along x then y into the thread's own stack of slices
        (integers: x and y weights 1 4 6 4 1, so at most 256) --> each voxel of the block blurred along z (at most
        4096), x 255 / 4096 rounded, clamped by whether it is body, into ``out`` [x, y, z] above the voxel's label
        (label | soft << shift); a voxel outside the boxes of every slice within reach stays 0 (out comes zeroed)
    soft_refusals(flags, packed, shift, half, box)
        in a copy of the labels' flags, bit 8 (refuse a read unread) kept only where it holds for the soft values

Why integers: the weights 1 4 6 4 1 (a Gaussian of sigma 1, as binomial coefficients) sum exactly, so the field
is one exact number whatever the threads, and scipy.ndimage.correlate1d with the same weights gives it bit for
bit (the tests' reference). Why not scipy here: it blurs the whole box on one thread, three passes over float
arrays of the box's size (frog: 1.7 s, a first posed frame's wait); the body's boxes are a part of it, and a
block's slices stay in the thread's stack between passes. The inner loops run along x, the contiguous axis.
"""

from __future__ import annotations

import numba
import numpy as np
from numba import njit

SB = 16  # slices a block: its stack holds SB + 4 blurred slices, 4 of them made again by the next block
WEIGHTS = (1, 4, 6, 4, 1)
TOTAL = 4096  # the three passes' weights multiplied: a voxel deep in the body


@njit(cache=True, nogil=True, parallel=True)
def soft_field(labels, out, shift, threads, box):
    """``out[x, y, z]`` (zeroed; an unsigned integer ``shift`` bits wider than the labels): each voxel's label, and
    above it (``<< shift``) its soft value: ``labels > 0`` correlated with ``1 4 6 4 1`` along x, y and z (outside
    the array: 0), times 255 / 4096 rounded half up; then at least 128 on body voxels, at most 127 elsewhere.
    One array for both: a read between voxels weighs each corner's label and soft value, one cache line, not two.
    ``box`` ``(nz, 4)`` int64: filled with each slice's body's x and y extents (x0 > x1: none)."""
    nx, ny, nz = labels.shape
    for z in numba.prange(nz):  # box[z]: slice z's body's x and y extents (x0 > x1: no body)
        x0, x1, y0, y1 = nx, -1, ny, -1
        for y in range(ny):
            for x in range(nx):
                if labels[x, y, z] != 0:
                    x0, x1, y0, y1 = min(x0, x), max(x1, x), min(y0, y), max(y1, y)
        box[z, 0], box[z, 1], box[z, 2], box[z, 3] = x0, x1, y0, y1
    w = np.array(WEIGHTS, np.int32)
    nblocks = -(-nz // SB)
    stacks = np.zeros((threads, SB + 4, ny, nx), np.uint16)  # [slot, y, x]: slice z0 - 2 + slot, blurred in x, y
    along = np.zeros((threads, ny, nx), np.uint8)
    for t in numba.prange(threads):
        stack, ax = stacks[t], along[t]
        rect = np.empty((SB + 4, 4), np.int64)  # what each slot holds besides zeros: x and y extents
        rect[:, 0], rect[:, 1], rect[:, 2], rect[:, 3] = 0, -1, 0, -1
        for k in range(t, nblocks, threads):
            z0, z1 = k * SB, min(nz, k * SB + SB)
            for c in range(z0 - 2, z1 + 2):
                slot = c - z0 + 2
                s = stack[slot]
                for y in range(rect[slot, 2], rect[slot, 3] + 1):  # what the slot held for the block before
                    s[y, rect[slot, 0]:rect[slot, 1] + 1] = 0
                rect[slot, 0], rect[slot, 1], rect[slot, 2], rect[slot, 3] = 0, -1, 0, -1
                if c < 0 or c >= nz or box[c, 1] < box[c, 0]:
                    continue
                x0, x1, y0, y1 = box[c, 0], box[c, 1], box[c, 2], box[c, 3]
                xa, xb, ya, yb = max(0, x0 - 2), min(nx - 1, x1 + 2), max(0, y0 - 2), min(ny - 1, y1 + 2)
                for y in range(y0, y1 + 1):
                    for x in range(xa, xb + 1):
                        v = 0
                        for i in range(5):
                            if 0 <= x + i - 2 < nx and labels[x + i - 2, y, c] != 0:
                                v += w[i]
                        ax[y, x] = v
                for y in range(ya, yb + 1):
                    for i in range(5):
                        if y0 <= y + i - 2 <= y1:
                            for x in range(xa, xb + 1):
                                s[y, x] += w[i] * ax[y + i - 2, x]
                rect[slot, 0], rect[slot, 1], rect[slot, 2], rect[slot, 3] = xa, xb, ya, yb
            row = np.empty(nx, np.int32)
            for z in range(z0, z1):
                xa, xb, ya, yb = nx, -1, ny, -1  # the slices within reach: the union of what their slots hold
                for i in range(5):
                    slot = z - z0 + i
                    if rect[slot, 1] >= rect[slot, 0]:
                        xa, xb = min(xa, rect[slot, 0]), max(xb, rect[slot, 1])
                        ya, yb = min(ya, rect[slot, 2]), max(yb, rect[slot, 3])
                for y in range(ya, yb + 1):
                    row[xa:xb + 1] = 0
                    for i in range(5):
                        s = stack[z - z0 + i]
                        for x in range(xa, xb + 1):
                            row[x] += w[i] * s[y, x]
                    for x in range(xa, xb + 1):
                        v = (row[x] * 255 + TOTAL // 2) // TOTAL
                        c = np.int64(labels[x, y, z])
                        out[x, y, z] = c | ((max(v, 128) if c != 0 else min(v, 127)) << shift)


@njit(cache=True, nogil=True, inline="always")
def most_read_near(packed, shift, x, y, z, near):
    """The most a trilinear read of the soft values (``packed >> shift``: :func:`soft_field`) can weigh at a point
    whose nearest voxel is ``(x, y, z)`` (outside the array: 0). Within each of the 8 cells around the voxel the read
    is multilinear in the point, so over the part of the cell nearest the voxel (up to half a voxel along each axis)
    it is largest at a corner of that part: the voxel itself, or a point half a voxel off along 1, 2 or 3 axes,
    where it is the mean of the 2, 4 or 8 voxels that point lies between. The largest of those 27 means.
    ``near``: a (3, 3, 3) scratch array, the voxel's neighbourhood read once."""
    nx, ny, nz = packed.shape
    for i in range(3):
        for j in range(3):
            for k in range(3):
                a, b, c = x + i - 1, y + j - 1, z + k - 1
                near[i, j, k] = packed[a, b, c] >> shift if 0 <= a < nx and 0 <= b < ny and 0 <= c < nz else 0
    best = 0.0
    for dx in range(-1, 2):
        for dy in range(-1, 2):
            for dz in range(-1, 2):
                total, n = 0.0, 0
                for ex in range(0, abs(dx) + 1):
                    for ey in range(0, abs(dy) + 1):
                        for ez in range(0, abs(dz) + 1):
                            total += near[1 + ex * dx, 1 + ey * dy, 1 + ez * dz]
                            n += 1
                best = max(best, total / n)
    return best


@njit(cache=True, nogil=True, parallel=True)
def soft_refusals(flags, packed, shift, half, box):
    """Bit 8 of ``flags`` (Ownership.flags' copy: FAR, an outside voxel no face neighbour of which is body) taken away
    where a read nearest the voxel can weigh over ``half`` of the soft values (:func:`most_read_near`). Bit 8 was
    proved for reads of the bare voxels, where the corners two or three axes off weigh at most half; with soft
    values an outside corner weighs up to 127 of 255 too, so near a body voxel two or three axes off it may not
    hold. Only voxels with body among their 26 neighbours are looked at (the others read 0 all round): the slices'
    body boxes (``box``, :func:`soft_field`'s) grown by one."""
    nx, ny, nz = flags.shape
    for z in numba.prange(nz):
        near = np.empty((3, 3, 3), np.float64)
        xa, xb, ya, yb = nx, -1, ny, -1
        for c in range(max(0, z - 1), min(nz, z + 2)):
            if box[c, 1] >= box[c, 0]:
                xa, xb = min(xa, box[c, 0] - 1), max(xb, box[c, 1] + 1)
                ya, yb = min(ya, box[c, 2] - 1), max(yb, box[c, 3] + 1)
        for y in range(max(0, ya), min(ny - 1, yb) + 1):
            for x in range(max(0, xa), min(nx - 1, xb) + 1):
                f = flags[x, y, z]
                if f & 9 == 8 and most_read_near(packed, shift, x, y, z, near) > half:
                    flags[x, y, z] = f & 0xF7
