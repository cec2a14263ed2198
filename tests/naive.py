"""Deliberately simple NumPy references for the numba kernels (test oracles).

Slow and obvious on purpose: each follows docs/formats.md's words line by line.
"""

from __future__ import annotations

import itertools

import numpy as np


def chamfer_offsets_distance(dx, dy, dz):
    """3-4-5 chamfer distance of integer offsets: sort |d| so a >= b >= c, then 3a + b + c."""
    a = np.sort(np.abs(np.stack([dx, dy, dz])), axis=0)[::-1]
    return 3 * a[0] + a[1] + a[2]


def distance_transform(mask, metric="euclid"):
    """Brute force: min distance from each object voxel to any background voxel centre,
    the volume surrounded by a one-voxel ring of background."""
    m = np.pad(np.asarray(mask) != 0, 1)
    bg = np.argwhere(~m)
    out = np.zeros(m.shape, np.float64)
    for p in np.argwhere(m):
        d = bg - p
        if metric == "euclid":
            out[tuple(p)] = np.sqrt((d.astype(np.float64) ** 2).sum(1)).min()
        else:
            out[tuple(p)] = chamfer_offsets_distance(d[:, 0], d[:, 1], d[:, 2]).min()
    return out[1:-1, 1:-1, 1:-1]


def thinness(dt):
    """DT(p) minus the mean DT over its 26 neighbours (outside = 0), for every voxel."""
    p = np.pad(dt, 1)
    total = np.zeros_like(dt, dtype=np.float64)
    X, Y, Z = dt.shape
    for dx, dy, dz in itertools.product((-1, 0, 1), repeat=3):
        if dx == dy == dz == 0:
            continue
        total += p[1 + dx : 1 + dx + X, 1 + dy : 1 + dy + Y, 1 + dz : 1 + dz + Z]
    return dt - total / 26.0


def union_of_balls(points, radii, shape, metric="euclid"):
    """Voxels q with |q - p| < r for some (p, r): a plain loop over every ball."""
    out = np.zeros(shape, bool)
    grid = np.indices(shape)
    for p, r in zip(points, radii):
        d = grid - np.asarray(p).reshape(3, 1, 1, 1)
        if metric == "euclid":
            out |= (d**2).sum(0) < r * r - 1e-9 * r * r  # dt = sqrt(k): strictly inside
        else:
            out |= chamfer_offsets_distance(d[0], d[1], d[2]) < r
    return out


