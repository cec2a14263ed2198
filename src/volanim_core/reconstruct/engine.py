"""Reconstruction: re-grow a volume from a posed skeleton (``.tskel``).

    Tskel --plan_frame (plan.py: checks, posed centres, output grid, slice lists, the cut)--> FramePlan
          --K.fill_slices, z-chunks of ~LAUNCH_SECONDS (progress, cancel)--> volume [z, y, x]
          --sample_source (sampled mode), count_outside (given bounds)--> Reconstruction [x, y, z]

Semantics (docs/formats.md, "Reconstruction semantics"), with the two numerical
details the original contract left open pinned down here and in the oracle alike
(docs/formats.md#reconstruction records them):

* a posed centre is snapped to a 2^-20 voxel grid (kills ~1e-15 noise from
  rotation matrices, so a 90-degree turn lands exactly on voxels);
* ``dt`` values are square roots of integers written to float precision, so
  ``dt**2`` within 1e-9 (relative) of an integer is taken as that integer:
  otherwise the float nearest ``sqrt(2)`` would let a voxel exactly
  ``sqrt(2)`` away -- a background voxel -- into the strict ``|q - c| < dt``.

Ties in distance go to the sphere first in file order; distances are compared
as float32 (squared Euclidean, or integer 3-4-5 chamfer).
"""

from __future__ import annotations

import time

import numba
import numpy as np

from volanim_core.geometry import Geometry
from volanim_core.progress import CancelFn, Clock, Pacer, ProgressFn, Reporter
from volanim_core.reconstruct import _kernels as K
from volanim_core.reconstruct._clip_kernels import count_outside

# the plan's checks and geometry are this module's API too (callers import them from here)
from volanim_core.reconstruct.plan import (  # noqa: F401
    LAUNCH_SECONDS,
    MODES,
    OWNER,
    SNAP,
    check_frame,
    check_matrices,
    check_output_grid,
    check_reach,
    file_ordered,
    grid_bounds,
    mottled_values,
    output_dtype,
    plan_frame,
    posed_centres,
)
from volanim_core.reconstruct.result import Reconstruction  # noqa: F401  (this module's API too)
from volanim_core.reconstruct.sampling import grid_to_source, sample_source
from volanim_core.reconstruct.speedups import ALL, Speedups
from volanim_core.rig.connectivity import Tskel
from volanim_core.volume import Bounds

_MODE_CODE = {"binary": K.BINARY, "mottled": K.MOTTLED, "bone": K.BONE, "sampled": K.SAMPLED, "hotspot": K.HOTSPOT,
              OWNER: K.BONE}
CLIP_ROW_BUDGET = 4_000_000  # rows counted exactly per clipped sphere (radius ~1000); beyond, estimated


