"""Reconstruction and its checks: bounds, reconstruct, compare, report, scan.

``report`` and ``scan`` are the studio's verdicts for scripts (``volanim_core.report``, ``.scan``): they exit
0 when healthy, 1 when broken, 2 on bad input."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from volanim_core.errors import FormatError
from volanim_core.io import (
    read_bones,
    read_connect,
    read_trans,
    read_tskel,
    write_output,
)
from volanim_core.progress import TextProgress
from volanim_core.reconstruct.engine import MODES, grid_bounds, reconstruct
from volanim_core.rig.pose import root_bones
from volanim_core.rig.tskel_tools import check_root_order, identity_tskel

from ._common import (
    add_command,
    add_dims,
    add_joints,
    ascii_int,
    bounds_arg,
    joints_of,
    load_source,
    positive_int,
)


def _bounds(args):
    b = grid_bounds([read_tskel(p) for p in args.tskel], args.padding)
    print(b)


def _check_output(path: str) -> None:
    from ..io.volume_files import WRITE_SUFFIXES

    if not any(path.endswith(sfx) for sfx in WRITE_SUFFIXES):
        raise ValueError(f"cannot write {path}: the output must end in {', '.join(WRITE_SUFFIXES)}")


def _reconstruct(args):
    _check_output(args.output)
    t = joints_of(args, read_tskel(args.tskel))
    source, source_geometry = load_source(args, t, colour=True)
    bounds = bounds_arg(args.bounds) if args.bounds else None
    bar = TextProgress("reconstruct")
    r = reconstruct(t, mode=args.mode, source=source, source_geometry=source_geometry, kernel=args.kernel,
                    bounds=bounds, padding=args.padding, threads=args.threads, progress=bar, method=args.method)
    output, note = write_output(args.output, r.volume, r.geometry, args.mode)
    if note:
        print(f"note: {note}")
    s = r.stats
    made = f"{s['bones']} bones moved their owned voxels" if s.get("method") == "owned" else f"{s['spheres']} spheres"
    print(f"{made} -> {s['filled']} voxels filled in {s['seconds']:.3f} s "
          f"(overdraw {s['overdraw']:.1f}); grid {r.volume.shape[0]}x{r.volume.shape[1]}x{r.volume.shape[2]}, "
          f"origin {r.origin[0]} {r.origin[1]} {r.origin[2]} -> {output}")
    if s["clipped"]:
        # what the user loses is body voxels, not sphere coverage (overlapping spheres count many times)
        try:
            whole = reconstruct(t, mode="binary", padding=args.padding, threads=args.threads, method=args.method)
        except ValueError:  # the unbounded grid is too large to make: say what is known
            print(f"clipped: the spheres reach outside the given bounds ({s['clipped']:,} sphere voxels, "
                  "overlaps counted; the whole body's grid is too large to count the voxels lost)")
        else:
            lost = whole.stats["filled"] - s["filled"]
            print(f"clipped: {lost:,} voxels of the body lie outside the given bounds and were not written "
                  f"({100 * lost / max(whole.stats['filled'], 1):.2f} % of {whole.stats['filled']:,})")
    if args.mode == "hotspot":
        what = "bones" if s.get("method") == "owned" else "spheres"
        print(f"hotspot: max {s['hotspot_max']} {what} on one voxel, mean {s['hotspot_mean']:.2f}")
    if args.loss:
        rest = reconstruct(identity_tskel(t.connectivity), mode="binary", threads=args.threads, method=args.method)
        lost = rest.stats["filled"] - s["filled"]
        print(f"voxel loss against the identity frame: {lost} of {rest.stats['filled']} "
              f"({100 * lost / max(rest.stats['filled'], 1):.2f} %)")


def _compare(args):
    """``compare OURS (TRUTH | --sample NAME --pose P)``: how far a posed volume is from its true shape."""
    import json

    from volanim_core.geometry import IDENTITY
    from volanim_core.io import read_scan
    from volanim_core.reconstruct.shape import compare_shapes
    from volanim_core.rig.pose import posed_joints

    if (args.truth is None) == (args.sample is None):
        raise ValueError("give the true volume (TRUTH) or --sample NAME --pose P.trans, not both or neither")
    trans = read_trans(args.pose) if args.pose else None
    bones = read_bones(args.bones) if args.bones else None
    if args.sample is not None:
        from volanim_core.posed_truth import posed_sample

        if trans is None:
            raise ValueError("--sample needs --pose: the .trans the reconstruction was posed with")
        bar = TextProgress("posing the true shape")
        made = posed_sample(args.sample, trans.matrices, progress=bar)
        bar.close()
        truth, truth_geometry = made.volume, IDENTITY.shifted(made.origin)
        bones = bones or made.bones
    else:
        truth, truth_geometry, _ = read_scan(args.truth, colour=True)
    ours, ours_geometry, _ = read_scan(args.ours, colour=True)
    base = bones.geometry if bones is not None else truth_geometry
    at = [_offset(g, base, f) for g, f in ((ours_geometry, args.ours), (truth_geometry, args.truth or args.sample))]
    joints = segments = None
    if bones is not None and trans is not None:
        trans = trans.on_grid(bones.geometry)
        check_root_order(root_bones(bones), trans.bones, first=".bones")
        joints = posed_joints(bones, trans.matrices)
        segments = {b.label: (joints[b.proximal], joints[b.distal]) for b in bones.bones}
    bar = TextProgress("comparing")
    report = compare_shapes(ours, truth, ours_origin=at[0], truth_origin=at[1], spacing=base.spacing,
                            joints=joints, segments=segments, tissue=args.tissue, progress=bar)
    bar.close()
    print(json.dumps(report.as_dict(), indent=2) if args.json else report.summary())


def _offset(geometry, base, name) -> tuple[int, int, int]:
    """Where a volume's voxel [0, 0, 0] lies in the frame's grid ``base`` (same spacing and axes)."""
    m = geometry.index_map(base)
    if not np.allclose(m[:3, :3], np.eye(3), atol=1e-6) or not np.allclose(m[3, :3], np.rint(m[3, :3]), atol=1e-3):
        raise ValueError(f"{name}: its voxels are not the frame's (other spacing, axes or a part-voxel shift); "
                         "resample it onto the frame's grid first")
    return tuple(int(v) for v in np.rint(m[3, :3]))


def _report(args):
    from volanim_core.reconstruct.checks import report, report_json

    conn = joints_of(args, read_connect(args.connect))
    source, geometry = load_source(args, conn, colour="luminance") if args.source else (None, None)
    rep = report(conn, read_trans(args.trans), bones=read_bones(args.bones) if args.bones else None,
                 source=source, source_geometry=geometry)
    if args.json:
        print(json.dumps(report_json(rep), indent=1))
    else:
        print(rep.verdict)
        for line in rep.lines():
            print(f"  {line}")
        for j in rep.joints:
            print(f"  near {j.name}: {j.lost} cracks, opening {j.gap:.1f} voxels")
    return 0 if rep.healthy else 1


def _scan(args):
    from volanim_core.io.frame_files import frame_number
    from volanim_core.reconstruct.checks import scan, scan_json
    from volanim_core.reconstruct.scan import scan_summary

    conn = joints_of(args, read_connect(args.connect))
    frames = [read_trans(p) for p in args.frames]
    for path, t in zip(args.frames, frames):  # a frame of another rig, named by its file (scan names numbers)
        try:
            check_root_order(conn.bones, t.on_grid(conn.geometry).bones, Path(path).name, Path(args.connect).name)
        except ValueError as exc:
            raise FormatError(path, str(exc)) from None
    numbers = [frame_number(p) for p in args.frames]
    if None in numbers or len(set(numbers)) < len(numbers):
        numbers = list(range(len(args.frames)))  # names without (distinct) numbers: their order on the line
    verdicts = scan(conn, frames, bones=read_bones(args.bones) if args.bones else None, numbers=numbers,
                    progress=None if args.json else TextProgress(f"scanning {len(frames)} frames"))
    bad = [v for v in verdicts if v.broken]
    if args.json:
        print(json.dumps(scan_json(verdicts), indent=1))
    else:
        print(f"{scan_summary(verdicts)}; worst first")
        for v in verdicts[:args.top]:
            print(f"  frame {v.frame}: {v.pieces} piece(s) ({v.rest_pieces} at rest), {v.detached} voxels "
                  f"detached, {v.stump} stump points, {v.cracks} cracks"
                  + (f" near {v.worst_joint}" if v.worst_joint else "")
                  + (f", a lump of {v.lump:,} voxels near {v.lump_near}" if v.lump else "")
                  + (": BROKEN" if v.broken else ""))
    return 1 if bad else 0


def register(sub) -> None:
    p = add_command(sub, "bounds", "Inclusive bounds of the posed spheres of one or more frames (tskelbounds).",
                    "volanim bounds arm.tskel rest.tskel --padding 2", _bounds)
    p.add_argument("tskel", nargs="+")
    p.add_argument("--padding", type=ascii_int, default=2)

    p = add_command(sub, "reconstruct", "Re-grow a volume from a .tskel frame (numba, parallel).",
                    ("volanim reconstruct arm.tskel --source mannequin.VOL --mode sampled -o arm.vti",
                     "volanim reconstruct arm.tskel --mode hotspot -o arm-hot.nrrd",
                     "volanim reconstruct arm.tskel --joints smooth --blend 1.5 --mode bone -o arm-smooth.vti",
                     "volanim reconstruct arm.tskel --mode bone -o arm-bone.vol   # written as arm-bone.XxYxZ.vol"),
                    _reconstruct)
    p.add_argument("tskel")
    p.add_argument("--source", help="rest-pose volume (needed for --mode sampled)")
    add_dims(p)  # --dims for a headerless .vol source, --series for a DICOM folder of several
    p.add_argument("--mode", choices=MODES, default="binary", help="default binary")
    p.add_argument("--method", choices=("auto", "owned", "spheres"), default="auto",
                   help="auto (default): move each rest voxel with the bone that owns it when the frame names its "
                        "rig's ownership (# ownership:, written by connect2tskel), else re-grow spheres; spheres: "
                        "the thesis's re-growth")
    p.add_argument("--kernel", type=ascii_int, choices=(1, 3, 5), default=1, help="sampled: Gaussian kernel size")
    group = p.add_mutually_exclusive_group()
    group.add_argument("--bounds", nargs=6, type=ascii_int, metavar="N", help="inclusive bounds x0 y0 z0 x1 y1 z1")
    group.add_argument("--padding", type=ascii_int, default=2, help="voxels around the posed spheres (default 2)")
    p.add_argument("--threads", type=ascii_int, help="numba threads (default: all cores)")
    p.add_argument("--loss", action="store_true", help="also report voxel loss against the identity frame")
    add_joints(p, "the .tskel's (rigid when it records none)")
    p.add_argument("-o", "--output", required=True, help=".vti/.nrrd keep the origin; .vol/.VOL: it is printed")

    p = add_command(sub, "compare", "How far a posed volume is from its true shape: Dice, the largest wrong blobs, "
                    "surface distance, tissue (the mannequins' truth: volanim samples NAME --pose).",
                    ("volanim compare arm.vti --sample mannequin --pose arm.trans --tissue",
                     "volanim compare arm-smooth.vti --sample mannequin --pose arm.trans --json"),
                    _compare)
    p.add_argument("ours", help="the posed volume (a reconstruction)")
    p.add_argument("truth", nargs="?", help="the true posed volume on the same voxel grid (samples NAME --pose)")
    p.add_argument("--sample", choices=("mannequin", "mannequin-large", "mannequin-full", "mannequin-colour"),
                   help="make the truth here: this mannequin posed by --pose")
    p.add_argument("--pose", metavar="TRANS", help="the .trans the volume was posed with (joints: where blobs are)")
    p.add_argument("--bones", help="the .bones of --pose (default: the sample's): blobs named by joint and bone")
    p.add_argument("--tissue", action="store_true", help="also compare values (a sampled reconstruction)")
    p.add_argument("--json", action="store_true", help="the figures as JSON")

    p = add_command(sub, "report", "The breakage report of one frame; exit 0 healthy, 1 broken, 2 bad input.",
                    ("volanim report mannequin.0.50.connect arm.trans",
                     "volanim report mannequin.0.50.connect arm.trans --bones mannequin.bones --json",
                     "volanim report mannequin.0.50.connect arm.trans --joints smooth   # the same frame, blended"),
                    _report)
    p.add_argument("connect")
    p.add_argument("trans")
    p.add_argument("--bones", help="name the joints as this .bones file does (default: after their bones)")
    p.add_argument("--source", help="the scan: also how much of its object the rest pose re-grows")
    add_dims(p)
    p.add_argument("--json", action="store_true", help="the report as JSON on stdout")
    add_joints(p, "the .connect's (rigid when it records none)")

    p = add_command(sub, "scan", "Scan frames for breakage, worst first; exit 0 none broken, 1 any broken.",
                    ("volanim scan mannequin.0.50.connect wave/*.trans --top 5",
                     "volanim scan mannequin.0.50.connect wave/*.trans --joints smooth"), _scan)
    p.add_argument("connect")
    p.add_argument("frames", nargs="+", help=".trans files")
    p.add_argument("--bones", help="name the joints as this .bones file does")
    p.add_argument("--top", type=positive_int, default=10, help="frames to list (default 10)")
    p.add_argument("--json", action="store_true", help="every frame's verdict as JSON, worst first")
    add_joints(p, "the .connect's (rigid when it records none)")