def reconstruct(tskel, bounds, *, mode="binary", source=None, source_origin=(0, 0, 0), kernel=1, value=255):
    """docs/formats.md's reconstruction, sphere by sphere over each sphere's bounding box.

    Shares only the definitions of the posed centre, the snapped radius and the
    mottled values with the library (they define the semantics); the voxel
    loops, distances, ties and sampling are written out here independently.
    Returns ``(volume[x, y, z], stencil, ties)``: ``ties`` marks sampled voxels whose
    source position is within 1e-6 of half-way between voxels (either rounding is right).
    """
    from volanim_core.reconstruct.engine import mottled_values, posed_centres
    from volanim_core.reconstruct.radii import radius_squared
    from volanim_core.reconstruct.sampling import gaussian_weights

    lo = np.asarray(bounds.lo)
    shape = tuple(int(v) for v in np.asarray(bounds.hi) - lo + 1)
    dtype = {"hotspot": np.uint16, "sampled": None}.get(mode, np.uint8)
    out = np.zeros(shape, source.dtype if mode == "sampled" else dtype)
    best = np.full(shape, np.inf, np.float32)
    ties = np.zeros(shape, bool)
    centres = posed_centres(tskel)
    r2 = radius_squared(tskel.dt)
    mott = mottled_values(len(tskel))
    chamfer = tskel.metric == "345"
    for i, c in enumerate(centres):
        r = tskel.dt[i]
        half = r / 3 if chamfer else np.sqrt(r2[i])
        blo = np.floor(c - half).astype(int) - 1
        bhi = np.ceil(c + half).astype(int) + 1
        g = np.stack(np.meshgrid(*[np.arange(a, b + 1) for a, b in zip(blo, bhi)], indexing="ij"))
        d = g - c.reshape(3, 1, 1, 1)
        if chamfer:
            dist = chamfer_offsets_distance(d[0], d[1], d[2]).astype(np.float64)
            inside = dist < r
        else:
            dist = d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
            inside = dist < r2[i]
        idx = g - lo.reshape(3, 1, 1, 1)
        inside &= ((idx >= 0) & (idx < np.array(shape).reshape(3, 1, 1, 1))).all(0)
        q = idx[:, inside]
        dist32 = dist[inside].astype(np.float32)
        if mode == "hotspot":
            out[tuple(q)] += 1
            continue
        win = dist32 < best[tuple(q)]
        qw = q[:, win]
        best[tuple(qw)] = dist32[win]
        if mode == "binary":
            out[tuple(qw)] = value
        elif mode == "mottled":
            out[tuple(qw)] = mott[i]
        elif mode == "bone":
            out[tuple(qw)] = tskel.bone[i] + 1
        else:
            minv = np.linalg.inv(tskel.matrices[tskel.bone[i]])
            pos = (qw.T + lo) @ minv[:3, :3] + minv[3, :3] - np.asarray(source_origin)
            near = np.floor(pos + 0.5).astype(int)
            ties[tuple(qw)] = (np.abs(pos - np.floor(pos) - 0.5) < 1e-6).any(1)
            if kernel == 1:
                ok = ((near >= 0) & (near < source.shape)).all(1)
                vals = np.zeros(len(near), source.dtype)
                vals[ok] = source[tuple(near[ok].T)]
            else:
                w = gaussian_weights(kernel)  # [z, y, x]
                h = kernel // 2
                padded = np.pad(source.astype(np.float64), h)
                acc = np.zeros(len(near))
                for a in range(kernel):
                    for b in range(kernel):
                        for cc in range(kernel):
                            nb = near + [a - h, b - h, cc - h] + h
                            ok = ((nb >= 0) & (nb < padded.shape)).all(1)
                            acc[ok] += w[cc, b, a] * padded[tuple(nb[ok].T)]
                vals = np.floor(acc + 0.5)
            out[tuple(qw)] = vals
    return out, best, ties


def _quaternion_of(rot):
    """Unit quaternion (w, x, y, z) of a 3x3 rotation, Shepperd's method, one branch at a time."""
    m = np.asarray(rot, np.float64)
    tr = m[0, 0] + m[1, 1] + m[2, 2]
    if tr > 0:
        s = np.sqrt(tr + 1.0) * 2
        q = [0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s]
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = np.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2]) * 2
        q = [(m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s]
    elif m[1, 1] > m[2, 2]:
        s = np.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2]) * 2
        q = [(m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s]
    else:
        s = np.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1]) * 2
        q = [(m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s]
    return np.array(q)


def _qmul(a, b):
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])


def dual_quaternion_blend(point, matrices, influence, weight):
    """Kavan et al. 2007, one point: sum w_k (q_k, 0.5 t_k q_k) (each q_k on q_0's side), normalise,
    then p' = R(q) p + t with t = 2 d q*. ``matrices`` are row-vector rigid 4x4."""
    real, dual = np.zeros(4), np.zeros(4)
    first = None
    for b, w in zip(influence, weight):
        if b < 0 or w == 0:
            continue
        m = np.asarray(matrices[b], np.float64)
        q = _quaternion_of(m[:3, :3].T)
        if first is None:
            first = q
        if np.dot(q, first) < 0:
            q = -q
        d = 0.5 * _qmul(np.array([0.0, *m[3, :3]]), q)
        real += w * q
        dual += w * d
    n = np.linalg.norm(real)
    real, dual = real / n, dual / n
    t = 2 * _qmul(dual, real * np.array([1, -1, -1, -1]))[1:]
    v = _qmul(_qmul(real, np.array([0.0, *point])), real * np.array([1, -1, -1, -1]))[1:]
    return v + t


