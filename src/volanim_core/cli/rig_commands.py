"""The rig's subcommands: autorig, connect, pose, straighten, connect2tskel, connect2identitytskel,
sorttskel, mirror -- proposing bones, attaching points to them, and posing them one frame at a time."""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

from volanim_core.io import (
    read_bones,
    read_connect,
    read_skeleton,
    read_trans,
    read_tskel,
    skeleton_at,
    write_bones,
    write_connect,
    write_trans,
    write_tskel,
)
from volanim_core.progress import TextProgress
from volanim_core.rig.attach import METHODS
from volanim_core.rig.connectivity import Trans
from volanim_core.rig.pose import pose_matrices, root_bones
from volanim_core.rig.skinning import transform_table
from volanim_core.rig.tskel_tools import connect_to_tskel, identity_tskel, sort_tskel

from ._common import (
    add_command,
    add_dims,
    add_joints,
    finite_float,
    joints_of,
    parse_range,
    positive_int,
)


def _autorig(args):
    from volanim_core.rig.attach import connect
    from volanim_core.rig.autorig import autorig

    skel = skeleton_at(read_skeleton(args.mskel), args.thinness, args.mskel)
    t0 = time.perf_counter()
    proposal = autorig(skel, template=args.template, bones=args.bones, progress=TextProgress("proposing bones"))
    write_bones(args.output, proposal.bones)
    print(f"{proposal} in {time.perf_counter() - t0:.2f} s -> {args.output}")
    if args.connect:
        mask = _mask(args, skel)
        conn, report = connect(skel, proposal.bones, method=args.method, mask=mask,
                               progress=TextProgress(f"attaching {len(skel)} points"))
        write_connect(args.connect, conn, thinness=args.thinness)
        counts = np.bincount(conn.bone, minlength=len(conn.bones))
        print(f"{report} ({args.method}); fewest points on one bone: {counts.min()} -> {args.connect}")
        if args.ownership:  # as volanim connect: without it the frames re-grow the thesis's spheres
            _write_ownership(args.connect, conn, mask if args.volume else None, hang=args.hang_on)


def _mask(args, skel):
    """The object on the skeleton's grid: the scan's, segmented as skeletonize does, or else the union
    of the skeleton's own balls (the rest pose it re-grows)."""
    if args.volume:
        from .skeleton_commands import mask_like_skeleton

        return mask_like_skeleton(args, skel)
    from volanim_core.rig.curve_skeleton import balls

    return balls(skel)


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
    if args.ownership:
        _write_ownership(args.output, conn, mask, (lambda own: _fixed(args, conn.with_ownership(own)))
                         if args.fix_lumps else None, hang=args.hang_on)


def _write_ownership(connect_path, conn, mask, fix=None, hang=False) -> None:
    """The rig's ownership beside the .connect (rig/ownership.py): of the scan's object with --volume (the
    rest pose is then the segmentation voxel for voxel), else of the body the skeleton's spheres re-grow at
    rest (the thesis's rest pose, which the identity frame then gives back unchanged); ``fix(own)``: the
    ownership with the lumps of test poses fixed; ``hang``: flesh its chain cannot reach given to the flesh
    it hangs from (rig/reach.hang_on), said by bone; else it is warned about."""
    from volanim_core.io.ownership_files import ownership_path, write_ownership
    from volanim_core.rig.ownership import ownership
    from volanim_core.rig.reach import LEAST, hang_on

    t0 = time.perf_counter()
    body = mask if mask is not None else _sphere_body(conn)
    own = ownership(body, conn)
    path = ownership_path(connect_path)
    of = "the scan's object" if mask is not None else "the body its spheres re-grow (give --volume for the scan's own)"
    if fix is not None:
        own = fix(own)
    moved = []
    if hang:
        own, moved = hang_on(own)
    write_ownership(path, own)
    print(f"ownership of {int(own.mask.sum())} voxels ({of}) in {time.perf_counter() - t0:.1f} s -> {path}")
    counts = own.counts()
    for a, b, n in moved:
        if n > LEAST * (n + counts[a]):  # as the warning: specks a repaint is not worth go unsaid
            print(f"  {own.bones[a].label}: {n:,} voxels that touched the body only through another limb's flesh "
                  f"given to {own.bones[b].label}, the flesh they hang from ({int(counts[a]):,} left: move the "
                  "bone onto its flesh, or repaint)")
    _warn_out_of_reach(own, hint=not hang)


def _warn_out_of_reach(own, hint: bool) -> None:
    """Flesh that would come off when its bone moves (rig/reach.py), by bone, on stderr; ``hint``: and that
    --hang-on would give it to the flesh it hangs from."""
    from volanim_core.rig.reach import reach_notes

    notes = reach_notes(own)
    for line in notes:
        print(f"warning: {line}", file=sys.stderr)
    if notes and hint:
        print("warning: --hang-on gives such flesh to the limb it hangs from", file=sys.stderr)


def _fixed(args, conn):
    """The ownership with the lumps of the ``--fix-lumps`` poses given back to the bones they belong to."""
    from volanim_core.reconstruct.checks import fix_lumps

    bones = read_bones(args.bones)
    frames = [read_trans(p).on_grid(conn.geometry) for p in args.fix_lumps]
    own, fixes = fix_lumps(conn, frames, bones.on_grid(conn.geometry),
                           progress=TextProgress(f"fixing lumps over {len(frames)} poses"))
    for k, lump, n in fixes:
        print(f"  {args.fix_lumps[k]}: lump of {lump.voxels:,} voxels near {lump.near}: {n:,} rest voxels of "
              f"{lump.carrier} given to {lump.belongs_to}")
    print(f"{len(fixes)} lump(s) fixed over {len(frames)} pose(s)" if fixes else
          f"no lump in {len(frames)} pose(s): the ownership is as made")
    return own


