"""Reconstruction: re-grow a volume from a posed skeleton (``.tskel``).

    Tskel --posed_centres, radius_squared--> spheres in output-grid coordinates
          --grid_bounds (or given bounds)--> output grid + origin
          --slice_lists--> spheres per z-slice (file order)
          --fill_slices, z-chunks (progress, cancel)--> volume [x, y, z]

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
from dataclasses import dataclass, field

import numba
import numpy as np

from volanim_core.geometry import IDENTITY, Geometry
from volanim_core.limits import MAX_COORD, check_allocation
from volanim_core.modes import MODES
from volanim_core.progress import CancelFn, ProgressFn, Reporter
from volanim_core.reconstruct import _kernels as K
from volanim_core.reconstruct._clipped import count_outside
from volanim_core.reconstruct.neighbours import (
    CUT_MIN_RADIUS,
    cached_neighbours,
    check_neighbours,
    reorder_neighbours,
)
from volanim_core.reconstruct.radii import radius_squared
from volanim_core.reconstruct.sampling import sample_source
from volanim_core.reconstruct.speedups import ALL, Speedups
from volanim_core.rig.connectivity import Tskel
from volanim_core.rig.pose import apply_rows
from volanim_core.rig.skinning import transform_table
from volanim_core.volume import Bounds

#: Not a user's mode: bone mode's pass labelling each voxel with its owner's row of the transform table
#: (:func:`~volanim_core.rig.skinning.transform_table`; the bone + 1 with rigid joints). The breakage
#: report moves rest voxels by it.
OWNER = "owner"
_MODE_CODE = {"binary": K.BINARY, "mottled": K.MOTTLED, "bone": K.BONE, "sampled": K.SAMPLED, "hotspot": K.HOTSPOT,
              OWNER: K.BONE}
SNAP = 2.0**20
LAUNCH_SECONDS = 0.25  # aimed length of one parallel launch: the progress and cancel granularity
CLIP_ROW_BUDGET = 4_000_000  # rows counted exactly per clipped sphere (radius ~1000); beyond, estimated


@dataclass
class Reconstruction:
    """A reconstructed volume and what it took.

    Attributes
    ----------
    volume : (X, Y, Z) ndarray indexed ``[x, y, z]``
        uint8 (binary, mottled, bone with < 256 bones), uint16 (hotspot, bone
        with more bones) or the source's dtype (sampled).
    origin : (3,) ints
        Voxel ``[0, 0, 0]`` of ``volume`` is voxel ``origin`` of the rest frame.
    geometry : Geometry
        Where ``volume``'s voxels are in physical space: the frame's geometry shifted to ``origin``
        (what a writer records, so the posed frame overlays the scan it came from).
    stats : dict
        ``spheres``, ``filled`` (voxels), ``visits`` (voxels the spheres
        examined: the kernel's work), ``overdraw`` (visits / filled), ``clipped`` (sphere voxels outside
        given bounds), ``seconds``; hotspot adds ``hotspot_max`` and
        ``hotspot_mean`` (over covered voxels).
    """

    volume: np.ndarray
    origin: tuple[int, int, int]
    stats: dict = field(default_factory=dict)
    geometry: Geometry = IDENTITY

    @property
    def bounds(self) -> Bounds:
        lo = tuple(int(v) for v in self.origin)
        return Bounds(lo, tuple(lo[i] + self.volume.shape[i] - 1 for i in range(3)))


def check_matrices(tskel: Tskel) -> np.ndarray:
    """Inverse of every bone matrix; a matrix that is not a finite, invertible affine map
    (row-vector convention: last column 0 0 0 1) is a ValueError naming the bone and what is wrong."""
    mats = np.asarray(tskel.matrices)
    if mats.shape != (len(tskel.bones), 4, 4):
        raise ValueError(f"expected one 4x4 matrix per bone ({len(tskel.bones)}), got shape {mats.shape}")
    inv = np.empty(mats.shape, np.float64)
    for b, m in enumerate(mats):
        name = f"bone {b} ({tskel.bones[b].label})"
        if not np.isfinite(m).all():
            raise ValueError(f"{name}: its matrix holds NaN or infinite values")
        if not np.allclose(m[:, 3], (0, 0, 0, 1), atol=1e-6):
            raise ValueError(f"{name}: its matrix is not affine (last column {m[:, 3].tolist()}, expected "
                             "0 0 0 1: row-vector convention, translation in row 4)")
        det = np.linalg.det(m[:3, :3])
        if abs(det) < 1e-9:
            raise ValueError(f"{name}: its matrix is singular (determinant {det:.3g}); "
                             "it cannot be inverted to sample the source")
        inv[b] = np.linalg.inv(m)
    return inv


def check_frame(tskel: Tskel) -> None:
    """Refuse points a reconstruction cannot place: NaN/infinite values, negative radii,
    and spheres that reach beyond ``MAX_COORD`` voxels."""
    pts, dt = np.ascontiguousarray(tskel.points, np.float64), np.ascontiguousarray(tskel.dt, np.float64)
    if K.spheres_fit(pts, dt, MAX_COORD):
        return
    finite = np.isfinite(pts)
    bad = ~(finite[:, 0] & finite[:, 1] & finite[:, 2]) | ~np.isfinite(dt) | (dt < 0)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"point {i} ({pts[i].tolist()}, dt {dt[i]}) has a NaN, infinite or negative value")
    check_reach(pts, dt, "")


def check_reach(centres: np.ndarray, extents: np.ndarray, where: str) -> None:
    """Every sphere (centre +- extent) must lie within ``MAX_COORD`` voxels of the origin."""
    if not len(centres) or K.spheres_fit(np.ascontiguousarray(centres, np.float64),
                                         np.ascontiguousarray(extents, np.float64), MAX_COORD):
        return
    a = np.abs(centres)
    reach = np.maximum(np.maximum(a[:, 0], a[:, 1]), a[:, 2]) + extents  # not .max(axis=1): 20x slower on (N, 3)
    if not np.isfinite(reach).all() or reach.max() > MAX_COORD:
        i = int(np.argmax(np.where(np.isfinite(reach), reach, np.inf)))
        raise ValueError(f"point {i}{where} at {np.round(centres[i], 3).tolist()} with radius {extents[i]:g} "
                         f"reaches {reach[i]:.3g} voxels from the origin; coordinates and radii must stay "
                         f"within {MAX_COORD:,}")


def check_output_grid(shape, bytes_per_voxel: int) -> None:
    """Refuse an output grid that cannot be allocated, stating its size."""
    check_allocation(shape, bytes_per_voxel, "the output grid", "give smaller --bounds or check the radii")


def posed_centres(tskel: Tskel, transforms: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
    """Each point's centre moved by its bone's matrix, ``[x y z 1] @ M`` (snapped; 345: rounded); with
    smooth joints, a point in a blend zone by its blended matrix.

    In the 3-4-5 metric the posed centre is rounded to the nearest voxel
    (half-way rounds up), as docs/formats.md says. ``transforms``: the frame's
    :func:`~volanim_core.rig.skinning.transform_table`, when the caller has it.
    """
    if len(tskel) == 0:
        return np.zeros((0, 3))
    table, row = transform_table(tskel) if transforms is None else transforms
    c = apply_rows(tskel.points, row, table, len(tskel.bones))
    # floor(c * SNAP + 0.5) / SNAP, in place: no temporaries of the frog's 3.3 MB each
    c *= SNAP
    c += 0.5
    np.floor(c, out=c)
    c /= SNAP
    if tskel.metric == "345":
        c += 0.5
        np.floor(c, out=c)
    return c


def file_ordered(tskel: Tskel) -> tuple[Tskel, np.ndarray | None]:
    """Points grouped by bone in root order (stable), the order a ``.tskel`` file lists them,
    and the permutation applied (None when the frame already was).

    Ties go to the sphere first in file order, so a frame built in memory must
    reconstruct exactly like the same frame written out and read back.
    """
    if tskel.is_grouped():
        return tskel, None
    order = np.argsort(tskel.bone, kind="stable")
    return tskel.take(order), order


def _extent(tskel: Tskel) -> np.ndarray:
    """Half-size of each sphere's bounding box: dt (Euclid) or dt / 3 (345: 3a <= distance)."""
    return tskel.dt / 3.0 if tskel.metric == "345" else tskel.dt


