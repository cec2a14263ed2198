"""Only what moved: a frame re-grown after a pose edit by redoing only the output slices the moved
spheres reach (#65). The studio's drag and the timeline call it frame after frame on one grid.

    LiveFrame(bounds, mode, source, ...)
      .update(tskel) --plan_frame (the fixed bounds)--> posed centres and radii
                     --compared with the last frame's--> the spheres that moved or changed radius
                     --their old and new z-extents--> the output slices to redo
                     --K.fill_slices, then sample_source (sampled) on those slices only--> Reconstruction

Why this is exact: the fill kernel's unit is a z-slice -- each slice is filled by one thread from
its first sphere to its last, with a stencil of its own -- so a slice's voxels depend only on the
spheres crossing it and their posed centres and radii. A slice that no changed sphere reaches,
before the edit or after it, has the same spheres at the same places and keeps its voxels; every
other slice is zeroed and filled again whole. Nothing depends on the bones: smooth joints' blended
spheres, which move with either bone, are found like any other (their centres changed).

The grid is fixed (``bounds``): a pose that carries a sphere out of it is clipped and counted, as
``reconstruct(bounds=...)`` does.
"""

from __future__ import annotations

import time

import numba
import numpy as np

from volanim_core.geometry import Geometry
from volanim_core.progress import Clock, Reporter
from volanim_core.reconstruct import _kernels as K
from volanim_core.reconstruct._clip_kernels import count_outside
from volanim_core.reconstruct.engine import (
    _MODE_CODE,
    CLIP_ROW_BUDGET,
    Reconstruction,
    _stats,
    source_maps,
)
from volanim_core.reconstruct.neighbours import sphere_neighbours
from volanim_core.reconstruct.plan import plan_frame
from volanim_core.reconstruct.sampling import sample_source
from volanim_core.rig.connectivity import Tskel
from volanim_core.volume import Bounds


