"""A frame's reconstruction plan: everything the fill kernel reads, checked and made before it runs.

    Tskel, mode, bounds | padding --check_matrices, check_frame--> inverse bone matrices
      --file_ordered--> points grouped by bone (ties go to the first in file order)
      --transform_table, posed_centres--> posed centres (snapped; smooth joints: blended)
      --posed_radii--> the radii (smooth joints: a stretched medial sheet's spheres thin)
      --grid_bounds (or the given bounds, check_reach)--> the output grid
      --_sphere_values--> what each sphere writes, the output dtypes
      --cached_neighbours, P.build_halfspaces--> the overdraw cut's planes (Euclid, big spheres)
      --P.slice_lists--> the spheres each z slice visits
      --> FramePlan (engine.reconstruct runs it)

Why a plan: the kernel takes some twenty arrays; made here under names, once, they are
checked in one place, and :func:`~volanim_core.reconstruct.engine.reconstruct` reads as
what it does (plan, fill in timed launches, sample, count).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from volanim_core.limits import MAX_COORD, check_allocation
from volanim_core.modes import MODES
from volanim_core.reconstruct import _kernels as K
from volanim_core.reconstruct import _plan_kernels as P
from volanim_core.reconstruct.neighbours import CUT_MIN_RADIUS, cached_neighbours, check_neighbours, reorder_neighbours
from volanim_core.reconstruct.radii import radius_squared
from volanim_core.reconstruct.speedups import ALL, Speedups
from volanim_core.rig.connectivity import Tskel
from volanim_core.rig.pose import apply_rows
from volanim_core.rig.skinning import posed_radii, transform_table
from volanim_core.volume import Bounds

#: Not a user's mode: bone mode's pass labelling each voxel with its owner's row of the transform table
#: (:func:`~volanim_core.rig.skinning.transform_table`; the bone + 1 with rigid joints). The breakage
#: report moves rest voxels by it.
OWNER = "owner"
SNAP = 2.0**20

LAUNCH_SECONDS = 0.25  # aimed length of one parallel launch: the progress and cancel granularity


@dataclass
class FramePlan:
    """One frame ready for the fill kernel. Arrays are C-contiguous; coordinates are the output grid's."""

    tskel: Tskel  # points grouped by bone, in file order
    minv_rest: np.ndarray  # (B, 4, 4) inverse bone matrices
    table: np.ndarray  # the transform table: bone matrices, then smooth joints' blended ones
    bounds: Bounds  # the output grid, inclusive, in the posed frame
    own_bounds: bool  # sized here to fit every sphere (nothing is clipped)
    centres: np.ndarray  # (N, 3) posed centres minus the grid's origin
    r2s: np.ndarray  # squared radii (float32, integers snapped)
    radii: np.ndarray  # radii (float64)
    metric: int  # K.EUCLID or K.CHAMFER
    values: np.ndarray  # what each sphere writes
    out_dtype: np.dtype  # the kernel's output
    final_dtype: np.dtype  # the result's (sampled: the source's)
    relax: bool  # the kernel keeps a distance stencil (every mode but binary and hotspot)
    plane_start: np.ndarray  # the overdraw cut: sphere i's half-spaces are planes[plane_start[i]:plane_start[i+1]]
    planes: np.ndarray
    max_planes: int
    offsets: np.ndarray  # slice z visits ids[offsets[z]:offsets[z+1]]
    ids: np.ndarray

    @property
    def shape(self) -> tuple[int, int, int]:
        """The output grid's ``(nz, ny, nx)``: the kernel writes ``[z, y, x]``."""
        nx, ny, nz = self.bounds.shape
        return nz, ny, nx

    @property
    def origin(self) -> np.ndarray:
        return np.asarray(self.bounds.lo, np.float64)


