"""Effects: frames added after a clip's last pose, run by the same sequence machinery.

    melt(frames, N)              every sphere's DT shrinks linearly to 0 (the old ``meltMan``)
    teleport(conn, frames, N)    a beam sweeps head to feet; each sphere shrinks to 0 as it passes
    crumble(frames, N)           voxels fall with constant acceleration and pile into a heap (``multiVolumeMelt``);
                                 with ``melt`` the spheres shrink as they fall; ``heap="sum"``: the thesis's heap colour

Melt and teleport only scale the radii, so their frames are ordinary
reconstructions. A crumble frame is the last pose reconstructed and then
:func:`fall`-en: a pure function of that volume and how far the fall has gone,
so each frame is computed on its own (any worker, any order, bit-identical).
"""

from __future__ import annotations

import numpy as np

from volanim_core.rig.connectivity import Connectivity

from .frames import FrameSpec

AXES = {"x": 0, "y": 1, "z": 2}
TELEPORT_SWEEP = 0.25  # the fraction of the effect each sphere takes to vanish once the beam reaches it


def parse_axis(text: str) -> tuple[int, int]:
    """``"-z"`` -> (2, -1): the axis index and the direction along it."""
    t = text.strip().lower()
    sign = -1 if t.startswith("-") else 1
    name = t.lstrip("+-")
    if name not in AXES or len(t) - len(name) > 1:
        raise ValueError(f"an axis is x, y or z with an optional sign (e.g. -z), got {text!r}")
    return AXES[name], sign


def _check(after: list[FrameSpec], n: int, effect: str) -> FrameSpec:
    if n < 1:
        raise ValueError(f"a {effect} needs at least one frame, got {n}")
    if not after:
        raise ValueError(f"a {effect} follows a pose: give frames before it")
    return after[-1]


def melt(after: list[FrameSpec], n: int) -> list[FrameSpec]:
    """``n`` frames after the last one: its pose held while every sphere's DT shrinks linearly to 0."""
    last = _check(after, n, "melt")
    return [FrameSpec(last.number + k, last.matrices, float(1.0 - k / n)) for k in range(1, n + 1)]


def teleport(conn: Connectivity, after: list[FrameSpec], n: int, down: str = "-z", seed: int = 0) -> list[FrameSpec]:
    """``n`` frames in which a beam sweeps from the top of the last pose to its feet; a sphere
    starts to shrink when the beam reaches it (give or take a little sparkle) and is gone
    ``TELEPORT_SWEEP`` of the effect later. The last frame is empty."""
    from volanim_core.reconstruct.engine import posed_centres

    last = _check(after, n, "teleport")
    axis, sign = parse_axis(down)
    height = -sign * posed_centres(last.tskel(conn))[:, axis]  # larger = higher
    span = max(float(np.ptp(height)) if len(height) else 0.0, 1e-9)
    w = TELEPORT_SWEEP
    start = (height.max(initial=0.0) - height) / span * (1.0 - w)  # the top goes first
    start += np.random.default_rng(seed).uniform(-0.04, 0.04, len(start)) * (1.0 - w)  # sparkle, reproducible
    start = np.clip(start, 0.0, 1.0 - w)
    out = []
    for k in range(1, n + 1):
        scale = np.clip(1.0 - (k / n - start) / w, 0.0, 1.0)
        out.append(FrameSpec(last.number + k, last.matrices, scale))
    return out


HEAPS = ("keep", "sum")  # a heap voxel: its own grain's value, or the capped sum resting on it (multiVolumeMelt)