class LiveFrame:
    """Frames of one connectivity on one grid, each after the last: :meth:`update` redoes the slices
    the changed spheres reach and returns what :func:`~volanim_core.reconstruct.engine.reconstruct`
    would for the same frame and ``bounds`` (voxel for voxel; the tests compare them).

    Parameters are ``reconstruct``'s; ``bounds`` is required (the grid every frame shares).
    """

    def __init__(self, bounds: Bounds, *, mode: str = "bone", source: np.ndarray | None = None,
                 source_geometry: Geometry | None = None, kernel: int = 1, value: int = 255,
                 threads: int | None = None, clock: Clock = time.perf_counter):
        self.bounds, self.mode, self.source, self.kernel, self.value = bounds, mode, source, kernel, value
        self.source_geometry, self.clock = source_geometry, clock
        self.threads = max(1, min(int(threads or numba.get_num_threads()), numba.config.NUMBA_NUM_THREADS))
        self._last = None  # (connectivity arrays, centres, r2s) of the frame the arrays hold
        self.redone = 0  # slices the last update filled: what it cost (all of them on a first frame)
        # the grid's z-slices the last update may have changed: (first, last), None (none) or "all" (a first frame)
        self.changed: tuple[int, int] | None | str = "all"

    def update(self, tskel: Tskel, *, progress=None, cancel=None, copy: bool = True) -> Reconstruction:
        """The frame ``tskel`` reconstructed on the fixed grid. ``copy=False`` returns a view of the live
        arrays: cheaper, but the next update overwrites it (draw it, then let it go)."""
        t0 = self.clock()
        report = Reporter(progress, cancel)
        same = self._last is not None and _same_spheres(self._last[0], tskel)
        if not same:  # the cut's lists, once per set of spheres (not looked up by a hash of them every frame)
            self._neighbours = sphere_neighbours(tskel)
        plan = plan_frame(tskel, self.mode, source=self.source, kernel=self.kernel, value=self.value,
                          bounds=self.bounds, neighbours=self._neighbours)
        nz, ny, nx = plan.shape
        if not same:
            self._allocate(plan)
            redo = np.ones(nz, bool)
        else:
            redo = _moved_slices(self._last[1], self._last[2], plan, nz)
        spans = _runs(redo)
        self.redone = int(redo.sum())
        self.changed = "all" if not same else ((int(spans[0][0]), int(spans[-1][1]) - 1) if spans else None)
        previous = numba.get_num_threads()
        numba.set_num_threads(self.threads)
        try:
            done = 0
            report(0, max(self.redone, 1))
            for z0, z1 in spans:
                self._redo(plan, z0, z1)
                done += z1 - z0
                report(done, max(self.redone, 1))
        except BaseException:
            self._last = None  # half-redone arrays: the next update starts afresh
            raise
        finally:
            numba.set_num_threads(previous)
        self._last = ((tskel.points, tskel.dt, tskel.bone, tskel.metric), plan.centres, plan.r2s)
        clipped, estimated = count_outside(plan.centres, plan.r2s, plan.radii, plan.metric, (nz, ny, nx),
                                           CLIP_ROW_BUDGET) if len(plan.radii) else (0.0, False)
        stats = _stats(len(plan.radii), self.filled, self.visits, int(round(clipped)),
                       self.volume if self.mode == "hotspot" else None)
        stats["clipped_estimated"] = bool(estimated)
        stats["redone_slices"] = self.redone
        stats["seconds"] = self.clock() - t0
        volume = self.volume.copy() if copy else self.volume
        volume = volume.transpose(2, 1, 0, 3) if volume.ndim == 4 else volume.T
        lo = plan.bounds.lo
        return Reconstruction(volume, tuple(int(v) for v in lo), stats, plan.tskel.geometry.shifted(lo))

    def _allocate(self, plan) -> None:
        nz, ny, nx = plan.shape
        self.owner = np.zeros((nz, ny, nx), plan.out_dtype)
        colour = self.mode == "sampled" and np.ndim(self.source) == 4
        shared = self.mode != "sampled" or (not colour and plan.final_dtype == plan.out_dtype)
        self.volume = self.owner if shared else np.zeros((nz, ny, nx, 3) if colour else (nz, ny, nx),
                                                         plan.final_dtype)
        self.scratch = np.empty((self.threads, ny, nx) if plan.relax else (self.threads, 1, 1), np.float32)
        self.row_lo = np.full((nz, ny) if plan.relax else (1, 1), nx, np.int32)
        self.row_hi = np.full(self.row_lo.shape, -1, np.int32)
        self.filled = np.zeros(nz, np.int64)
        self.visits = np.zeros(nz, np.int64)

    def _redo(self, plan, z0: int, z1: int) -> None:
        """Slices ``z0..z1`` zeroed and filled again (and sampled): each whole, as reconstruct fills it."""
        self.owner[z0:z1] = 0
        if plan.relax:
            self.row_lo[z0:z1] = plan.shape[2]
            self.row_hi[z0:z1] = -1
        K.fill_slices(self.owner, self.scratch, z0, z1, self.threads, plan.offsets, plan.ids, plan.centres, plan.r2s,
                      plan.radii, plan.values, plan.metric, _MODE_CODE[self.mode], plan.plane_start, plan.planes,
                      plan.max_planes, self.row_lo, self.row_hi, self.filled, self.visits, True, K.AHEAD, K.ROW_CUT_R2)
        if self.mode != "sampled":
            return
        slab = sample_source(self.owner[z0:z1], self.source, source_maps(plan, self.source_geometry, z0), self.kernel,
                             (self.row_lo[z0:z1], self.row_hi[z0:z1]), self.threads, z1 - z0, lambda done: None)
        if not np.shares_memory(slab, self.volume):  # colour, or a source of another dtype than the owners
            self.volume[z0:z1] = slab


def _same_spheres(last, tskel: Tskel) -> bool:
    """The frame's spheres are the last frame's (same points, radii, bones, metric, order): only poses differ."""
    points, dt, bone, metric = last
    return metric == tskel.metric and len(points) == len(tskel.points) and np.array_equal(points, tskel.points) \
        and np.array_equal(dt, tskel.dt) and np.array_equal(bone, tskel.bone)


def _moved_slices(centres: np.ndarray, r2s: np.ndarray, plan, nz: int) -> np.ndarray:
    """The slices any sphere whose posed centre or radius changed reaches, before or after (bool, nz)."""
    moved = np.flatnonzero((centres != plan.centres).any(axis=1) | (r2s != plan.r2s))
    redo = np.zeros(nz + 1, np.int64)
    for c, r2 in ((centres[moved], r2s[moved]), (plan.centres[moved], plan.r2s[moved])):
        # every slice with |z - cz| < r, and one more each side: more slices redone is always exact
        reach = np.sqrt(r2.astype(np.float64)) + 1.0
        lo = np.clip(np.floor(c[:, 2] - reach), 0, nz).astype(np.int64)
        hi = np.clip(np.ceil(c[:, 2] + reach) + 1, 0, nz).astype(np.int64)
        # counted with bincount: np.add.at took 10 ms of the frog's 70 ms update (#65)
        redo += np.bincount(lo, minlength=nz + 1) - np.bincount(hi, minlength=nz + 1)
    return np.cumsum(redo[:nz]) > 0


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """``[(start, stop), ...]`` of the True runs of a bool array."""
    edges = np.flatnonzero(np.diff(np.concatenate([[False], mask, [False]]).astype(np.int8)))
    return [(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2])]

