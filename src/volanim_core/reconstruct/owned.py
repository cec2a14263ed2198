"""The posed body from the rig's ownership: every rest voxel moved by the bone that owns it, joints closed by balls.

    Ownership (rig/ownership.py: rest labels, ball radii), matrices (B, 4, 4)
        --each bone's owned box moved by its matrix--> posed boxes; output grid (their union + padding, or bounds)
        --K.posed_cells (each turned bone's rest cubes, Ownership.cells, moved)--> the output cubes it can land in
        --K.warp_owners (each output voxel read at the rest point its bone brings it from: the body's share
                         there, trilinear, and the bone owning most of it; a turned bone only in its cubes;
                         launches of ~LAUNCH_SECONDS, as the spheres')--> owner [z, y, x]
        --K.splat_turned (each turned bone's thin rest voxels pushed to where they land, where still empty: a limb
                          one voxel thin that the read steps over stays in one piece)-->
        --K.close_joints (the ball at each bone's proximal joint, moved by the bone: empty voxels to the bone)-->
        --by mode--> binary (value), bone (owner), mottled (a colour per bone), hotspot (bones reaching a voxel),
                     sampled (the source at each voxel's rest point: reconstruct/sampling.py, as the spheres do)
        --> Reconstruction

Why (#84): the spheres of the thesis's re-growth are centred on skeleton points, and a sphere beside a joint is
wider than its limb, so a raised arm swings a fist of armpit flesh with it (6 % of the arm) and the rest pose
comes back short (mannequin-large: 37,090 voxels). Moving the rest voxels themselves gives the rest pose back
voxel for voxel and moves exactly what each bone owns. Where a joint bends, the parent's and the child's
voxels part on the outside of the bend and a wedge opens; the ball of the body's depth at the joint, which
both bones carry to the same place, closes it.

Each voxel moves with its owner alone. Also carrying, as a copy, another bone's voxel where the two bones'
tubes overlap (the mannequin's capsules do: a limb's end inside the torso) was measured and left out
(benchmarks/bench_shape.py, #84's note): it narrowed the hip's gap (4.6 % -> 2.2-2.8 % of the leg) but every
variant swung flesh that is not there (a nodding head's neck: 3-9 % of the head), and a lump is what the
animator sees first.

Same output as :func:`~volanim_core.reconstruct.engine.reconstruct` (a :class:`Reconstruction`), so every
caller can take either: ``volanim reconstruct --method spheres`` is the thesis's, still exact against its oracle.
"""

from __future__ import annotations

import threading
import time
import weakref

import numba
import numpy as np

from volanim_core.geometry import Geometry
from volanim_core.memo import Recent, content_key
from volanim_core.progress import CancelFn, Clock, Pacer, ProgressFn, Reporter
from volanim_core.reconstruct import _owned_kernels as K
from volanim_core.reconstruct._owned_kernels import ZB
from volanim_core.reconstruct.plan import LAUNCH_SECONDS, MODES, mottled_values, output_dtype
from volanim_core.reconstruct.result import Reconstruction
from volanim_core.reconstruct.sampling import grid_to_source, sample_source
from volanim_core.rig.ownership import CELL, DIAGONALS, Ownership
from volanim_core.volume import Bounds

_POSES = weakref.WeakKeyDictionary()  # Ownership -> Recent: its boxes and balls in the last few poses
_POSES_LOCK = threading.Lock()
POSES_KEPT = 8  # (what, pose) pairs kept per ownership: a live picture asks for two poses, the full preview one


def _per_pose(own: Ownership, what: str, matrices: np.ndarray, make):
    """``make()`` of ``own`` in the pose ``matrices``, kept for its last few poses (read-only arrays). A live
    picture asks for the same pose's boxes and balls four times (the grid, what moved before and after, the
    frame, what left the grid): on the mannequin, 1.6 of its 10 ms alone, all of it Python under the lock
    the window's thread wants too."""
    with _POSES_LOCK:
        kept = _POSES.get(own)
        if kept is None:
            kept = _POSES[own] = Recent(POSES_KEPT)

    def made():
        out = make()
        for a in out if isinstance(out, tuple) else (out,):
            a.setflags(write=False)
        return out

    return kept.get(content_key(np.ascontiguousarray(matrices, np.float64), text=what), made)


def posed_boxes(own: Ownership, matrices: np.ndarray) -> np.ndarray:
    """``(B, 6)`` each bone's owned voxels' box once moved by its matrix, in rest-grid voxels (x1 < x0: owns
    none): its hull's vertices moved (own.hulls()), two voxels wider: a read finds the bone among the 8 voxels
    around its point, up to a voxel's diagonal away. Read-only: kept for the pose (:func:`_per_pose`)."""
    return _per_pose(own, "boxes", matrices, lambda: _posed_boxes(own, matrices))