def thinned_radii(rest, posed, dt, sheet, pairs, floor):
    """Smooth joints' radii of a posed frame, one point at a time: a sheet point's radius over the mean
    of ``|posed_a - posed_b| / |rest_a - rest_b|`` over its links ``pairs``, kept within ``floor``..1 of it."""
    ratios = {}
    for a, b in pairs:
        ratio = np.linalg.norm(posed[a] - posed[b]) / np.linalg.norm(np.subtract(rest[a], rest[b], dtype=float))
        ratios.setdefault(a, []).append(ratio)
        ratios.setdefault(b, []).append(ratio)
    out = np.array(dt, np.float64)
    for p in sheet:
        mean = sum(ratios[p]) / len(ratios[p])
        if mean > 1 + 1e-6:
            out[p] = dt[p] * min(1.0, max(floor, 1.0 / mean))
    return out


def _claims(labels, p, bone1):
    """Whether label ``bone1`` claims the rest point ``p`` (labels' voxel coordinates): the 8 voxels around p,
    weighted trilinearly (outside the array: 0), fill more than half of it with body, and p's nearest voxel is
    bone1's or, when that voxel is outside the body, bone1's share of the 8 is the largest (a tie to the lower
    label)."""
    import math

    base = [int(math.floor(v)) for v in p]
    share: dict[int, float] = {}
    for corner in np.ndindex(2, 2, 2):
        k = [base[a] + corner[a] for a in range(3)]
        w = 1.0
        for a in range(3):
            t = p[a] - base[a]
            w *= t if corner[a] else 1.0 - t
        inside = all(0 <= k[a] < labels.shape[a] for a in range(3))
        v = int(labels[tuple(k)]) if inside else 0
        if v:
            share[v] = share.get(v, 0.0) + w
    near = [int(math.floor(v + 0.5)) for v in p]
    nearest = int(labels[tuple(near)]) if all(0 <= near[a] < labels.shape[a] for a in range(3)) else 0
    if sum(share.values()) <= 0.5 or nearest not in (0, bone1):
        return False
    if nearest == bone1:
        return True
    if share.get(bone1, 0.0) <= 0.0:
        return False
    return all(w < share[bone1] or (w == share[bone1] and v > bone1) for v, w in share.items() if v != bone1)


def _label_at(labels, j):
    """The label at voxel ``j``; 0 outside the array."""
    return labels[tuple(j)] if all(0 <= j[a] < labels.shape[a] for a in range(3)) else 0


def _unjoined(labels, k, step):
    """Whether voxel ``k``'s edge or corner neighbour ``k + step`` is of its bone and no thin voxel of its bone
    lies a face step from ``k`` along one of ``step``'s axes."""
    mine = labels[tuple(k)]
    if _label_at(labels, k + step) != mine:
        return False
    for a in np.flatnonzero(step):
        face = k + np.where(np.arange(3) == a, step, 0)
        if _label_at(labels, face) == mine and _thin(labels, face):
            return False
    return True


def _thin(labels, k):
    """A body voxel whose two face neighbours along some axis are both not of its label (outside the body, another
    bone's, or outside the array)."""
    def mine(j):
        return all(0 <= j[a] < labels.shape[a] for a in range(3)) and labels[tuple(j)] == labels[tuple(k)]

    for a in range(3):
        lo, hi = list(k), list(k)
        lo[a] -= 1
        hi[a] += 1
        if not mine(lo) and not mine(hi):
            return True
    return False


