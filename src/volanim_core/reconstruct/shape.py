"""How far a posed body is from the shape it should have: Dice, wrong blobs, surface distance, tissue.

    ours [x, y, z] at origin a, truth [x, y, z] at origin b
      --one grid holding both--> A = ours > 0, T = truth > 0
      --Dice, |A - T| extra, |T - A| missing
      --each difference opened by one voxel (a one-voxel rim is not a blob), 26-connected pieces
        --> the largest extra and missing blob: voxels, % of its bone's part, nearest joint
      --surfaces (a mask minus its erosion), Euclidean distance of each to the other (edt, in voxels and
        mm) --> symmetric mean and 95th percentile
      --tissue: share of T & A whose value is the truth's (sampled reconstructions)
      --per joint: Dice of the voxels nearest each posed joint

Dice alone cannot see a lump: a fist of flesh hanging under a raised arm is 6 % of the arm and 0.5 % of
the body (Dice 0.995). The largest wrong blob can. A blob's bone is the posed bone segment nearest its
centre; "its bone's part" is the truth's voxels nearest that segment.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np
from scipy import ndimage

from volanim_core.progress import Reporter
from volanim_core.reconstruct._label_kernels import label_runs

STEPS = 5  # grid and parts, the extra blob, the missing blob, the surface distance, the joints' regions

OPENING = ndimage.generate_binary_structure(3, 1)  # a one-voxel ball: what a one-voxel rim does not survive
PIECES = ndimage.generate_binary_structure(3, 3)  # 26-connected blobs


def piece_count(volume: np.ndarray) -> int:
    """How many 26-connected pieces the non-zero voxels of ``volume`` (``[x, y, z]``) make, as
    ``scipy.ndimage.label`` counts them -- on its runs, without holding Python's GIL (scipy's label held it
    0.5 s on mannequin-large, and the studio's window with it, #83)."""
    zyx = np.asarray(volume).T
    if zyx.dtype == bool:
        zyx = zyx.view(np.uint8)  # the labelling kernels' own type: no copy, no second compilation
    return int(label_runs(np.ascontiguousarray(zyx))[4])


@dataclass
class Blob:
    voxels: int
    centre: tuple[float, float, float]  # rest-grid voxels (the frame's own coordinates)
    bone: str | None = None  # the posed bone segment nearest its centre
    share: float | None = None  # voxels / the truth's voxels of that bone's part
    near: str | None = None  # the posed joint nearest its centre

    def describe(self) -> str:
        where = f" near {self.near}" if self.near else ""
        share = f" ({100 * self.share:.1f} % of {self.bone})" if self.share is not None else ""
        return f"{self.voxels} voxels{share}{where}"


@dataclass
class ShapeReport:
    dice: float
    ours: int  # voxels
    truth: int
    extra: int  # ours, not the truth's
    missing: int  # the truth's, not ours
    largest_extra: Blob | None
    largest_missing: Blob | None
    surface_mean: float  # voxels, symmetric
    surface_p95: float
    surface_mean_mm: float
    surface_p95_mm: float
    tissue: float | None = None  # share of the shared voxels with the truth's value (None: not compared)
    regions: dict[str, float] = field(default_factory=dict)  # joint -> Dice of the voxels nearest it

    def as_dict(self) -> dict:
        return asdict(self)

    def summary(self) -> str:
        def blob(b):
            return b.describe() if b is not None else "none"

        lines = [f"Dice {self.dice:.4f}: {self.ours} voxels against the truth's {self.truth}; "
                 f"{self.extra} extra, {self.missing} missing",
                 f"largest extra blob: {blob(self.largest_extra)}",
                 f"largest missing blob: {blob(self.largest_missing)}",
                 f"surface distance: mean {self.surface_mean:.2f}, 95th percentile {self.surface_p95:.2f} voxels "
                 f"({self.surface_mean_mm:.2f} / {self.surface_p95_mm:.2f} mm)"]
        if self.tissue is not None:
            lines.append(f"tissue agreement: {100 * self.tissue:.1f} % of the shared voxels")
        if self.regions:
            worst = sorted(self.regions.items(), key=lambda kv: kv[1])[:3]
            lines.append("lowest Dice by joint: " + ", ".join(f"{k} {v:.3f}" for k, v in worst))
        return "\n".join(lines)