def plan_frame(tskel: Tskel, mode: str, *, source=None, kernel: int = 1, value: int = 255,
               bounds: Bounds | None = None, padding: int = 2, neighbours: np.ndarray | None = None,
               speedups: Speedups = ALL) -> FramePlan:
    """Check a frame and make its :class:`FramePlan` (:func:`~volanim_core.reconstruct.engine.reconstruct`'s
    arguments of the same names); every refusal is a ValueError saying what is wrong."""
    _check_arguments(mode, kernel, source, value)
    minv_rest = check_matrices(tskel)
    check_frame(tskel)
    if neighbours is not None:
        check_neighbours(neighbours, len(tskel))
    tskel, order = file_ordered(tskel)
    table, rows = transform_table(tskel)
    posed = posed_centres(tskel, (table, rows))
    rest = tskel
    radii = posed_radii(tskel, posed)
    if radii is not tskel.dt:
        tskel = tskel.with_radii(radii)
    own_bounds = bounds is None
    if own_bounds:  # grid_bounds checks the posed reach itself
        bounds = grid_bounds(tskel, padding, centres=[posed]) if len(tskel) else Bounds((0, 0, 0), (0, 0, 0))
    else:
        check_reach(posed, _extent(tskel), " once posed")
    if min(bounds.shape) < 1:
        raise ValueError(f"empty output bounds {bounds.lo}..{bounds.hi}: each upper bound must be >= its lower bound")
    centres = np.ascontiguousarray(posed - np.asarray(bounds.lo, np.float64))
    r2s = radius_squared(tskel.dt)
    metric = K.CHAMFER if tskel.metric == "345" else K.EUCLID
    out_dtype, values = _sphere_values(mode, tskel, value, rows, len(table))
    final_dtype = source.dtype if mode == "sampled" else out_dtype
    per_voxel = np.dtype(out_dtype).itemsize + \
        (np.dtype(final_dtype).itemsize if final_dtype != out_dtype else 0) + (3 if np.ndim(source) == 4 else 0)
    check_output_grid(bounds.shape, per_voxel)
    if metric == K.EUCLID and mode != "hotspot" and speedups.cut and len(tskel):
        # the rest frame's lists even when a sheet thinned: a cut plane is made from this frame's centres
        # and radii and is exact for any pair of spheres (_kernels.py), so the lists only say which pairs
        # are tried; made once per connectivity, not per frame
        nbrs = cached_neighbours(rest, min_radius=CUT_MIN_RADIUS, r2=r2s if rest is tskel else None) \
            if neighbours is None else reorder_neighbours(neighbours, order)
        # read-only as the cache keeps them, whoever made them: numba types a read-only array apart, and the
        # studio's live spheres (their own lists) compiled the kernel again on first use after the warm-up
        nbrs = nbrs.view()
        nbrs.flags.writeable = False
        plane_start, planes = P.build_halfspaces(centres, r2s, nbrs, CUT_MIN_RADIUS**2)
    else:
        plane_start, planes = np.zeros(len(tskel) + 1, np.int64), np.zeros((0, 5))
    # Euclid: the slices with |z - cz| < r + 1e-7 (one slice in from floor/ceil at each end): the kernel
    # tests each exactly, and one farther out has dz^2 > r2 by far more than rounding (listing two more a
    # sphere, as floor/ceil of cz -+ r did, cost the frog 275 k sphere-slice visits that only loaded the
    # sphere to skip it). 345: a margin of 1 beyond floor/ceil.
    reach, inward = (np.sqrt(r2s) + 1e-7, 1) if metric == K.EUCLID else (_extent(tskel), -1)
    zlo = np.floor(centres[:, 2] - reach).astype(np.int64) + inward
    zhi = np.ceil(centres[:, 2] + reach).astype(np.int64) - inward
    offsets, ids = P.slice_lists(zlo, zhi, bounds.shape[2])
    return FramePlan(tskel, minv_rest, table, bounds, own_bounds, centres, r2s,
                     np.ascontiguousarray(tskel.dt, np.float64), metric, values, out_dtype, final_dtype,
                     relax=mode not in ("hotspot", "binary"),  # binary is a union and hotspot a count: no stencil
                     plane_start=plane_start, planes=planes,
                     max_planes=max(1, int(np.diff(plane_start).max())) if len(tskel) else 1, offsets=offsets, ids=ids)


def check_matrices(tskel: Tskel) -> np.ndarray:
    """Inverse of every bone matrix; a matrix that is not a finite, invertible affine map
    (row-vector convention: last column 0 0 0 1) is a ValueError naming the bone and what is wrong."""
    mats = np.asarray(tskel.matrices)
    if mats.shape != (len(tskel.bones), 4, 4):
        raise ValueError(f"expected one 4x4 matrix per bone ({len(tskel.bones)}), got shape {mats.shape}")
    # all bones at once: a live drag checks every frame, and 18 bones one by one cost 11 ms of its 15 ms
    with np.errstate(invalid="ignore", over="ignore"):
        finite = np.isfinite(mats).all(axis=(1, 2))
        affine = finite & (np.abs(mats[:, :, 3] - (0, 0, 0, 1)) <= 1e-6 + 1e-5 * np.array([0, 0, 0, 1])).all(axis=1)
        dets = np.where(affine, np.linalg.det(np.where(affine[:, None, None], mats, np.eye(4))[:, :3, :3]), 0.0)
    bad = np.flatnonzero(~(affine & (np.abs(dets) >= 1e-9)))
    if not len(bad):
        return np.linalg.inv(mats.astype(np.float64))
    b = int(bad[0])
    name, m = f"bone {b} ({tskel.bones[b].label})", mats[b]
    if not finite[b]:
        raise ValueError(f"{name}: its matrix holds NaN or infinite values")
    if not affine[b]:
        raise ValueError(f"{name}: its matrix is not affine (last column {m[:, 3].tolist()}, expected "
                         "0 0 0 1: row-vector convention, translation in row 4)")
    raise ValueError(f"{name}: its matrix is singular (determinant {dets[b]:.3g}); "
                     "it cannot be inverted to sample the source")


def check_frame(tskel: Tskel) -> None:
    """Refuse points a reconstruction cannot place: NaN/infinite values, negative radii,
    and spheres that reach beyond ``MAX_COORD`` voxels."""
    pts, dt = np.ascontiguousarray(tskel.points, np.float64), np.ascontiguousarray(tskel.dt, np.float64)
    if P.spheres_fit(pts, dt, MAX_COORD):
        return
    finite = np.isfinite(pts)
    bad = ~(finite[:, 0] & finite[:, 1] & finite[:, 2]) | ~np.isfinite(dt) | (dt < 0)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"point {i} ({pts[i].tolist()}, dt {dt[i]}) has a NaN, infinite or negative value")
    check_reach(pts, dt, "")


def check_reach(centres: np.ndarray, extents: np.ndarray, where: str) -> None:
    """Every sphere (centre +- extent) must lie within ``MAX_COORD`` voxels of the origin."""
    if not len(centres) or P.spheres_fit(np.ascontiguousarray(centres, np.float64),
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
            lo, hi = P.sphere_box(np.ascontiguousarray(c, np.float64), np.ascontiguousarray(e, np.float64))
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