def owned_warp(labels, rest_lo, matrices, bounds, balls=()):
    """The ownership warp (reconstruct/owned.py) voxel by voxel: each output voxel q of ``bounds`` is bone b's
    (first in order) when b claims the rest point ``[q 1] @ inv(M_b)`` (:func:`_claims`: the body's trilinear
    share there more than half, and p b's); a bone moved by whole voxels only reads its own voxel there.
    Then each thin rest voxel (its bone's flesh one voxel thick along an axis) of a turned bone is written where
    it lands, rounded, if that is empty, and so is the midpoint to each of its edge and corner neighbours of the
    same bone (unless a thin voxel of the bone lies a face step from it on the way); then each
    empty voxel strictly inside a ball ``(centre, radius, bone)`` (in order) is that ball's bone. Returns 1 + bone
    per voxel ``[x, y, z]``."""
    import math

    lo, hi = np.asarray(bounds[0]), np.asarray(bounds[1])
    out = np.zeros(tuple(hi - lo + 1), np.int64)
    for b, m in enumerate(matrices):
        inv = np.linalg.inv(m)
        whole = np.array_equal(m[:3, :3], np.eye(3)) and np.array_equal(m[3, :3], np.round(m[3, :3]))
        for idx in np.ndindex(*out.shape):
            if out[idx]:
                continue
            q = np.asarray(idx) + lo
            if whole:
                k = q - np.round(m[3, :3]).astype(np.int64) - rest_lo
                if (k >= 0).all() and (k < labels.shape).all() and labels[tuple(k)] == b + 1:
                    out[idx] = b + 1
            elif _claims(labels, q @ inv[:3, :3] + inv[3, :3] - rest_lo, b + 1):
                out[idx] = b + 1
    for b, m in enumerate(matrices):  # each turned bone's thin rest voxels pushed to where they land, if empty
        if np.array_equal(m[:3, :3], np.eye(3)) and np.array_equal(m[3, :3], np.round(m[3, :3])):
            continue
        for k in np.argwhere(labels == b + 1):
            if not _thin(labels, k):
                continue
            at = k + rest_lo
            points = [at] + [at + (np.array(d) - 1) / 2 for d in np.ndindex(3, 3, 3)
                             if np.abs(np.array(d) - 1).sum() >= 2 and _unjoined(labels, k, np.array(d) - 1)]
            for p in points:
                v = [p[0] * m[0, i] + p[1] * m[1, i] + p[2] * m[2, i] + m[3, i] for i in range(3)]  # kernel's sums
                q = np.array([int(math.floor(x + 0.5)) for x in v]) - lo
                if (q >= 0).all() and (q < out.shape).all() and out[tuple(q)] == 0:
                    out[tuple(q)] = b + 1
    for centre, radius, bone in balls:
        for idx in np.ndindex(*out.shape):
            q = np.asarray(idx) + lo
            if out[idx] == 0 and ((q - centre) ** 2).sum() < radius ** 2:
                out[idx] = bone + 1
    return out


def voxel_flags(labels):
    """Ownership.flags() by its definition (rig/_ownership_kernels.voxel_flags), with whole-array shifts:
    1 where the 3x3x3 around a voxel holds its label (outside the array: 0), 2 on a body voxel whose two face
    neighbours along some axis are not of its label, 4 on an outside voxel with a face neighbour in the body, 8
    on every other outside voxel."""
    nx, ny, nz = labels.shape
    p = np.pad(labels, 1)
    same = np.ones(labels.shape, bool)
    for dx, dy, dz in np.ndindex(3, 3, 3):
        same &= p[dx:dx + nx, dy:dy + ny, dz:dz + nz] == labels
    inside = np.pad(labels != 0, 1)
    body = labels != 0

    def at(d):
        return inside[1 + d[0]:1 + d[0] + nx, 1 + d[1]:1 + d[1] + ny, 1 + d[2]:1 + d[2] + nz]

    def label_at(d):
        return p[1 + d[0]:1 + d[0] + nx, 1 + d[1]:1 + d[1] + ny, 1 + d[2]:1 + d[2] + nz]

    axes = np.eye(3, dtype=int)
    thin = body & np.any([(label_at(a) != labels) & (label_at(-a) != labels) for a in axes], axis=0)
    skin = ~body & np.any([at(a) | at(-a) for a in axes], axis=0)
    return (same * 1 | thin * 2 | skin * 4 | (~body & ~skin) * 8).astype(np.uint8)


def paint_runs(shape, first, x0, x1, piece) -> np.ndarray:
    """The label grid the runs describe (plain loop): volanim_core/_run_kernels' rows ``z * ny + y``."""
    out = np.zeros(shape, np.int64)
    for row in range(len(first) - 1):
        z, y = divmod(row, shape[1])
        for r in range(first[row], first[row + 1]):
            out[z, y, x0[r]:x1[r] + 1] = piece[r]
    return out