def compare_shapes(ours: np.ndarray, truth: np.ndarray, *, ours_origin=(0, 0, 0), truth_origin=(0, 0, 0),
                   spacing=(1.0, 1.0, 1.0), joints: dict[str, np.ndarray] | None = None,
                   segments: dict[str, tuple[np.ndarray, np.ndarray]] | None = None,
                   tissue: bool = False, progress=None, cancel=None) -> ShapeReport:
    """Compare a posed volume with the true one (see the module docstring).

    Parameters
    ----------
    ours, truth : (X, Y, Z) ndarray
        Volumes indexed ``[x, y, z]``; non-zero is body. A colour volume (X, Y, Z, 3) counts its non-black voxels.
    ours_origin, truth_origin : three ints
        Where each volume's voxel ``[0, 0, 0]`` lies in the frame's grid (``Reconstruction.origin``,
        ``posed_sample(...).origin``).
    spacing : three floats
        Millimetres per voxel, for the distances in mm.
    joints : dict, optional
        Posed joint positions (``posed_joints``): a blob's nearest joint, and the per-joint Dice.
    segments : dict, optional
        Posed bone segments ``name -> (proximal, distal)``: a blob's bone and the share of its part.
    tissue : bool
        Also the share of shared voxels whose value is the truth's (sampled reconstructions of a body
        whose values are tissues).
    progress, cancel : optional
        ``progress(done, total)`` after each of its steps (seconds each on a large body); ``cancel()``
        returning True stops it (:class:`~volanim_core.errors.Cancelled`).
    """
    report = Reporter(progress, cancel)
    report(0, STEPS)
    a, t, lo = _on_one_grid(ours, truth, ours_origin, truth_origin)
    body_a, body_t = _body(a), _body(t)
    shared = body_a & body_t
    n_a, n_t, n_shared = int(body_a.sum()), int(body_t.sum()), int(shared.sum())
    dice = 2 * n_shared / (n_a + n_t) if n_a + n_t else 1.0
    parts = _parts(body_t, lo, segments) if segments else None
    report(1, STEPS)
    largest = []
    for k, diff in enumerate((body_a & ~body_t, body_t & ~body_a)):
        largest.append(_largest_blob(diff, lo, joints, segments, parts))
        report(2 + k, STEPS)
    mean, p95, mean_mm, p95_mm = _surface_distance(body_a, body_t, spacing)
    report(4, STEPS)
    agree = None
    if tissue and n_shared:
        same = a[shared] == t[shared]
        agree = float((same.all(axis=-1) if a.ndim == 4 else same).mean())
    regions = _regions(body_a, body_t, lo, joints) if joints else {}
    report(STEPS, STEPS)
    return ShapeReport(dice, n_a, n_t, int((body_a & ~body_t).sum()), int((body_t & ~body_a).sum()),
                       largest[0], largest[1], mean, p95, mean_mm, p95_mm, agree, regions)


def _body(v: np.ndarray) -> np.ndarray:
    return v.any(axis=-1) if v.ndim == 4 else v != 0


def _on_one_grid(ours, truth, oa, ot):
    """Both volumes placed in the box holding both; ``lo`` is that box's corner in the frame's grid."""
    oa, ot = np.asarray(oa, int), np.asarray(ot, int)
    lo = np.minimum(oa, ot)
    hi = np.maximum(oa + ours.shape[:3], ot + truth.shape[:3])
    out = []
    for v, o in ((ours, oa), (truth, ot)):
        grid = np.zeros(tuple(hi - lo) + v.shape[3:], v.dtype)
        at = o - lo
        grid[at[0]:at[0] + v.shape[0], at[1]:at[1] + v.shape[1], at[2]:at[2] + v.shape[2]] = v
        out.append(grid)
    return out[0], out[1], lo


def _nearest(points: np.ndarray, named: dict[str, np.ndarray]) -> tuple[list[str], np.ndarray]:
    from scipy.spatial import cKDTree

    names = list(named)
    return names, cKDTree(np.array([np.asarray(named[n], float) for n in names])).query(points)[1]


