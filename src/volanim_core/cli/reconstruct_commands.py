"""Posing and reconstruction subcommands: connect, pose, connect2tskel,
connect2identitytskel, sorttskel, bounds, reconstruct, compare."""

from __future__ import annotations

import argparse

import numpy as np

from volanim_core.io import (
    read_bones,
    read_connect,
    read_skeleton,
    read_trans,
    read_tskel,
    skeleton_at,
    write_connect,
    write_output,
    write_trans,
    write_tskel,
)
from volanim_core.progress import TextProgress
from volanim_core.reconstruct.engine import MODES, grid_bounds, reconstruct
from volanim_core.rig.attach import METHODS
from volanim_core.rig.connectivity import Trans
from volanim_core.rig.pose import pose_matrices, root_bones
from volanim_core.rig.skinning import transform_table
from volanim_core.rig.tskel_tools import check_root_order, connect_to_tskel, identity_tskel, sort_tskel

from ._common import (
    add_command,
    add_dims,
    add_joints,
    ascii_int,
    bounds_arg,
    finite_float,
    joints_of,
    load_source,
    parse_range,
)


def _connect(args):
    from volanim_core.rig.attach import connect

    skel = skeleton_at(read_skeleton(args.mskel), args.thinness, args.mskel)
    mask = None
    if args.volume:
        from .skeleton_commands import mask_like_skeleton

        mask = mask_like_skeleton(args, skel)
    conn, report = connect(skel, read_bones(args.bones).on_grid(skel.geometry), method=args.method, mask=mask,
                           progress=TextProgress(f"attaching {len(skel)} points"))
    write_connect(args.output, conn, thinness=args.thinness)
    counts = np.bincount(conn.bone, minlength=len(conn.bones))
    print(f"{report} ({args.method}); {len(conn.bones)} bones, fewest points on one: {counts.min()} -> {args.output}")


def parse_rotation(text: str) -> tuple[str, tuple[float, float, float]]:
    """``BONE=RX,RY,RZ`` (degrees)."""
    name, sep, angles = text.partition("=")
    try:
        values = tuple(finite_float(v) for v in angles.split(","))
    except argparse.ArgumentTypeError:
        values = ()
    if not sep or len(values) != 3:
        raise argparse.ArgumentTypeError(f"expected BONE=RX,RY,RZ in degrees, got {text!r}")
    return name, values


def _pose(args):
    bones = read_bones(args.bones).on_cubes()
    rotations = {}
    for name, angles in args.rotate or []:
        try:
            bones.index(name)
        except KeyError:
            raise ValueError(f"{args.bones}: no bone named {name!r}; bones are "
                             + ", ".join(b.label for b in bones.bones)) from None
        rotations[name] = angles
    trans = Trans(root_bones(bones), pose_matrices(bones, rotations), bones.geometry)
    write_trans(args.output, trans)
    print(f"posed {len(rotations)} of {len(bones)} bones (children follow) -> {args.output}")


def _straighten(args):
    from volanim_core.rig.straighten import straighten

    bones = read_bones(args.bones).on_cubes()
    first, last = args.chain if args.chain else (None, None)
    matrices, axis, ids = straighten(bones, first, last)
    write_trans(args.output, Trans(root_bones(bones), matrices, bones.geometry))
    ends = bones.bones[ids[0]], bones.bones[ids[-1]]
    print(f"straightened {len(ids)} bones ({ends[0].label} .. {ends[1].label}) along "
          f"({', '.join(f'{v:.3f}' for v in axis)}) from joint {ends[0].proximal} -> {args.output}")


def _connect2tskel(args):
    t = connect_to_tskel(joints_of(args, read_connect(args.connect)), read_trans(args.trans))
    transform_table(t)  # a frame smooth joints cannot blend (a sheared bone) is refused now, not at reconstruct
    write_tskel(args.output, t)
    print(f"{len(t)} points, {len(t.bones)} bones, {t.joints.text()} joints -> {args.output}")


def _connect2identity(args):
    t = identity_tskel(read_connect(args.connect))
    write_tskel(args.output, t)
    print(f"{len(t)} points, {len(t.bones)} bones, identity matrices -> {args.output}")


def _sorttskel(args):
    write_tskel(args.output, sort_tskel(read_tskel(args.tskel)))
    print(f"sorted -> {args.output}")


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
                    bounds=bounds, padding=args.padding, threads=args.threads, progress=bar)
    output, note = write_output(args.output, r.volume, r.geometry, args.mode)
    if note:
        print(f"note: {note}")
    s = r.stats
    print(f"{s['spheres']} spheres -> {s['filled']} voxels filled in {s['seconds']:.3f} s "
          f"(overdraw {s['overdraw']:.1f}); grid {r.volume.shape[0]}x{r.volume.shape[1]}x{r.volume.shape[2]}, "
          f"origin {r.origin[0]} {r.origin[1]} {r.origin[2]} -> {output}")
    if s["clipped"]:
        # what the user loses is body voxels, not sphere coverage (overlapping spheres count many times)
        try:
            whole = reconstruct(t, mode="binary", padding=args.padding, threads=args.threads)
        except ValueError:  # the unbounded grid is too large to make: say what is known
            print(f"clipped: the spheres reach outside the given bounds ({s['clipped']:,} sphere voxels, "
                  "overlaps counted; the whole body's grid is too large to count the voxels lost)")
        else:
            lost = whole.stats["filled"] - s["filled"]
            print(f"clipped: {lost:,} voxels of the body lie outside the given bounds and were not written "
                  f"({100 * lost / max(whole.stats['filled'], 1):.2f} % of {whole.stats['filled']:,})")
    if args.mode == "hotspot":
        print(f"hotspot: max {s['hotspot_max']} spheres on one voxel, mean {s['hotspot_mean']:.2f}")
    if args.loss:
        rest = reconstruct(identity_tskel(t.connectivity), mode="binary", threads=args.threads)
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
        check_root_order(root_bones(bones), trans.bones)
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


