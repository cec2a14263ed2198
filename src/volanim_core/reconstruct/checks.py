"""The studio's breakage checks for scripts: ``report`` (one frame) and ``scan`` (a clip).

    .connect + .trans --connect_to_tskel--> posed frame --breakage_report--> BreakageReport
                                                                           --report_json--> dict
    .connect + many .trans --stack, check root order--> scan_frames --worst first--> [FrameVerdict]

The same functions the studio's preview report and Scan for breakage call
(:mod:`.breakage`, :mod:`.scan`); these only gather the joints (:func:`rig_of`)
and the frames the files give. Without a ``.bones`` file the joints are named after the bones
that hang from them (``near L_UPPERARM``: at the upper arm's proximal end).
"""

from __future__ import annotations

from dataclasses import asdict

import numpy as np

from volanim_core.reconstruct.breakage import BreakageReport, RestParts, breakage_report
from volanim_core.reconstruct.engine import Reconstruction
from volanim_core.reconstruct.scan import FrameVerdict, scan_frames, worst_first
from volanim_core.rig.bones import Bone, BoneSkeleton
from volanim_core.rig.connectivity import Connectivity, Trans
from volanim_core.rig.pose import posed_joints
from volanim_core.rig.tskel_tools import check_root_order, connect_to_tskel

SLAB_VOXELS = 8_000_000  # source voxels looked at per step of the coverage count (bounded memory)


def rig_of(conn: Connectivity, bones: BoneSkeleton | None = None) -> BoneSkeleton:
    """The bone skeleton of a connectivity on its grid: ``bones`` (checked to be its bones), or one made
    from its segments, each joint named after the bone that hangs from it (``LABEL.end`` at a limb's end)."""
    if bones is not None:
        from volanim_core.rig.symmetry import check_same_bones

        check_same_bones(conn, bones)
        return bones.on_grid(conn.geometry)
    names: dict[tuple, str] = {}
    for b in conn.bones:
        names.setdefault(tuple(b.proximal), b.label)
    for b in conn.bones:
        names.setdefault(tuple(b.distal), f"{b.label}.end")  # nothing hangs from it
    return BoneSkeleton({n: np.array(p) for p, n in names.items()},
                        [Bone(names[tuple(b.proximal)], names[tuple(b.distal)], b.label) for b in conn.bones],
                        conn.geometry)


def report(conn: Connectivity, trans: Trans, *, bones: BoneSkeleton | None = None, source: np.ndarray | None = None,
           source_geometry=None, cancel=None) -> BreakageReport:
    """The breakage report of one frame (``volanim report``): pieces torn off, stumps, cracks, loss
    against the rest pose, hotspot and the one-line verdict (:class:`BreakageReport`).

    ``source`` (the scan, on ``source_geometry``): also how much of the scan's object the rest pose
    re-grows (``report.source_coverage``), so a loss that is the skeleton's, not the pose's, shows.
    """
    tskel = connect_to_tskel(conn, trans)
    rig = rig_of(conn, bones)
    rest = RestParts.of(conn, cancel)  # made once: the report's rest pose is also the coverage's
    out = breakage_report(tskel, rig.joints, posed_joints(rig, tskel.matrices), rest=rest, cancel=cancel)
    if source is not None:
        out.source_coverage = source_coverage(rest.rest_bone, source, source_geometry)
    return out


def source_coverage(rest: Reconstruction, source: np.ndarray, source_geometry=None) -> tuple[int, int]:
    """``(covered, object)``: the scan's object voxels (non-zero) and how many the rest reconstruction
    ``rest`` (any mode; on the frame's grid) covers."""
    frame = rest.geometry.shifted(-np.asarray(rest.origin))  # the grid the reconstruction's origin counts on
    to_grid = (source_geometry or frame).index_map(rest.geometry)  # source indices -> rest.volume's
    body = np.asarray(source)
    body = body.any(axis=3) if body.ndim == 4 else body != 0
    covered = total = 0
    step = max(1, SLAB_VOXELS // max(body.shape[0] * body.shape[1], 1))
    for z0 in range(0, body.shape[2], step):
        idx = np.argwhere(body[:, :, z0:z0 + step]) + (0, 0, z0)
        where = np.rint(np.column_stack([idx, np.ones(len(idx))]) @ to_grid)[:, :3].astype(np.int64)
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
           "specks": [{"voxels": int(n), "near": j, "at": [round(float(v), 3) for v in c]} for n, j, c in rep.specks],
           "stumps": [{"points": s.points, "near": s.joint, "attached": s.attached, "lies_along": s.lies_along}
                      for s in rep.stumps],
           "lumps": [{"voxels": lump.voxels, "near": lump.near, "at": [round(float(v), 3) for v in lump.centre]}
                     for lump in rep.lumps],
           "joints": [{"name": j.name, "cracks": j.lost, "gap": round(j.gap, 3)} for j in rep.joints]}
    if rep.source_coverage is not None:
        covered, total = rep.source_coverage
        out["source_voxels"], out["source_covered_at_rest"] = total, covered
    return out


def scan(conn: Connectivity, frames: list[Trans], *, bones: BoneSkeleton | None = None, numbers=None,
         factor: int = 2, progress=None, cancel=None) -> list[FrameVerdict]:
    """Scan a clip for breakage (``volanim scan``): one
    :class:`~volanim_core.reconstruct.scan.FrameVerdict` per frame, worst first.

    ``numbers``: each frame's number (default 0, 1, ...); ``factor``: the coarse grid of the piece count.
    """
    if not frames:
        raise ValueError("no frame to scan")
    frames = [t.on_grid(conn.geometry) for t in frames]
    for n, t in enumerate(frames):
        check_root_order(conn.bones, t.bones, f"frame {n if numbers is None else numbers[n]}")
    matrices = np.stack([t.matrices for t in frames])
    verdicts = scan_frames(conn, matrices, numbers, joints=rig_of(conn, bones).joints, factor=factor,
                           progress=progress, cancel=cancel)
    return worst_first(verdicts)


def scan_json(verdicts: list[FrameVerdict]) -> list[dict]:
    return [{**asdict(v), "gap": round(v.gap, 3), "healthy": v.healthy, "broken": v.broken} for v in verdicts]


def fix_lumps(conn: Connectivity, frames: list, bones, *, rounds: int = 3, progress=None) -> tuple:
    """The ownership of ``conn`` (which carries one) with every lump its ``frames`` (Trans) show given back: the
    flesh each lump was made of goes to the bone it belongs to (``Lump.belongs_to``), frame after frame, the
    frames looked at again until none shows a lump or ``rounds`` passes are done (a fix can uncover another).
    Returns the fixed ownership and ``[(frame index, lump, voxels given)]``. The headless *Fix* of the studio
    (``volanim connect --fix-lumps``)."""
    own = conn.ownership
    if own is None:
        raise ValueError("fixing lumps repaints ownership: the connectivity has none (volanim connect makes it)")
    names = [b.name for b in conn.bones]
    fixes = []
    for _ in range(rounds):
        found = False
        for k, trans in enumerate(frames):
            rep = report(conn.with_ownership(own), trans, bones=bones)
            for lump in rep.lumps:
                if lump.belongs_to not in names:
                    continue
                to = names.index(lump.belongs_to)
                taken = own.carried_into(trans.matrices, lump.lo, lump.hi, but=to)
                if len(taken):
                    own = own.relabelled(taken, to)
                    fixes.append((k, lump, len(taken)))
                    found = True
            if progress is not None:
                progress(k + 1, len(frames))
        if not found:
            break
    return own, fixes