def _nearest_segment(points: np.ndarray, segments: dict) -> tuple[list[str], np.ndarray]:
    """Each point's nearest bone segment (ties: the first named), as the nearest-bone connect finds it."""
    from volanim_core.rig.nearest import segment_distances

    names = list(segments)
    segs = np.array([[np.asarray(p, float) for p in segments[n]] for n in names])
    which = np.empty(len(points), np.int64)
    for s in range(0, len(points), 65536):  # bounded memory: (chunk, B, 3) at a time
        which[s:s + 65536] = segment_distances(points[s:s + 65536], segs).argmin(1)
    return names, which


def _parts(body_t: np.ndarray, lo, segments) -> dict[str, int]:
    """Voxels of the truth nearest each bone segment: each bone's part."""
    names, which = _nearest_segment(np.argwhere(body_t) + lo, segments)
    counts = np.bincount(which, minlength=len(names))
    return {n: int(c) for n, c in zip(names, counts)}


def extra_flesh(ours: np.ndarray, truth: np.ndarray, *, ours_origin=(0, 0, 0), truth_origin=(0, 0, 0)
                ) -> tuple[np.ndarray, np.ndarray]:
    """``(extra, lo)``: the voxels ours has and the truth lacks, opened by one voxel as the blobs are, on the
    grid holding both (its voxel [0, 0, 0] at ``lo`` in the frame's grid): what a flagged lump is checked
    against (benchmarks/bench_shape.py)."""
    a, t, lo = _on_one_grid(ours, truth, ours_origin, truth_origin)
    return _opened(_body(a) & ~_body(t)), lo


def _opened(diff: np.ndarray) -> np.ndarray:
    return ndimage.binary_opening(diff, OPENING)


def _largest_blob(diff: np.ndarray, lo, joints, segments, parts) -> Blob | None:
    labels, n = ndimage.label(_opened(diff), PIECES)
    if n == 0:
        return None
    sizes = np.bincount(labels.ravel())[1:]
    k = int(np.argmax(sizes)) + 1
    centre = np.argwhere(labels == k).mean(axis=0) + lo
    blob = Blob(int(sizes[k - 1]), tuple(round(float(c), 1) for c in centre))
    if joints:
        names, which = _nearest(centre[None], joints)
        blob.near = names[int(which[0])]
    if segments:
        names, which = _nearest_segment(centre[None], segments)
        blob.bone = names[int(which[0])]
        blob.share = blob.voxels / max(parts.get(blob.bone, 0), 1)
    return blob


def _surface(mask: np.ndarray) -> np.ndarray:
    return mask & ~ndimage.binary_erosion(mask, OPENING, border_value=0)


def _surface_distance(a: np.ndarray, t: np.ndarray, spacing) -> tuple[float, float, float, float]:
    """Symmetric surface distance (mean, 95th percentile) in voxels and in mm."""
    import edt

    sa, st = _surface(a), _surface(t)
    if not sa.any() or not st.any():
        return (0.0, 0.0, 0.0, 0.0) if sa.any() == st.any() else (np.inf,) * 4
    out = []
    for anisotropy in ((1.0, 1.0, 1.0), tuple(float(s) for s in spacing)):
        d = np.concatenate([edt.edt(~st, anisotropy=anisotropy, black_border=False)[sa],
                            edt.edt(~sa, anisotropy=anisotropy, black_border=False)[st]])
        out.append((float(d.mean()), float(np.percentile(d, 95))))
    return out[0][0], out[0][1], out[1][0], out[1][1]


def _regions(a: np.ndarray, t: np.ndarray, lo, joints) -> dict[str, float]:
    """Dice per joint, each voxel of either body counted at the posed joint nearest it."""
    either = a | t
    at = np.argwhere(either)
    names, which = _nearest(at + lo, joints)
    ia, it = a[either], t[either]
    out = {}
    for k, n in enumerate(names):
        sel = which == k
        na, nt, both = int(ia[sel].sum()), int(it[sel].sum()), int((ia[sel] & it[sel]).sum())
        if na + nt:
            out[n] = 2 * both / (na + nt)
    return out
