"""Motion subcommands: bvh2trans (motion capture -> one .trans per frame), trans2tskel."""

from __future__ import annotations

import argparse
from pathlib import Path

from volanim_core.io import read_bones, read_connect, read_trans, write_trans, write_tskel
from volanim_core.motion.bvh import read_bvh
from volanim_core.motion.retarget import Retarget, check_mapping_file, format_mapping, read_mapping
from volanim_core.rig.connectivity import Trans
from volanim_core.rig.pose import root_bones
from volanim_core.rig.tskel import connect_to_tskel

from ._common import add_command


def parse_frames(text: str) -> slice:
    """``START:STOP:STEP`` (any part may be empty), frames counted from 0."""
    parts = text.split(":")
    if len(parts) > 3 or not all(p == "" or p.lstrip("-").isdigit() and p.isascii() for p in parts):
        raise argparse.ArgumentTypeError(f"expected START:STOP:STEP, got {text!r}")
    values = [int(p) if p else None for p in parts] + [None] * (3 - len(parts))
    if values[2] is not None and values[2] < 1:
        raise argparse.ArgumentTypeError(f"STEP must be 1 or more, got {values[2]}")
    return slice(*values)


def _bvh2trans(args):
    bones = read_bones(args.bones)
    motion = read_bvh(args.clip)
    mapping = None
    if args.map:
        mapping = read_mapping(args.map)
        check_mapping_file(args.map, mapping, bones, motion)
    retarget = Retarget.build(bones, motion, mapping, up=args.up, forward=args.forward)
    frames = range(motion.frames)[args.frames]
    if not len(frames):
        raise ValueError(f"{args.clip}: --frames {args.frames.start}:{args.frames.stop}:{args.frames.step} "
                         f"selects no frame of {motion.frames}")
    used = {retarget.bones.bones[b].label: motion.names[k] for b, k in retarget.mapping.items()}
    print(format_mapping(used, bones), end="")
    for label, angle in retarget.absorbed_degrees().items():
        print(f"# {label}: rest poses differ by {angle:.1f} degrees (absorbed)")
    out = Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    stem = Path(args.clip).stem
    roots = root_bones(bones)
    mats = retarget.matrices(args.frames)
    conn = read_connect(args.connect) if args.connect else None
    for n, (frame, m) in enumerate(zip(frames, mats)):
        trans = Trans(roots, m)
        write_trans(out / f"{stem}.{frame:04d}.trans", trans)
        if conn is not None:
            write_tskel(out / f"{stem}.{frame:04d}.tskel", connect_to_tskel(conn, trans))
        if n % 100 == 0 or n == len(frames) - 1:
            print(f"\rframe {frame} ({n + 1}/{len(frames)})", end="", flush=True)
    print(f"\nwrote {len(frames)} frames ({motion.fps:.1f} fps in the clip, scale {retarget.scale:.3g} voxels per "
          f"BVH unit) -> {out}")


def _trans2tskel(args):
    conn = read_connect(args.connect)
    out = Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    for path in args.trans:
        target = out / (Path(path).stem + ".tskel")
        write_tskel(target, connect_to_tskel(conn, read_trans(path)))
    print(f"wrote {len(args.trans)} .tskel files -> {out}")


def register(sub) -> None:
    p = add_command(sub, "bvh2trans", "Motion capture onto the bone skeleton: one .trans (and .tskel) per frame.",
                    "volanim bvh2trans walk.bvh --bones mannequin.bones --frames 0:200:10 -o walk/", _bvh2trans)
    p.add_argument("clip", help="a .bvh motion-capture clip")
    p.add_argument("--bones", required=True, help="our .bones file")
    p.add_argument("--map", help="BONE BVH_JOINT per line (default: suggested from the names; printed)")
    p.add_argument("--frames", type=parse_frames, default=slice(None), metavar="START:STOP:STEP")
    p.add_argument("--up", default="y", help="the clip's up axis (default y; e.g. z, -y)")
    p.add_argument("--forward", default="z", help="the way the clip's figure faces at rest (default z)")
    p.add_argument("--connect", help="also write each frame's .tskel for this .connect")
    p.add_argument("-o", "--output", required=True, help="folder for NAME.0000.trans, ...")

    p = add_command(sub, "trans2tskel", "A .connect plus many .trans frames -> one .tskel each.",
                    "volanim trans2tskel mannequin.0.50.connect walk/*.trans -o walk/", _trans2tskel)
    p.add_argument("connect")
    p.add_argument("trans", nargs="+")
    p.add_argument("-o", "--output", required=True, help="folder for the .tskel files")
