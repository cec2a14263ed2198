"""The studio's breakage checks for scripts: ``report`` (one frame) and ``scan`` (a clip).

    .connect + .trans --connect_to_tskel--> posed frame --breakage_report--> BreakageReport
                                                                           --report_json--> dict
    .connect + many .trans --stack, check root order--> scan_frames --worst first--> [FrameVerdict]

The same functions the studio's preview report and Scan for breakage call
(:mod:`.breakage`, :mod:`.scan`); these only gather the joints and the frames
the files give. Without a ``.bones`` file the joints are named after the bones
that hang from them (``near L_UPPERARM``: at the upper arm's proximal end).
"""

from __future__ import annotations

from dataclasses import asdict

import numpy as np

from volanim_core.reconstruct.breakage import BreakageReport, breakage_report
from volanim_core.reconstruct.scan import FrameVerdict, scan_frames, worst_first
from volanim_core.rig.bones import BoneSkeleton
from volanim_core.rig.connectivity import Connectivity, Trans
from volanim_core.rig.pose import posed_joints
from volanim_core.rig.tskel import check_root_order, connect_to_tskel

SLAB_VOXELS = 8_000_000  # source voxels looked at per step of the coverage count (bounded memory)


def joints_of(conn: Connectivity, bones: BoneSkeleton | None = None) -> dict[str, np.ndarray]:
    """Joint name -> rest position on the connectivity's grid: the bones' joints, or one per bone."""
    if bones is not None:
        from volanim_core.rig.symmetry import check_same_bones

        check_same_bones(conn, bones)
        return dict(bones.on_grid(conn.geometry).joints)
    out = {b.label: b.proximal for b in conn.bones}
    starts = {tuple(b.proximal) for b in conn.bones}
    for b in conn.bones:
        if tuple(b.distal) not in starts:  # a limb's end: nothing hangs from it
            out[f"{b.label}.end"] = b.distal
    return out


def _posed(conn: Connectivity, matrices: np.ndarray, bones: BoneSkeleton | None) -> dict[str, np.ndarray]:
    if bones is not None:
        return posed_joints(bones.on_grid(conn.geometry), matrices)
    out = {b.label: np.append(b.proximal, 1.0) @ m for b, m in zip(conn.bones, matrices)}
    for name, rest in joints_of(conn).items():
        if name.endswith(".end"):
            i = next(i for i, b in enumerate(conn.bones) if f"{b.label}.end" == name)
            out[name] = np.append(rest, 1.0) @ matrices[i]
    return {k: np.asarray(v)[:3] for k, v in out.items()}


def report(conn: Connectivity, trans: Trans, *, bones: BoneSkeleton | None = None, source: np.ndarray | None = None,
           source_geometry=None, cancel=None) -> BreakageReport:
    """The breakage report of one frame (``volanim report``): pieces torn off, stumps, cracks, loss
    against the rest pose, hotspot and the one-line verdict (:class:`BreakageReport`).

    ``source`` (the scan, on ``source_geometry``): also how much of the scan's object the rest pose
    re-grows (``report.source_coverage``), so a loss that is the skeleton's, not the pose's, shows.
    """
    tskel = connect_to_tskel(conn, trans)
    joints = joints_of(conn, bones)
    out = breakage_report(tskel, joints, _posed(conn, tskel.matrices, bones), cancel=cancel)
    if source is not None:
        out.source_coverage = source_coverage(conn, source, source_geometry)
    return out


def source_coverage(conn: Connectivity, source: np.ndarray, source_geometry=None) -> tuple[int, int]:
    """``(covered, object)``: the scan's object voxels (non-zero) and how many the rest pose re-grows."""
    from volanim_core.reconstruct.engine import reconstruct
    from volanim_core.rig.tskel import identity_tskel

    rest = reconstruct(identity_tskel(conn), mode="binary", padding=1)
    to_grid = (source_geometry or conn.geometry).index_map(conn.geometry)
    body = np.asarray(source)
    body = body.any(axis=3) if body.ndim == 4 else body != 0
    covered = total = 0
    step = max(1, SLAB_VOXELS // max(body.shape[0] * body.shape[1], 1))
    for z0 in range(0, body.shape[2], step):
        idx = np.argwhere(body[:, :, z0:z0 + step]) + (0, 0, z0)
        where = np.rint(np.column_stack([idx, np.ones(len(idx))]) @ to_grid)[:, :3].astype(np.int64)
        where -= np.asarray(rest.origin)
        inside = np.all((where >= 0) & (where < rest.volume.shape), axis=1)
        covered += int(np.count_nonzero(rest.volume[tuple(where[inside].T)]))
        total += len(idx)
    return covered, total


def report_json(rep: BreakageReport) -> dict:
    """The report as plain JSON values (``volanim report --json``)."""
    out = {"verdict": rep.verdict, "healthy": rep.healthy, "components": rep.components,
           "rest_pieces": rep.rest_pieces, "posed_voxels": rep.posed_voxels, "rest_voxels": rep.rest_voxels,
           "lost_voxels": rep.lost_voxels, "loss_percent": round(rep.loss_percent, 4), "cracks": rep.cracks,
           "hotspot_max": rep.hotspot_max, "hotspot_mean": round(rep.hotspot_mean, 4),
           "pieces": [{"voxels": int(n), "near": j, "at": [round(float(v), 3) for v in c]} for n, j, c in rep.pieces],
           "stumps": [{"points": s.points, "near": s.joint, "attached": s.attached, "lies_along": s.lies_along}
                      for s in rep.stumps],
           "joints": [{"name": j.name, "cracks": j.lost, "gap": round(j.gap, 3)} for j in rep.joints]}
    if rep.source_coverage is not None:
        covered, total = rep.source_coverage
        out["source_voxels"], out["source_covered_at_rest"] = total, covered
    return out


def scan(conn: Connectivity, frames: list[Trans], *, bones: BoneSkeleton | None = None, numbers=None,
         factor: int = 2, progress=None, cancel=None) -> list[FrameVerdict]:
    """Scan a clip for breakage (``volanim scan``): one :class:`FrameVerdict` per frame, worst first.

    ``numbers``: each frame's number (default 0, 1, ...); ``factor``: the coarse grid of the piece count.
    """
    if not frames:
        raise ValueError("no frame to scan")
    for n, t in enumerate(frames):
        check_root_order(conn.bones, t.bones, f"frame {n if numbers is None else numbers[n]}")
    matrices = np.stack([t.matrices for t in frames])
    verdicts = scan_frames(conn, matrices, numbers, joints=joints_of(conn, bones), factor=factor,
                           progress=progress, cancel=cancel)
    return worst_first(verdicts)


def scan_json(verdicts: list[FrameVerdict]) -> list[dict]:
    return [{**asdict(v), "gap": round(v.gap, 3), "healthy": v.healthy, "broken": v.broken} for v in verdicts]