def _posed_boxes(own: Ownership, matrices: np.ndarray) -> np.ndarray:
    out = np.zeros((len(own.bones), 6), np.int64)
    out[:, :3] = 1
    for b, hull in enumerate(own.hulls()):
        if not len(hull):
            continue
        moved = hull @ matrices[b, :3, :3] + matrices[b, 3, :3]
        out[b, :3] = np.floor(moved.min(0)) - 2
        out[b, 3:] = np.ceil(moved.max(0)) + 2
    return out


def joint_balls(own: Ownership, matrices: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The balls closing the joints, posed: centres ``(K, 3)``, squared radii, the bone each fills for.
    One ball a joint (bones sharing a proximal joint carry it to one place; the first in root order fills).
    Read-only: kept for the pose (:func:`_per_pose`)."""
    return _per_pose(own, "balls", matrices, lambda: _joint_balls(own, matrices))


def _joint_balls(own: Ownership, matrices: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    has = np.flatnonzero(own.ball_radii > 0)
    prox = np.array([own.bones[b].proximal for b in has], np.float64).reshape(-1, 3)
    m = np.asarray(matrices, np.float64)[has]
    posed = np.einsum("ki,kij->kj", prox, m[:, :3, :3]) + m[:, 3, :3]
    keep = [k for k in range(len(has)) if not (np.abs(posed[:k] - posed[k]).max(1, initial=np.inf) <= 1e-6).any()]
    return (np.ascontiguousarray(posed[keep]).reshape(-1, 3), own.ball_radii[has[keep]] ** 2,
            has[keep].astype(np.int64))


def reconstruct_owned(
    own: Ownership,
    matrices,
    *,
    mode: str = "binary",
    source: np.ndarray | None = None,
    source_geometry: Geometry | None = None,
    kernel: int = 1,
    bounds: Bounds | None = None,
    padding: int = 2,
    value: int = 255,
    threads: int | None = None,
    progress: ProgressFn | None = None,
    cancel: CancelFn | None = None,
    clock: Clock = time.perf_counter,
    owners: np.ndarray | None = None,
) -> Reconstruction:
    """The body posed by ``matrices`` (``(B, 4, 4)``, rest voxels -> posed, ``[x y z 1] @ M``) from its
    ownership: see the module docstring. Parameters as :func:`~volanim_core.reconstruct.engine.reconstruct`'s.
    ``owners``: a ``[z, y, x]`` array of the grid's shape and the labels' dtype to hold each voxel's owner
    (zeroed here; bone mode returns it as the volume): a caller's kept one spares a fresh array's first touch
    (a live update's box: 9 of the frog's 34 ms a half-size picture in the studio, 0.4 alone).

    Examples
    --------
    >>> import numpy as np
    >>> from volanim_core.rig.connectivity import BoneSegment
    >>> own = Ownership(np.ones((3, 3, 3), np.uint8), (4, 4, 4), [BoneSegment((4, 5, 5), (6, 5, 5))], [0.0])
    >>> r = reconstruct_owned(own, np.eye(4)[None], padding=0)
    >>> int((r.volume > 0).sum()), r.origin
    (27, (4, 4, 4))
    """
    t0 = clock()
    matrices = _checked(own, matrices, mode, source, kernel)
    report = Reporter(progress, cancel)
    boxes = posed_boxes(own, matrices)
    centres, r2s, ball_bones = joint_balls(own, matrices)
    grid = bounds or _grid(boxes, centres, r2s, padding)
    lo = np.asarray(grid.lo, np.int64)
    nx, ny, nz = grid.shape
    n_bones = len(own.bones)
    if owners is not None and (owners.shape != (nz, ny, nx) or owners.dtype != own.labels.dtype):
        raise ValueError(f"owners must be a {own.labels.dtype} array of shape {(nz, ny, nx)} (the grid's [z, y, x]), "
                         f"got {owners.dtype} {owners.shape}")
    owner = K.zeroed(np.empty((nz, ny, nx), own.labels.dtype) if owners is None else owners)
    count = mode == "hotspot"
    claims = np.zeros((nz, ny, nx) if count else (1, 1, 1), np.uint16)
    row_lo = np.full((nz, ny), nx, np.int32)
    row_hi = np.full((nz, ny), -1, np.int32)
    local = boxes - np.tile(lo, 2)
    local[:, :3] = np.maximum(local[:, :3], 0)
    local[:, 3:] = np.minimum(local[:, 3:], np.array([nx, ny, nz]) - 1)
    inv = np.ascontiguousarray(np.linalg.inv(matrices))
    rest_lo = np.asarray(own.origin, np.int64)
    flags = own.flags()
    shifts = whole_voxel_shifts(matrices)
    # a bone whose posed box misses the grid adds nothing (a live update's box holds few): not splatted
    reaches = (boxes[:, 3:] >= lo).all(1) & (boxes[:, :3] <= np.asarray(grid.hi)).all(1)
    nthreads = max(1, min(int(threads or numba.get_num_threads()), numba.config.NUMBA_NUM_THREADS))
    previous = numba.get_num_threads()
    numba.set_num_threads(nthreads)
    reads = filled = 0
    try:
        turned, marks = _turned_marks(own, matrices, (shifts[:, 3] == 0) & reaches, lo, (nz, ny, nx))
        total = 2 * nz if mode == "sampled" else nz
        report(0, total)
        # a first, small launch measures the pace; the next ones last about LAUNCH_SECONDS each (engine's rule)
        pacer = Pacer(first=max(nthreads * ZB * 2, nz // 16), least=nthreads * ZB, seconds=LAUNCH_SECONDS, clock=clock)
        for z0, z1 in pacer.spans(nz):
            slab = local.copy()
            slab[:, 2] = np.maximum(slab[:, 2] - z0, 0)
            slab[:, 5] = np.minimum(slab[:, 5] - z0, z1 - z0 - 1)
            visits, wrote = K.warp_owners(own.labels, flags, own.spans(), rest_lo, inv, shifts, turned, marks, CELL, z0,
                                          slab, lo + (0, 0, z0), owner[z0:z1], row_lo[z0:z1], row_hi[z0:z1],
                                          claims[z0:z1] if count else claims, count, nthreads)
            reads, filled = reads + visits, filled + wrote
            report(z1, total)
        # then each turned bone's own voxels pushed to where they land: a limb one voxel thin stays whole
        starts, thin = own.thin()
        bits = own.diagonals()
        for b in np.flatnonzero((shifts[:, 3] == 0) & reaches):
            filled += K.splat_turned(thin[starts[b]:starts[b + 1]], bits[starts[b]:starts[b + 1]], DIAGONALS,
                                     rest_lo, matrices[b], int(b), lo, owner, row_lo, row_hi, claims, count)
        filled += K.close_joints(owner, lo, centres, r2s, ball_bones, row_lo, row_hi, claims, count)
        volume = _by_mode(owner, claims, mode, n_bones, value)
        if mode == "sampled":
            # a coarse ownership's voxel c is the source's voxel factor c (Ownership.coarse)
            to_source = np.diag([float(own.factor)] * 3 + [1.0]) if source_geometry is None else \
                own.geometry.index_map(source_geometry)
            maps = grid_to_source(inv, lo.astype(np.float64), to_source)
            volume = sample_source(owner, source, maps, kernel, (row_lo, row_hi), nthreads, pacer.size,
                                   lambda done: report(nz + done, total))
    finally:
        numba.set_num_threads(previous)
    # given bounds: the bones whose posed box leaves them (a caller counts the voxels lost, as for spheres)
    outside = 0 if bounds is None else int(((boxes[:, 3] >= boxes[:, 0]) & ((boxes[:, :3] < lo).any(1) | (
        boxes[:, 3:] > np.asarray(grid.hi)).any(1))).sum())
    stats = {"method": "owned", "bones": n_bones, "balls": len(r2s), "filled": filled, "visits": int(reads),
             "overdraw": float(reads / filled) if filled else 0.0, "clipped": outside,
             "clipped_estimated": bool(outside)}
    if count:
        stats["hotspot_max"] = int(claims.max()) if claims.size else 0
        stats["hotspot_mean"] = float(claims.sum() / filled) if filled else 0.0
    stats["seconds"] = clock() - t0
    xyz = volume.transpose(2, 1, 0, 3) if volume.ndim == 4 else volume.T
    return Reconstruction(xyz, tuple(int(v) for v in lo), stats, own.geometry.shifted(lo))


def _turned_marks(own: Ownership, matrices: np.ndarray, which: np.ndarray, lo: np.ndarray, shape_zyx):
    """For each turned bone that reaches the grid (``which``: not moved by whole voxels), the output cubes
    (:data:`CELL` a side) its reads can find it in: ``turned[b]`` its index in ``marks (T, cz, cy, cx)`` (0 for
    the others, whose entry is never read). A read finds the bone among the 8 voxels around its point, a
    voxel's diagonal away at most, and a voxel lies within half a cube's diagonal of its cube's centre."""
    turned = np.zeros(len(matrices), np.int64)
    which = np.flatnonzero(which)
    marks = np.zeros((max(1, len(which)), *(-(-np.asarray(shape_zyx) // CELL))), np.uint8)
    starts, cells = own.cells()
    rest_lo = np.asarray(own.origin, np.int64)
    for k, b in enumerate(which):
        turned[b] = k
        K.posed_cells(cells[starts[b]:starts[b + 1]], CELL, rest_lo, matrices[b], cube_reach(matrices[b]), lo, marks[k])
    return turned, marks


def cube_reach(m: np.ndarray) -> np.ndarray:
    """How far from a rest cube's centre, moved by ``m``, along each output axis, a read can find one of the cube's
    voxels: a read's point is within a voxel of the voxel it finds (one of the 8 around it) and that voxel within
    half a cube of its centre, along each rest axis; moved, output axis k spans that much times ``sum_j |m[j, k]|``.
    The box this bounds, not a ball round the largest stretch: a turn of 45 degrees marks half the cubes."""
    return ((CELL - 1) / 2 + 1) * np.abs(np.asarray(m, np.float64)[:3, :3]).sum(0) + 1e-6


def whole_voxel_shifts(matrices: np.ndarray) -> np.ndarray:
    """``(B, 4)``: ``dx dy dz 1`` for each bone its matrix moves by whole voxels only (no turn), else zeros."""
    m = np.asarray(matrices)
    t = m[:, 3, :3]
    whole = (m[:, :3, :3] == np.eye(3)).all((1, 2)) & (t == np.round(t)).all(1) & (np.abs(t) < 2**30).all(1)
    out = np.zeros((len(m), 4), np.int64)
    out[whole, :3] = np.round(t[whole]).astype(np.int64)
    out[whole, 3] = 1
    return out


def _checked(own: Ownership, matrices, mode, source, kernel) -> np.ndarray:
    if mode not in MODES:
        raise ValueError(f"mode must be one of {', '.join(MODES)}, got {mode!r}")
    if kernel not in (1, 3, 5):
        raise ValueError(f"kernel must be 1, 3 or 5, got {kernel!r}")
    if mode == "sampled" and source is None:
        raise ValueError("sampled mode needs the rest-pose source volume")
    m = np.asarray(matrices, np.float64)
    if m.shape != (len(own.bones), 4, 4):
        raise ValueError(f"matrices must be ({len(own.bones)}, 4, 4), one per bone of the ownership, "
                         f"got shape {m.shape}")
    if not np.isfinite(m).all():
        raise ValueError("matrices must be finite")
    if abs(np.linalg.det(m[:, :3, :3])).min() < 1e-9:
        raise ValueError("a bone's matrix is singular: it cannot be inverted to find the rest voxels it moves")
    return np.ascontiguousarray(m)


def posed_bounds(own: Ownership, matrices: np.ndarray, padding: int = 2) -> Bounds:
    """The grid :func:`reconstruct_owned` makes the pose on when given no bounds."""
    return _grid(posed_boxes(own, matrices), *joint_balls(own, matrices)[:2], padding)


def _grid(boxes: np.ndarray, centres: np.ndarray, r2s: np.ndarray, padding: int) -> Bounds:
    has = boxes[:, 3] >= boxes[:, 0]
    los = [boxes[has, :3]]
    his = [boxes[has, 3:]]
    if len(r2s):
        r = np.sqrt(r2s)[:, None]
        los.append(np.floor(centres - r))
        his.append(np.ceil(centres + r))
    lo = np.concatenate(los).min(0).astype(int) - padding
    hi = np.concatenate(his).max(0).astype(int) + padding
    return Bounds(tuple(int(v) for v in lo), tuple(int(v) for v in hi))


def _by_mode(owner: np.ndarray, claims: np.ndarray, mode: str, n_bones: int, value: int) -> np.ndarray:
    if mode == "bone":
        return owner.astype(output_dtype("bone", n_bones), copy=False)
    if mode == "hotspot":
        return claims
    if mode == "binary":
        lut = np.zeros(n_bones + 1, np.uint8)
        lut[1:] = value
        return lut[owner]
    if mode == "mottled":
        lut = np.zeros(n_bones + 1, np.uint8)
        lut[1:] = mottled_values(n_bones)
        return lut[owner]
    return owner  # sampled: the owners, sampled after