def register(sub) -> None:
    p = add_command(sub, "connect", "Attach every skeleton point to a bone -> .connect (the studio's auto-connect).",
                    ("volanim connect mannequin.mskel mannequin.bones --thinness 0.5 -o mannequin.0.50.connect",
                     "volanim connect mannequin.mskel mannequin.bones --method path --volume mannequin.VOL "
                     "-o mannequin.path.connect",
                     "volanim connect mannequin.mskel mannequin.bones --thinness 0.5 --method fitted "
                     "-o mannequin.fitted.connect"),
                    _connect)
    p.add_argument("mskel", metavar="SKELETON", help="the skeleton: .mskel, or a .skel (one resolution)")
    p.add_argument("bones")
    p.add_argument("--thinness", type=finite_float, help="only points with thinness >= this")
    p.add_argument("--method", choices=METHODS, default="nearest",
                   help="nearest segment (default); path: the nearest bone reachable by a straight path inside "
                        "the object; path-or-nearest: path, else nearest; geodesic: along the skeleton inside "
                        "the object (these three need --volume); fitted: nearest, then flesh a limb's own tube "
                        "cannot hold (the armpit, the groin) to the bone above")
    p.add_argument("--volume", help="the scan the skeleton was made from (segmented like skeletonize)")
    add_dims(p)
    p.add_argument("--threshold", type=parse_range, metavar="LO[:HI]",
                   help="object = LO <= v <= HI (default: every non-zero voxel)")
    p.add_argument("--fill-cavities", action="store_true", help="fill enclosed background first")
    p.add_argument("-o", "--output", required=True)

    p = add_command(sub, "pose", "Write a .trans frame: rotate bones about their proximal joints (FK).",
                    "volanim pose mannequin.bones --rotate L_UPPERARM=0,-45,0 -o arm.trans", _pose)
    p.add_argument("bones", help=".bones file")
    p.add_argument("--rotate", action="append", type=parse_rotation, metavar="BONE=RX,RY,RZ",
                   help="Euler angles in degrees about x, y, z (repeatable)")
    p.add_argument("-o", "--output", required=True)

    p = add_command(sub, "straighten", "Write a .trans frame that lays a chain of bones straight along its principal "
                    "axis, each bone keeping its length, the first joint in place (the thesis's colon uncoiled, "
                    "section 5.3).",
                    ("volanim straighten curved-tube.bones -o straight.trans",
                     "volanim straighten mannequin.bones --chain L_UPPERARM L_HAND -o arm-straight.trans"), _straighten)
    p.add_argument("bones", help=".bones file")
    p.add_argument("--chain", nargs=2, metavar=("FIRST", "LAST"),
                   help="the chain's first and last bones, each the child of the one before (default: the whole "
                        "skeleton, when it is one chain)")
    p.add_argument("-o", "--output", required=True)

    p = add_command(sub, "connect2tskel", "A .connect plus one .trans frame -> .tskel (root orders must match).",
                    ("volanim connect2tskel mannequin.0.50.connect arm.trans -o arm.tskel",
                     "volanim connect2tskel mannequin.0.50.connect arm.trans --joints smooth -o arm-smooth.tskel"),
                    _connect2tskel)
    p.add_argument("connect")
    p.add_argument("trans")
    add_joints(p, "the .connect's (rigid when it records none)")
    p.add_argument("-o", "--output", required=True)

    p = add_command(sub, "connect2identitytskel", "The identity (rest) .tskel of a .connect.",
                    "volanim connect2identitytskel mannequin.0.50.connect -o rest.tskel", _connect2identity)
    p.add_argument("connect")
    p.add_argument("-o", "--output", required=True)

    p = add_command(sub, "sorttskel", "Sort each bone's points by decreasing DT.",
                    "volanim sorttskel arm.tskel -o arm.sorted.tskel", _sorttskel)
    p.add_argument("tskel")
    p.add_argument("-o", "--output", required=True)

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
    p.add_argument("--sample", choices=("mannequin", "mannequin-large", "mannequin-colour"),
                   help="make the truth here: this mannequin posed by --pose")
    p.add_argument("--pose", metavar="TRANS", help="the .trans the volume was posed with (joints: where blobs are)")
    p.add_argument("--bones", help="the .bones of --pose (default: the sample's): blobs named by joint and bone")
    p.add_argument("--tissue", action="store_true", help="also compare values (a sampled reconstruction)")
    p.add_argument("--json", action="store_true", help="the figures as JSON")