def crumble(after: list[FrameSpec], n: int, down: str = "-z", *, acceleration: float = 0.0, heap: str = "keep",
            melt: int = 0, conn: Connectivity | None = None) -> list[FrameSpec]:
    """``n`` frames in which the last pose's voxels fall onto the floor under its lowest voxel.

    By default the distance grows with the square of time so that the top lands exactly at the last
    frame; ``acceleration`` (voxels per frame², the thesis's multiVolumeMelt parameter) gives the
    distance ``a k² / 2`` at frame k instead, landed or not. ``melt`` (frames; needs ``conn``) shrinks
    every sphere to nothing over that many frames while it falls: the floor and the height stay the
    standing pose's. ``heap`` is :data:`HEAPS`.
    """
    last = _check(after, n, "crumble")
    axis, sign = parse_axis(down)  # refuse a bad axis before any frame runs
    if heap not in HEAPS:
        raise ValueError(f"a heap is one of {', '.join(HEAPS)}, got {heap!r}")
    if not np.isfinite(acceleration) or acceleration < 0:
        raise ValueError(f"the acceleration is a number of voxels per frame squared >= 0, got {acceleration}")
    total = max(n, melt)
    floor = height = None
    if melt or acceleration:  # distances fixed now, from the standing body: a shrinking one keeps its floor
        if conn is None:
            raise ValueError("a crumble that melts or has an acceleration needs the connectivity")
        from volanim_core.reconstruct.engine import grid_bounds

        box = grid_bounds(last.tskel(conn), 0)
        floor = box.lo[axis] if sign < 0 else box.hi[axis]
        height = box.hi[axis] - box.lo[axis]
    out = []
    for k in range(1, total + 1):
        fraction = min(k / n, 1.0)
        drop = None
        if floor is not None:
            drop = 0.5 * acceleration * k * k if acceleration else height * fraction * fraction
        scale = max(0.0, 1.0 - k / melt) if melt else 1.0
        out.append(FrameSpec(last.number + k, last.matrices, scale, fraction, down, heap=heap, floor=floor,
                             drop=drop))
    return out


def fall(volume: np.ndarray, fraction: float, down: str = "-z", *, heap: str = "keep", floor: int | None = None,
         drop: float | None = None) -> np.ndarray:
    """``volume`` (x, y, z) after its voxels have fallen ``fraction`` (0..1) of the way.

    Every filled voxel falls straight down its column by ``d = H * fraction**2``
    voxels (constant acceleration; ``H`` = the body's height above the floor, its
    lowest voxel), so the top lands exactly at ``fraction = 1``; ``drop`` gives
    ``d`` itself and ``floor`` the floor's index along the axis (a body that moves
    or melts while it falls keeps the floor it stood on). Nothing passes
    through anything: voxel ``r`` of a column (counted from the bottom) would be
    at ``max(z - d, floor + r)``; those resting (the second term wins -- always the
    bottom of a column) form the heap, which slumps until no slope is steeper than
    45 degrees (:func:`settle`; the grid's sides are walls). Voxels that the
    settled heap now reaches land on it and settle too, until the rest are all
    above it, still falling. With ``heap="keep"`` every voxel keeps its value, so
    the heap is coloured by everything that fell on it; with ``"sum"`` a heap voxel
    holds the sum of its value and those resting above it in its column, capped
    at the type's maximum (the thesis's multiVolumeMelt). Each frame is computed
    from the standing volume alone: any worker, any order, the same voxels.
    """
    from ._heap_kernels import settle

    if not 0.0 <= fraction <= 1.0:
        raise ValueError(f"a fall fraction is between 0 and 1, got {fraction}")
    if heap not in HEAPS:
        raise ValueError(f"a heap is one of {', '.join(HEAPS)}, got {heap!r}")
    axis, sign = parse_axis(down)
    if fraction == 0.0 and not drop:
        return volume.copy()  # still standing: it turns to sand the moment it starts to fall
    a = np.moveaxis(volume, axis, -1)
    if sign > 0:
        a = a[..., ::-1]  # falling toward higher indices: flip so that down is always toward 0
        floor = None if floor is None else a.shape[2] - 1 - floor
    i, j, k = np.nonzero(a)  # C order: by column, then from the bottom up within a column
    out = np.zeros_like(a)
    if len(k):
        floor = int(k.min()) if floor is None else max(0, min(int(floor), int(k.min())))
        d = int(np.floor((int(k.max()) - floor) * fraction * fraction + 1e-9)) if drop is None else int(drop)
        ny = a.shape[1]
        heights = np.zeros(a.shape[:2], np.int64)
        stacks = np.full((*a.shape[:2], a.shape[2] - floor), -1, np.int32)  # grain ids, bottom up
        falling = np.arange(len(k))
        while True:  # land what reaches the heap, let it settle, repeat (settling can lift a column)
            fi, fj = i[falling], j[falling]
            above = floor + heights[fi, fj] + _rank_among(fi, fj, ny)  # where each would rest now
            lands = k[falling] - d <= above  # a prefix of every column (k - rank never decreases)
            if not lands.any():
                break
            g = falling[lands]
            if above[lands].max() - floor >= stacks.shape[2]:  # pushed up past the top by the slumping heap
                raise ValueError(f"the heap does not fit in the grid ({a.shape[2] - floor} voxels of room above "
                                 "the floor): give the sequence more --padding")
            stacks[i[g], j[g], above[lands] - floor] = g
            np.add.at(heights, (i[g], j[g]), 1)
            settle(stacks, heights)
            falling = falling[~lands]
        values = a[i, j, k]
        if heap == "sum":
            out[..., floor:] = _resting_sums(stacks, values, a.dtype)
        else:
            x, y, h = np.nonzero(stacks >= 0)
            out[x, y, floor + h] = values[stacks[x, y, h]]
        fi, fj = i[falling], j[falling]  # still in the air, above the heap
        out[fi, fj, k[falling] - d] = values[falling]
    if sign > 0:
        out = out[..., ::-1]
    return np.ascontiguousarray(np.moveaxis(out, -1, axis))