def _sphere_body(conn) -> np.ndarray:
    """The body the connectivity's spheres re-grow at rest, on the skeleton's grid from voxel 0."""
    from volanim_core.reconstruct.engine import reconstruct
    from volanim_core.volume import Bounds

    rest = reconstruct(identity_tskel(conn), mode="binary", method="spheres", padding=1)
    lo = np.asarray(rest.origin)
    if (lo < 0).any():  # spheres reaching below voxel 0: the grid starts there, the body is cut at it
        rest = reconstruct(identity_tskel(conn), mode="binary", method="spheres",
                           bounds=Bounds((0, 0, 0), tuple(int(v) for v in rest.bounds.hi)))
        lo = np.asarray(rest.origin)
    body = np.zeros(tuple(lo + rest.volume.shape), bool)
    body[lo[0]:, lo[1]:, lo[2]:] = rest.volume > 0
    return body


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


def _mirror(args):
    from volanim_core.rig.symmetry import mirror

    conn = read_connect(args.connect)
    out, rep = mirror(conn, read_bones(args.bones), side=args.side, only=args.bone, plane=args.plane)
    write_connect(args.output, out, thinness=conn.thinness_threshold)
    print(f"{rep} -> {args.output}")


def register(sub) -> None:
    from volanim_core.rig.autorig import TEMPLATES

    p = add_command(sub, "autorig", "Propose a bone skeleton from the volume's own skeleton -> .bones (and .connect).",
                    ("volanim autorig mannequin.mskel --template humanoid -o proposed.bones --connect proposed.connect",
                     "volanim autorig mannequin.mskel --template none --bones 12 -o chains.bones"),
                    _autorig)
    p.add_argument("mskel", metavar="SKELETON", help="the skeleton: .mskel, or a .skel (one resolution)")
    p.add_argument("--thinness", type=finite_float, help="only points with thinness >= this (default: all)")
    p.add_argument("--template", choices=TEMPLATES, default="auto",
                   help="humanoid (the mannequin's names), quadruped, none (chains named by position) or auto: "
                        "the template that fits, else none (default)")
    p.add_argument("--bones", type=positive_int, metavar="N",
                   help="with --template none: exactly N bones, split where the branches bend most")
    p.add_argument("-o", "--output", required=True, help="the proposed .bones")
    p.add_argument("--connect", metavar="CONNECT", help="also attach every point -> this .connect")
    p.add_argument("--method", choices=METHODS, default="pieces",
                   help="how --connect attaches (default pieces: each piece of the body to the bones lying in it, "
                        "else the nearest; `volanim connect --help` lists the others)")
    p.add_argument("--volume", help="with --connect: the scan whose pieces (or, with --method path, whose inside) "
                                    "the attachment follows (default: the skeleton's own balls)")
    add_dims(p)
    p.add_argument("--threshold", type=parse_range, metavar="LO[:HI]", help="segment the scan as skeletonize did")
    p.add_argument("--fill-cavities", action="store_true", help="fill enclosed background, as skeletonize did")
    p.add_argument("--no-ownership", dest="ownership", action="store_false",
                   help="with --connect: write no NAME.owners.nrrd beside it (frames then re-grow the thesis's "
                        "spheres)")
    p.add_argument("--hang-on", action=argparse.BooleanOptionalAction, default=True,
                   help="with --connect: flesh of a proposed bone that touches the body only through another "
                        "limb's, and would come off when the bone moves, goes to the flesh it hangs from "
                        "(default; --no-hang-on keeps it, with a warning)")

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
    p.add_argument("--fix-lumps", nargs="+", metavar="TRANS",
                   help="test poses (.trans): each lump their report finds is given back to the bone it belongs to "
                        "in the ownership (the studio's Fix, headless)")
    p.add_argument("--no-ownership", dest="ownership", action="store_false",
                   help="write no NAME.owners.nrrd (frames then re-grow the thesis's spheres)")
    p.add_argument("--hang-on", action="store_true",
                   help="flesh of a bone that touches the body only through another limb's (warned about: it "
                        "comes off when the bone moves) goes to the flesh it hangs from")
    p.add_argument("-o", "--output", required=True,
                   help="the .connect; NAME.owners.nrrd beside it holds which bone owns each rest voxel")

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

    p = add_command(sub, "mirror", "Copy one side's attachments to the twin bones (the studio's Mirror connectivity).",
                    "volanim mirror mannequin.0.50.connect --bones mannequin.bones -o mirrored.connect", _mirror)
    p.add_argument("connect")
    p.add_argument("--bones", required=True, help="the .bones file (joint names L_/R_ or Left/Right)")
    p.add_argument("--side", choices=("L", "R"), default="L", help="copy this side to the other (default L)")
    p.add_argument("--bone", action="append", metavar="NAME", help="only this bone (repeatable)")
    p.add_argument("--plane", type=finite_float, metavar="X",
                   help="x of the mirror plane in voxels (default: midway between the L_/R_ joints)")
    p.add_argument("-o", "--output", required=True)
