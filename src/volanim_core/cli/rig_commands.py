"""Auto-rig from the command line: ``volanim autorig`` (``volanim_core.autorig``).

    .mskel --autorig--> .bones (named by a template, or chains by position)
           --connect (pieces: each piece of the scan, or of the skeleton's own balls, to its bones)--> .connect
"""

from __future__ import annotations

import time

import numpy as np

from volanim_core.io import read_skeleton, skeleton_at, write_bones, write_connect
from volanim_core.progress import TextProgress

from ._common import add_command, add_dims, finite_float, parse_range, positive_int


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


def _mask(args, skel):
    """The object on the skeleton's grid: the scan's, segmented as skeletonize does, or else the union
    of the skeleton's own balls (the rest pose it re-grows)."""
    if args.volume:
        from .skeleton_commands import mask_like_skeleton

        return mask_like_skeleton(args, skel)
    from volanim_core.rig.curve_skeleton import balls

    return balls(skel)


def register(sub) -> None:
    from volanim_core.rig.attach import METHODS
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
