"""The one function that reconstructs a frame of a sequence, wherever it runs.

    Payload (connectivity, source, mode, shared bounds, store path)
        --local pool: handed to each worker process once (initializer)
        --Dask: scattered to every worker once, passed to each task as a future
    reconstruct_frame(payload, index, spec, grid) --> writes shard ``index`` of the zarr store
        (+ the optional per-frame file) --> returns statistics, never the voxels
    reconstruct_frames(payload, [(index, spec, grid), ...]) --> several short frames as one task

Neighbour lists depend on the connectivity and the radii, not on the pose,
so each worker computes them once per DT scale and keeps them.
"""

from __future__ import annotations

import os
import socket
import time
from dataclasses import dataclass

import numpy as np

from volanim_core.limits import peak_rss
from volanim_core.rig.connectivity import Connectivity
from volanim_core.volume import Bounds, tight_bounds

from .frames import FrameSpec
from .store import CHUNK_EDGE, frame_record, open_frames


@dataclass
class Payload:
    conn: Connectivity
    mode: str
    kernel: int
    bounds: Bounds
    store: str
    source: np.ndarray | None = None
    source_geometry: object = None  # a Geometry, or None: the source is on the frames' grid
    every_frame_as: str | None = None  # "DIR/NAME.%04d.vti" (or .nrrd, .vol, .VOL)
    threads: int = 1  # numba threads per task: N workers x 1 thread use N cores without oversubscription


_INSTALLED: Payload | None = None


def install(payload: Payload) -> None:
    """A local pool worker's initializer: keep the payload for every task it runs."""
    global _INSTALLED
    _INSTALLED = payload


def occupied(zyx: np.ndarray, edge: int = CHUNK_EDGE) -> tuple[slice, slice, slice]:
    """The ``[z, y, x]`` slices holding every filled voxel of a frame, widened to whole
    ``edge``-voxel chunks (outside them the frame is zero)."""
    out = []
    for axis in range(3):
        filled = np.flatnonzero(np.any(zyx, axis=tuple(a for a in range(3) if a != axis)))
        if not len(filled):
            return (slice(0, 0),) * 3
        lo, hi = int(filled[0]) // edge * edge, int(filled[-1]) + 1
        out.append(slice(lo, hi))
    return tuple(out)


def frame_file(pattern: str, number: int) -> str:
    """``DIR/NAME.%04d.vti`` with the frame number filled in."""
    return pattern % number


def check_frame_pattern(pattern: str, option: str = "--every-frame-as",
                        suffixes: tuple[str, ...] = (".vti", ".nrrd", ".vol")) -> None:
    """Refuse (before any frame runs) a per-frame name that is not one %d field or names no volume format."""
    try:
        names = {pattern % 0, pattern % 1}
    except (TypeError, ValueError):
        names = set()
    if len(names) != 2:
        raise ValueError(f"{option} {pattern!r} needs one number field for the frame, e.g. "
                         f"frames/walk.%04d{suffixes[0]}")
    if not pattern.lower().endswith(suffixes):
        raise ValueError(f"{option} {pattern!r} must end in {', '.join(suffixes)}")


def reconstruct_frame(payload: Payload | None, index: int, spec: FrameSpec, grid: Bounds) -> dict:
    """Reconstruct ``spec`` in ``grid`` (its part of the shared grid: ``run.frame_grids``) into frame
    ``index`` of the store; returns its statistics."""
    from volanim_core.reconstruct.engine import reconstruct

    p = payload if payload is not None else _INSTALLED
    if p is None:
        raise RuntimeError("reconstruct_frame: no payload (the pool's initializer did not run)")
    t0 = time.perf_counter()
    tskel = spec.tskel(p.conn)
    r = reconstruct(tskel, mode=p.mode, source=p.source, source_geometry=p.source_geometry, kernel=p.kernel,
                    bounds=grid, threads=p.threads)  # neighbour lists: remembered per connectivity
    zyx = r.volume.T  # the engine's own [z, y, x] array: C-contiguous, no copy
    if spec.crumble:
        from .effects import fall, parse_axis

        floor = None if spec.floor is None else spec.floor - grid.lo[parse_axis(spec.down)[0]]  # world -> grid index
        zyx = np.ascontiguousarray(fall(r.volume, spec.crumble, spec.down, heap=spec.heap, floor=floor,
                                        drop=spec.drop).T)
        region = occupied(zyx)
        part = zyx[region]
        box = tight_bounds(zyx.T)
    else:  # the frame's grid, placed in the shared grid
        placed = Bounds(tuple(np.subtract(grid.lo, p.bounds.lo)), tuple(np.subtract(grid.hi, p.bounds.lo)))
        region = placed.slices()[::-1]
        part = zyx
        box = tight_bounds(r.volume)
    # shard ``index`` is this task's alone; only the chunks the body reaches are written (the shared
    # grid of a walk is mostly empty: writing all of it cost 3x the reconstruction)
    import zarr

    # zarr encodes chunks on as many threads as it may: give it the worker's cores, not the others' (its
    # default took 1.4 cores for a large frame's write; two workers then slowed each other by 10 %)
    with zarr.config.set({"async.concurrency": p.threads}):
        open_frames(p.store, "r+")[(index, *region)] = part
    if p.every_frame_as:
        from volanim_core import io

        whole = np.zeros(p.bounds.shape[::-1], part.dtype)  # per-frame files line up too: the shared grid
        whole[region] = part
        io.write_output(frame_file(p.every_frame_as, spec.number), whole.T, p.conn.geometry.shifted(p.bounds.lo),
                        p.mode)
    s = r.stats
    return frame_record(  # its checksum and the region it hashed: a reader verifies the frame
        index, spec.number, part, region, filled=int(s["filled"]),
        box=None if box is None else _in_grid(box, grid.lo), clipped=int(s.get("clipped", 0)),
        overdraw=round(float(s.get("overdraw", 0.0)), 3),  # voxel writes a filled voxel: the kernel's cost
        hotspot_max=int(s["hotspot_max"]) if "hotspot_max" in s else None,
        dt_scale=round(float(np.mean(spec.dt_scale)), 6), crumble=spec.crumble,
        seconds=round(time.perf_counter() - t0, 4), finished=round(time.time(), 4),
        worker=f"{socket.gethostname()}:{os.getpid()}",
        peak_rss=peak_rss())


def _in_grid(box, lo) -> list[list[int]]:
    """A frame's filled box (voxels of its own grid, whose corner is ``lo``) in the shared grid's voxel
    coordinates, as the store records it: what a render's camera frames (``render.run``)."""
    return [[int(a + b) for a, b in zip(box.lo, lo)], [int(a + b) for a, b in zip(box.hi, lo)]]


def reconstruct_frames(payload: Payload | None, work: list[tuple[int, FrameSpec, Bounds]]) -> list[dict]:
    """Several frames as one task, in order: a Dask task costs milliseconds of scheduling on the
    workers' own cores, as much as a small frame's reconstruction (``run.frames_per_task``)."""
    return [reconstruct_frame(payload, index, spec, grid) for index, spec, grid in work]