def fall_series(volumes, n: int, down: str = "-z", *, acceleration: float = 0.0, heap: str = "keep",
                frames=None):
    """The thesis's multiVolumeMelt on any volumes: ``n`` frames, frame k (1..n) fallen as :func:`fall` makes
    it, all onto the floor under the first volume's lowest voxel; ``acceleration`` as in :func:`crumble`.

    ``volumes``: one (held), or as many as frames, or -- as the thesis fed it "a few frames ... to produce a
    large number of crumbling volumes" -- fewer: each held for an equal run of frames, in order (2 volumes,
    6 frames: the first for frames 1-3, the second for 4-6). ``frames``: only these frame numbers (the
    thesis's desiredFrame; a frame does not depend on the others). Yields ``(k, volume)`` one at a time.
    Only the first volume and the frames' own are looked at, so ``volumes`` may be a lazy sequence: one
    frame of a long series reads two files, not all of them."""
    if n < 1:
        raise ValueError(f"a crumble needs at least one frame, got {n}")
    m = len(volumes)
    if not 1 <= m <= n:
        raise ValueError(f"give at most one volume a frame: {m} volumes for {n} frames")
    wanted = range(1, n + 1) if frames is None else list(frames)
    bad = [k for k in wanted if not 1 <= k <= n]
    if bad:
        raise ValueError(f"frame {bad[0]} is not one of the crumble's frames 1..{n}")
    axis, sign = parse_axis(down)
    first = volumes[0]
    if any(volumes[i].shape != first.shape for i in sorted({(k - 1) * m // n for k in wanted})):
        raise ValueError("the volumes of a series must share one grid")
    filled = np.flatnonzero(np.moveaxis(first, axis, 0).reshape(first.shape[axis], -1).any(axis=1))
    floor, height = (int(filled[0] if sign < 0 else filled[-1]), int(np.ptp(filled))) if len(filled) else (0, 0)
    for k in wanted:
        drop = 0.5 * acceleration * k * k if acceleration else height * (k / n) ** 2
        yield k, fall(volumes[(k - 1) * m // n], k / n, down, heap=heap, floor=floor, drop=drop)


def _resting_sums(stacks: np.ndarray, values: np.ndarray, dtype) -> np.ndarray:
    """Each heap voxel's value plus those resting above it in its column, capped at ``dtype``'s maximum."""
    grain = np.where(stacks >= 0, values[np.maximum(stacks, 0)].astype(np.float64), 0.0)
    sums = np.cumsum(grain[..., ::-1], axis=2)[..., ::-1]
    cap = np.iinfo(dtype).max if np.issubdtype(dtype, np.integer) else np.inf
    return np.where(stacks >= 0, np.minimum(sums, cap), 0).astype(dtype)


def _rank_among(i: np.ndarray, j: np.ndarray, ny: int) -> np.ndarray:
    """Each entry's position within its run of equal ``(i, j)`` (entries sorted by column)."""
    if not len(i):
        return np.zeros(0, np.int64)
    column = i.astype(np.int64) * ny + j
    first = np.flatnonzero(np.r_[True, column[1:] != column[:-1]])
    return np.arange(len(i)) - np.repeat(first, np.diff(np.r_[first, len(i)]))
