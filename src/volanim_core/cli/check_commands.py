"""The studio's tools for scripts: mirror, keys, report, scan.

Each is one library function (``volanim_core.mirror``, ``.keys``, ``.report``,
``.scan``) with the same options; this module only reads and writes files.
``report`` and ``scan`` exit 0 when healthy, 1 when broken, 2 on bad input.
"""

from __future__ import annotations

import json
from pathlib import Path

from volanim_core.io import read_bones, read_connect, read_trans, write_connect
from volanim_core.progress import TextProgress

from ._common import (
    add_command,
    add_dims,
    add_joints,
    finite_float,
    joints_of,
    load_source,
    positive_float,
    positive_int,
)


def _mirror(args):
    from volanim_core.rig.symmetry import mirror

    conn = read_connect(args.connect)
    out, rep = mirror(conn, read_bones(args.bones), side=args.side, only=args.bone, plane=args.plane)
    write_connect(args.output, out, thinness=conn.thinness_threshold)
    print(f"{rep} -> {args.output}")


def _keys(args):
    from volanim_core.motion.frame_files import write_frames
    from volanim_core.motion.keyframes import keys
    from volanim_core.motion.keys_files import read_keys

    bones = read_bones(args.bones).on_cubes()
    k = read_keys(args.keys, bones)
    key_fps = k.fps or 24.0
    ease = args.ease if args.ease is not None else bool(k.ease)
    mats = keys(k.keys, bones, length=args.length, fps=args.fps, key_fps=key_fps, key_length=k.length, ease=ease)
    conn = read_connect(args.connect) if args.connect else None
    write_frames(args.output, args.name or Path(args.keys).stem, bones, mats, range(len(mats)), connect=conn,
                 progress=TextProgress(f"writing {len(mats)} frames"))
    print(f"{len(k.keys)} keys -> {len(mats)} frames at {args.fps or key_fps:g} fps"
          f"{' (eased)' if ease else ''} -> {args.output}")


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
    from volanim_core.motion.frame_files import frame_number
    from volanim_core.reconstruct.checks import scan, scan_json
    from volanim_core.reconstruct.scan import scan_summary

    conn = joints_of(args, read_connect(args.connect))
    frames = [read_trans(p) for p in args.frames]
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
                  + (f" near {v.worst_joint}" if v.worst_joint else "") + (": BROKEN" if v.broken else ""))
    return 1 if bad else 0


def register(sub) -> None:
    p = add_command(sub, "mirror", "Copy one side's attachments to the twin bones (the studio's Mirror connectivity).",
                    "volanim mirror mannequin.0.50.connect --bones mannequin.bones -o mirrored.connect", _mirror)
    p.add_argument("connect")
    p.add_argument("--bones", required=True, help="the .bones file (joint names L_/R_ or Left/Right)")
    p.add_argument("--side", choices=("L", "R"), default="L", help="copy this side to the other (default L)")
    p.add_argument("--bone", action="append", metavar="NAME", help="only this bone (repeatable)")
    p.add_argument("--plane", type=finite_float, metavar="X",
                   help="x of the mirror plane in voxels (default: midway between the L_/R_ joints)")
    p.add_argument("-o", "--output", required=True)

    p = add_command(sub, "keys", "Keyframes (a .keys file) -> one .trans per frame, slerped (the studio's timeline).",
                    ("volanim keys mannequin.keys --bones mannequin.bones -o wave/",
                     "volanim keys mannequin.keys --bones mannequin.bones --fps 12 --no-ease -o wave12/  # 13 frames"),
                    _keys)
    p.add_argument("keys", help="FRAME BONE RX RY RZ [TX TY TZ] per line (docs/formats.md, 'Keys')")
    p.add_argument("--bones", required=True)
    p.add_argument("--length", type=positive_int, help="frames to write (default: the file's, else to the last key)")
    p.add_argument("--fps", type=positive_float, help="frames per second to write (default: the file's, else 24)")
    p.add_argument("--ease", action="store_true", default=None, help="slow in and out at each key")
    p.add_argument("--no-ease", dest="ease", action="store_false", help="constant speed (over the file's 'ease on')")
    p.add_argument("--connect", help="also write each frame's .tskel for this .connect")
    p.add_argument("--name", help="file name stem (default: the keys file's)")
    p.add_argument("-o", "--output", required=True, help="folder for NAME.0000.trans, ...")

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
