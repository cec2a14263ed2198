"""Effects: frames added after a clip's last pose, run by the same sequence machinery.

    melt(frames, N)              every sphere's DT shrinks linearly to 0 (the old ``meltMan``)
    teleport(conn, frames, N)    a beam sweeps head to feet; each sphere shrinks to 0 as it passes
    crumble(frames, N)           voxels fall with constant acceleration and pile into a heap (``multiVolumeMelt``)

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


def crumble(after: list[FrameSpec], n: int, down: str = "-z") -> list[FrameSpec]:
    """``n`` frames in which the last pose's voxels fall (distance grows with the square of time)
    onto the floor under its lowest voxel; the top lands exactly at the last frame."""
    last = _check(after, n, "crumble")
    parse_axis(down)  # refuse a bad axis before any frame runs
    return [FrameSpec(last.number + k, last.matrices, 1.0, k / n, down) for k in range(1, n + 1)]


def fall(volume: np.ndarray, fraction: float, down: str = "-z") -> np.ndarray:
    """``volume`` (x, y, z) after its voxels have fallen ``fraction`` (0..1) of the way.

    Every filled voxel falls straight down its column by ``d = H * fraction**2``
    voxels (constant acceleration; ``H`` = the body's height above the floor, its
    lowest voxel), so the top lands exactly at ``fraction = 1``. Nothing passes
    through anything: voxel ``r`` of a column (counted from the bottom) would be
    at ``max(z - d, floor + r)``; those resting (the second term wins -- always the
    bottom of a column) form the heap, which slumps until no slope is steeper than
    45 degrees (:func:`settle`; the grid's sides are walls). Voxels that the
    settled heap now reaches land on it and settle too, until the rest are all
    above it, still falling. Every voxel keeps its value, so the heap
    is coloured by everything that fell on it. Each frame is computed from the
    standing volume alone: any worker, any order, the same voxels.
    """
    from ._heap_kernels import settle

    if not 0.0 <= fraction <= 1.0:
        raise ValueError(f"a fall fraction is between 0 and 1, got {fraction}")
    axis, sign = parse_axis(down)
    if fraction == 0.0:
        return volume.copy()  # still standing: it turns to sand the moment it starts to fall
    a = np.moveaxis(volume, axis, -1)
    if sign > 0:
        a = a[..., ::-1]  # falling toward higher indices: flip so that down is always toward 0
    i, j, k = np.nonzero(a)  # C order: by column, then from the bottom up within a column
    out = np.zeros_like(a)
    if len(k):
        floor = int(k.min())
        d = int(np.floor((int(k.max()) - floor) * fraction * fraction + 1e-9))
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
        x, y, h = np.nonzero(stacks >= 0)
        out[x, y, floor + h] = a[i, j, k][stacks[x, y, h]]
        fi, fj = i[falling], j[falling]  # still in the air, above the heap
        out[fi, fj, k[falling] - d] = a[fi, fj, k[falling]]
    if sign > 0:
        out = out[..., ::-1]
    return np.ascontiguousarray(np.moveaxis(out, -1, axis))


def _rank_among(i: np.ndarray, j: np.ndarray, ny: int) -> np.ndarray:
    """Each entry's position within its run of equal ``(i, j)`` (entries sorted by column)."""
    if not len(i):
        return np.zeros(0, np.int64)
    column = i.astype(np.int64) * ny + j
    first = np.flatnonzero(np.r_[True, column[1:] != column[:-1]])
    return np.arange(len(i)) - np.repeat(first, np.diff(np.r_[first, len(i)]))