def reconstruct(
    tskel: Tskel,
    *,
    mode: str = "binary",
    source: np.ndarray | None = None,
    source_geometry: Geometry | None = None,
    kernel: int = 1,
    bounds: Bounds | None = None,
    padding: int = 2,
    value: int = 255,
    threads: int | None = None,
    neighbours: np.ndarray | None = None,
    out: np.ndarray | None = None,
    progress: ProgressFn | None = None,
    cancel: CancelFn | None = None,
    speedups: Speedups = ALL,
    clock: Clock = time.perf_counter,
    method: str = "auto",
) -> Reconstruction:
    """Re-grow a volume from the spheres of a ``.tskel`` frame, or move the rig's owned voxels.

    A rigid frame posed from a connectivity with an ownership (``tskel.ownership``, rig/ownership.py) is
    made by :func:`~volanim_core.reconstruct.owned.reconstruct_owned` unless ``method='spheres'``: every
    rest voxel moved by the bone that owns it, joints closed by balls (the default, #84). Smooth joints
    and frames without an ownership re-grow the thesis's spheres.

    Parameters
    ----------
    tskel : Tskel
        Points with their bone's matrix (rest voxel coordinates -> posed).
    mode : {'binary', 'mottled', 'bone', 'sampled', 'hotspot'}
    source : (X, Y, Z) ndarray indexed ``[x, y, z]``, required for 'sampled'
        The rest-pose volume; positions outside it read 0. A colour source
        ``(X, Y, Z, 3)`` uint8 gives a colour result (``volanim_core.reconstruct.sampling``).
    source_geometry : Geometry, optional
        Where the source's voxels are: each output voxel samples the source at the same physical
        point as its rest position in the frame's grid (``tskel.geometry``). None: the source is
        on the frame's own grid. ``check_source_overlap`` refuses a source the frame misses.
    kernel : {1, 3, 5}
        Sampled mode: nearest voxel (1) or a Gaussian-weighted average over
        a 3^3 / 5^3 neighbourhood (anti-aliasing; leave 1 for label volumes).
    bounds : Bounds, optional
        Inclusive output bounds in the posed frame; spheres outside are
        clipped and counted. Default: the posed spheres plus ``padding``.
    value : int
        Binary mode's value.
    threads : int, optional
        numba threads (default: the calling thread's numba setting, all cores unless it was set: the studio's
        live thread keeps a core for the window). The result does not depend on it.
    neighbours : (N, k) int ndarray, optional
        ``sphere_neighbours`` of this connectivity (made once per connectivity and remembered when not
        given); lets each sphere skip voxels a larger neighbour provably wins.
        The result does not depend on it; ``speedups=Speedups(cut=False)`` turns the cut off.
    out : ndarray, optional
        A previous result's ``volume`` of the same grid and dtype to overwrite
        (saves the first-touch cost of a fresh array; the studio's live preview).
    progress, cancel : callables, optional
        ``progress(done, total)`` in output slices; ``cancel() -> True``
        raises :class:`~volanim_core.errors.Cancelled`.
    speedups : Speedups
        Optimisations to switch off, to measure them (``volanim_core.reconstruct.speedups``); the result does not
        depend on it.
    clock : callable
        Seconds (``time.perf_counter``): sizes the launches (:class:`~volanim_core.progress.Pacer`) and
        times the call (``stats['seconds']``). The result does not depend on it; a test passes a fake one.
    method : {'auto', 'owned', 'spheres'}
        'auto': owned when the frame carries an ownership and its joints are rigid, else spheres.

    Returns
    -------
    Reconstruction

    Examples
    --------
    >>> import numpy as np
    >>> from volanim_core.rig.connectivity import BoneSegment, Tskel
    >>> t = Tskel([BoneSegment((0, 0, 0), (1, 0, 0))], np.eye(4)[None], [[5, 5, 5]], [2.0], None, [0])
    >>> r = reconstruct(t, padding=0)
    >>> int((r.volume > 0).sum()), r.origin   # voxels strictly within 2 of the centre: 3x3x3
    (27, (3, 3, 3))
    """
    if moves_owned(tskel, method):
        from volanim_core.reconstruct.owned import reconstruct_owned

        own = tskel.ownership  # a coarse frame's is pooled (Ownership.coarse): its rest voxels are every f-th
        return reconstruct_owned(own, own.rest_matrices(tskel.matrices), mode="bone" if mode == OWNER else mode,
                                 source=source, source_geometry=source_geometry, kernel=kernel, bounds=bounds,
                                 padding=padding, value=value, threads=threads, progress=progress, cancel=cancel,
                                 clock=clock)
    t0 = clock()
    report = Reporter(progress, cancel)
    plan = plan_frame(tskel, mode, source=source, kernel=kernel, value=value, bounds=bounds, padding=padding,
                      neighbours=neighbours, speedups=speedups)
    nz, ny, nx = plan.shape
    nthreads = int(threads or numba.get_num_threads())
    nthreads = max(1, min(nthreads, numba.config.NUMBA_NUM_THREADS))
    out = _output_array(out, (nz, ny, nx), plan.out_dtype, plan.final_dtype)
    # one slice of stencil per thread: a slice is filled by one thread, start to end
    scratch = np.empty((nthreads, ny, nx) if plan.relax else (nthreads, 1, 1), np.float32)
    row_lo = np.full((nz, ny) if plan.relax else (1, 1), nx, np.int32)  # each row's span of written output
    row_hi = np.full(row_lo.shape, -1, np.int32)
    filled = np.zeros(nz, np.int64)
    visits = np.zeros(nz, np.int64)

    previous = numba.get_num_threads()
    numba.set_num_threads(nthreads)
    try:
        total = 2 * nz if mode == "sampled" else nz  # sampling is a second pass: report and cancel in it too
        report(0, total)
        # a first, small launch measures the pace; the next ones last about LAUNCH_SECONDS each
        pacer = Pacer(first=max(nthreads * 8, nz // 16), least=nthreads * 4, seconds=LAUNCH_SECONDS, clock=clock)
        for z0, z1 in pacer.spans(nz):
            K.fill_slices(out, scratch, z0, z1, nthreads, plan.offsets, plan.ids, plan.centres, plan.r2s, plan.radii,
                          plan.values, plan.metric, _MODE_CODE[mode], plan.plane_start, plan.planes, plan.max_planes,
                          row_lo, row_hi, filled, visits, speedups.box_sweep, K.AHEAD if speedups.prefetch else 0,
                          K.ROW_CUT_R2)
            report(z1, total)
        if mode == "sampled":
            out = sample_source(out, source, source_maps(plan, source_geometry), kernel,
                                (row_lo, row_hi), nthreads, pacer.size, lambda done: report(nz + done, total))
    finally:
        numba.set_num_threads(previous)

    # nothing can stick out of the grid this call sized to fit every sphere
    fits = plan.own_bounds and padding >= 0
    clipped, estimated = count_outside(plan.centres, plan.r2s, plan.radii, plan.metric, (nz, ny, nx),
                                       CLIP_ROW_BUDGET) if len(tskel) and not fits else (0.0, False)
    stats = _stats(len(tskel), filled, visits, int(round(clipped)), out if mode == "hotspot" else None)
    stats["clipped_estimated"] = bool(estimated)
    stats["seconds"] = clock() - t0
    volume = out.transpose(2, 1, 0, 3) if out.ndim == 4 else out.T  # [x, y, z] view: no copy
    lo = plan.bounds.lo
    return Reconstruction(volume, tuple(int(v) for v in lo), stats, plan.tskel.geometry.shifted(lo))


def moves_owned(tskel: Tskel, method: str) -> bool:
    """Whether this frame is made from its rig's ownership (see :func:`reconstruct`)."""
    if method not in ("auto", "owned", "spheres"):
        raise ValueError(f"method must be 'auto', 'owned' or 'spheres', got {method!r}")
    own = getattr(tskel, "ownership", None)
    if method == "owned" and (own is None or tskel.joints.smooth):
        raise ValueError("method 'owned' needs a rigid frame of a rig with an ownership (volanim connect makes "
                         "NAME.owners.nrrd beside the .connect)")
    return method != "spheres" and own is not None and not tskel.joints.smooth


def _output_array(out, shape_zyx, out_dtype, final_dtype) -> np.ndarray:
    """A zeroed ``[z, y, x]`` array: the caller's previous result when it fits (no first-touch cost)."""
    if out is not None and out.shape == shape_zyx[::-1] and out.dtype == final_dtype == out_dtype \
            and out.T.flags.c_contiguous:
        out = out.T  # the [z, y, x] view of a previous [x, y, z] result
        out.fill(0)
        return out
    return np.zeros(shape_zyx, out_dtype)


def source_maps(plan, source_geometry: Geometry | None, z0: int = 0) -> np.ndarray:
    """Sampled mode's maps, one per row of the plan's transform table: voxels of the output grid's slab
    that starts at slice ``z0`` -> source-array coordinates (a smooth joint's blended row is inverted as a
    rigid map)."""
    to_source = np.eye(4) if source_geometry is None else plan.tskel.geometry.index_map(source_geometry)
    minv = np.concatenate([plan.minv_rest, np.linalg.inv(plan.table[len(plan.minv_rest):])])
    return grid_to_source(minv, plan.origin + np.array([0.0, 0.0, z0]), to_source)


def _stats(spheres: int, filled: np.ndarray, visits: np.ndarray, clipped: int, hotspot=None) -> dict:
    n_filled, n_visits = int(filled.sum()), int(visits.sum())
    stats = {"spheres": spheres, "filled": n_filled, "visits": n_visits,
             "overdraw": float(n_visits / n_filled) if n_filled else 0.0, "clipped": clipped}
    if hotspot is not None:
        stats["hotspot_max"] = int(hotspot.max()) if hotspot.size else 0
        stats["hotspot_mean"] = float(n_visits / n_filled) if n_filled else 0.0
    return stats