def grid_bounds(tskels: Tskel | list[Tskel], padding: int = 2, *, centres: list | None = None) -> Bounds:
    """Inclusive bounds of the posed spheres of one or several frames, plus ``padding`` (tskelbounds).

    ``centres``: the frames' :func:`posed_centres`, when the caller has them already.
    """
    frames = [tskels] if isinstance(tskels, Tskel) else list(tskels)
    los, his = [], []
    for k, t in enumerate(frames):
        if len(t):
            c, e = (posed_centres(t) if centres is None else centres[k]), _extent(t)
            check_reach(c, e, " once posed")  # else the int conversion below wraps silently
            lo, hi = K.sphere_box(np.ascontiguousarray(c, np.float64), np.ascontiguousarray(e, np.float64))
            los.append(lo)
            his.append(hi)
    if not los:
        raise ValueError("no points to bound: every frame is empty")
    lo = np.floor(np.min(los, axis=0)).astype(int) - padding
    hi = np.ceil(np.max(his, axis=0)).astype(int) + padding
    return Bounds(tuple(int(v) for v in lo), tuple(int(v) for v in hi))


def mottled_values(n: int) -> np.ndarray:
    """One value 1..255 per sphere, neighbours in file order far apart (uint8)."""
    return (1 + (np.arange(n, dtype=np.int64) * 97) % 255).astype(np.uint8)


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
) -> Reconstruction:
    """Re-grow a volume from the spheres of a ``.tskel`` frame.

    Parameters
    ----------
    tskel : Tskel
        Points with their bone's matrix (rest voxel coordinates -> posed).
    mode : {'binary', 'mottled', 'bone', 'sampled', 'hotspot'}
    source : (X, Y, Z) ndarray indexed ``[x, y, z]``, required for 'sampled'
        The rest-pose volume; positions outside it read 0. A colour source
        ``(X, Y, Z, 3)`` uint8 gives a colour result (:mod:`.sampling`).
    source_geometry : Geometry, optional
        Where the source's voxels are: each output voxel samples the source at the same physical
        point as its rest position in the frame's grid (``tskel.geometry``). None: the source is
        on the frame's own grid. :func:`check_source_overlap` refuses a source the frame misses.
    kernel : {1, 3, 5}
        Sampled mode: nearest voxel (1) or a Gaussian-weighted average over
        a 3^3 / 5^3 neighbourhood (anti-aliasing; leave 1 for label volumes).
    bounds : Bounds, optional
        Inclusive output bounds in the posed frame; spheres outside are
        clipped and counted. Default: the posed spheres plus ``padding``.
    value : int
        Binary mode's value.
    threads : int, optional
        numba threads (default: all cores). The result does not depend on it.
    neighbours : (N, k) int ndarray, optional
        :func:`sphere_neighbours` of this connectivity (made once per connectivity and remembered when not
        given); lets each sphere skip voxels a larger neighbour provably wins.
        The result does not depend on it; ``speedups=Speedups(cut=False)`` turns the cut off.
    out : ndarray, optional
        A previous result's ``volume`` of the same grid and dtype to overwrite
        (saves the first-touch cost of a fresh array; the studio's live preview).
    progress, cancel : callables, optional
        ``progress(done, total)`` in output slices; ``cancel() -> True``
        raises :class:`~volanim_core.errors.Cancelled`.
    speedups : Speedups
        Optimisations to switch off, to measure them (:mod:`.speedups`); the result does not depend on it.

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
    _check_arguments(mode, kernel, source, value)
    t0 = time.perf_counter()
    report = Reporter(progress, cancel)
    minv_rest = check_matrices(tskel)
    check_frame(tskel)
    if neighbours is not None:
        check_neighbours(neighbours, len(tskel))
    tskel, order = file_ordered(tskel)
    table, rows = transform_table(tskel)
    posed = posed_centres(tskel, (table, rows))
    own_bounds = bounds is None
    if own_bounds:  # grid_bounds checks the posed reach itself
        bounds = grid_bounds(tskel, padding, centres=[posed]) if len(tskel) else Bounds((0, 0, 0), (0, 0, 0))
    else:
        check_reach(posed, _extent(tskel), " once posed")
    if min(bounds.shape) < 1:
        raise ValueError(f"empty output bounds {bounds.lo}..{bounds.hi}: each upper bound must be >= its lower bound")
    origin = np.asarray(bounds.lo, np.float64)
    nx, ny, nz = bounds.shape
    centres = np.ascontiguousarray(posed - origin)
    r2s = radius_squared(tskel.dt)
    radii = np.ascontiguousarray(tskel.dt, np.float64)
    metric = K.CHAMFER if tskel.metric == "345" else K.EUCLID
    out_dtype, values = _sphere_values(mode, tskel, value, rows, len(table))
    final_dtype = source.dtype if mode == "sampled" else out_dtype
    relax = mode not in ("hotspot", "binary")  # binary is a union and hotspot a count: no stencil
    per_voxel = np.dtype(out_dtype).itemsize + \
        (np.dtype(final_dtype).itemsize if final_dtype != out_dtype else 0) + (3 if np.ndim(source) == 4 else 0)
    check_output_grid(bounds.shape, per_voxel)
    nthreads = int(threads or numba.config.NUMBA_NUM_THREADS)
    nthreads = max(1, min(nthreads, numba.config.NUMBA_NUM_THREADS))
    out = _output_array(out, (nz, ny, nx), out_dtype, final_dtype)
    # one slice of stencil per thread: a slice is filled by one thread, start to end
    scratch = np.empty((nthreads, ny, nx) if relax else (nthreads, 1, 1), np.float32)
    row_lo = np.full((nz, ny) if relax else (1, 1), nx, np.int32)  # each row's span of written output
    row_hi = np.full(row_lo.shape, -1, np.int32)
    if metric == K.EUCLID and mode != "hotspot" and speedups.cut and len(tskel):
        nbrs = cached_neighbours(tskel, min_radius=CUT_MIN_RADIUS, r2=r2s) if neighbours is None \
            else reorder_neighbours(neighbours, order)
        plane_start, planes = K.build_halfspaces(centres, r2s, nbrs, CUT_MIN_RADIUS**2)
    else:
        plane_start, planes = np.zeros(len(tskel) + 1, np.int64), np.zeros((0, 5))
    max_planes = max(1, int(np.diff(plane_start).max())) if len(tskel) else 1
    # Euclid: the slices with |z - cz| < r + 1e-7 (one slice in from floor/ceil at each end): the kernel
    # tests each exactly, and one farther out has dz^2 > r2 by far more than rounding (listing two more a
    # sphere, as floor/ceil of cz -+ r did, cost the frog 275 k sphere-slice visits that only loaded the
    # sphere to skip it). 345: a margin of 1 beyond floor/ceil.
    reach, inward = (np.sqrt(r2s) + 1e-7, 1) if metric == K.EUCLID else (_extent(tskel), -1)
    zlo = np.floor(centres[:, 2] - reach).astype(np.int64) + inward
    zhi = np.ceil(centres[:, 2] + reach).astype(np.int64) - inward
    offsets, ids = K.slice_lists(zlo, zhi, nz)
    filled = np.zeros(nz, np.int64)
    visits = np.zeros(nz, np.int64)

    previous = numba.get_num_threads()
    numba.set_num_threads(nthreads)
    try:
        total = 2 * nz if mode == "sampled" else nz  # sampling is a second pass: report and cancel in it too
        report(0, total)
        z0, chunk = 0, max(nthreads * 8, nz // 16)  # a first, small launch measures the pace ...
        while z0 < nz:
            z1 = min(nz, z0 + chunk)
            started = time.perf_counter()
            K.fill_slices(out, scratch, z0, z1, nthreads, offsets, ids, centres, r2s, radii, values, metric,
                          _MODE_CODE[mode], plane_start, planes, max_planes, row_lo, row_hi, filled, visits,
                          speedups.box_sweep, K.AHEAD if speedups.prefetch else 0)
            report(z1, total)
            # ... and the next ones last about LAUNCH_SECONDS each: progress and cancel stay that responsive,
            # and a fast call is not cut into many launches (each ends on its slowest thread)
            pace = (z1 - z0) / max(time.perf_counter() - started, 1e-6)
            z0, chunk = z1, max(nthreads * 4, int(pace * LAUNCH_SECONDS))
        if mode == "sampled":
            to_source = np.eye(4) if source_geometry is None else tskel.geometry.index_map(source_geometry)
            minv = np.concatenate([minv_rest, np.linalg.inv(table[len(minv_rest):])])  # blended: rigid, invertible
            out = sample_source(out, source, _grid_to_source(minv, origin, to_source), kernel,
                                (row_lo, row_hi), nthreads, chunk, lambda done: report(nz + done, total))
    finally:
        numba.set_num_threads(previous)

    # nothing can stick out of the grid this call sized to fit every sphere
    fits = own_bounds and padding >= 0
    clipped, estimated = count_outside(centres, r2s, radii, metric, (nz, ny, nx), CLIP_ROW_BUDGET) \
        if len(tskel) and not fits else (0.0, False)
    stats = _stats(len(tskel), filled, visits, int(round(clipped)), out if mode == "hotspot" else None)
    stats["clipped_estimated"] = bool(estimated)
    stats["seconds"] = time.perf_counter() - t0
    volume = out.transpose(2, 1, 0, 3) if out.ndim == 4 else out.T  # [x, y, z] view: no copy
    return Reconstruction(volume, tuple(int(v) for v in bounds.lo), stats, tskel.geometry.shifted(bounds.lo))


def _check_arguments(mode, kernel, source, value) -> None:
    if mode not in MODES and mode != OWNER:
        raise ValueError(f"mode must be one of {', '.join(MODES)}, got {mode!r}")
    if kernel not in (1, 3, 5):
        raise ValueError(f"kernel must be 1, 3 or 5, got {kernel!r}")
    if mode == "binary" and not 0 < value <= 255:
        raise ValueError(f"binary value must be 1..255, got {value}")
    if mode == "sampled":
        if source is None:
            raise ValueError("sampled mode needs the source volume (source=...)")
        colour = np.ndim(source) == 4 and np.shape(source)[3] == 3
        if np.ndim(source) != 3 and not colour:
            raise ValueError(f"source must be a 3-D volume (or 3-D RGB, [x, y, z, 3]), got shape {np.shape(source)}")
        if colour and np.asarray(source).dtype != np.uint8:
            raise ValueError(f"a colour source holds 8-bit RGB, got {np.asarray(source).dtype}")
        kind = np.asarray(source).dtype.kind
        if kind not in "buif":
            raise ValueError(f"source voxels must be numbers (bool, integer or float), got {np.asarray(source).dtype}")


def output_dtype(mode: str, n_bones: int, source_dtype=None) -> np.dtype:
    """The dtype :func:`reconstruct` returns for ``mode`` (a sequence's store is made before any frame)."""
    if mode == "sampled":
        return np.dtype(source_dtype)
    if mode == "hotspot":
        return np.dtype(np.uint16)
    if mode == "bone":
        return np.dtype(np.uint8 if n_bones < 256 else np.uint16 if n_bones < 65536 else np.uint32)
    return np.dtype(np.uint8)


def _sphere_values(mode: str, tskel: Tskel, value: int, rows: np.ndarray, n_rows: int) -> tuple[type, np.ndarray]:
    """The kernel's output dtype and the value each sphere writes.

    Sampled relaxes like the owner pass (each sphere writes its row of the transform table + 1: its
    bone + 1 with rigid joints) and then samples (``K.sample_rows``); hotspot counts, so its values
    are unused.
    """
    if mode in ("sampled", OWNER):
        dtype = output_dtype("bone", n_rows).type
        return dtype, (rows + 1).astype(dtype)
    dtype = output_dtype(mode, len(tskel.bones)).type
    if mode == "hotspot":
        return dtype, np.zeros(len(tskel), dtype)
    if mode == "bone":
        return dtype, (tskel.bone + 1).astype(dtype)
    if mode == "mottled":
        return dtype, mottled_values(len(tskel))
    return dtype, np.full(len(tskel), value, dtype)


def _output_array(out, shape_zyx, out_dtype, final_dtype) -> np.ndarray:
    """A zeroed ``[z, y, x]`` array: the caller's previous result when it fits (no first-touch cost)."""
    if out is not None and out.shape == shape_zyx[::-1] and out.dtype == final_dtype == out_dtype \
            and out.T.flags.c_contiguous:
        out = out.T  # the [z, y, x] view of a previous [x, y, z] result
        out.fill(0)
        return out
    return np.zeros(shape_zyx, out_dtype)


def _grid_to_source(minv_rest: np.ndarray, origin: np.ndarray, to_source: np.ndarray) -> np.ndarray:
    """Per bone: output-grid coordinates -> source-array coordinates (shift in, invert, then the
    frame's grid -> the source's grid, :meth:`Geometry.index_map`)."""
    shift_in = np.eye(4)
    shift_in[3, :3] = origin
    return np.ascontiguousarray(shift_in @ minv_rest @ to_source)


def _stats(spheres: int, filled: np.ndarray, visits: np.ndarray, clipped: int, hotspot=None) -> dict:
    n_filled, n_visits = int(filled.sum()), int(visits.sum())
    stats = {"spheres": spheres, "filled": n_filled, "visits": n_visits,
             "overdraw": float(n_visits / n_filled) if n_filled else 0.0, "clipped": clipped}
    if hotspot is not None:
        stats["hotspot_max"] = int(hotspot.max()) if hotspot.size else 0
        stats["hotspot_mean"] = float(n_visits / n_filled) if n_filled else 0.0
    return stats
