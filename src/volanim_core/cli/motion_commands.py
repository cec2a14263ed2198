"""Motion subcommands: keys (keyframes -> one .trans per frame, the studio's timeline), bvh2trans (motion
capture -> one .trans per frame), export-gltf (the posed body as an animated glTF), trans2tskel, trans2bvh
(back to an animation package), trans2positions and positions2trans (joint positions per frame, as a CSV)."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from volanim_core.errors import FormatError
from volanim_core.io import read_bones, read_connect, read_trans, write_tskel
from volanim_core.io.clip_files import clip_animations, read_clip
from volanim_core.io.frame_files import write_frames
from volanim_core.io.mapping_files import format_mapping, read_mapping
from volanim_core.motion.plausible import check_clip, refuse_failed
from volanim_core.motion.retarget import Retarget, check_mapping_file
from volanim_core.progress import TextProgress
from volanim_core.rig.tskel_tools import connect_to_tskel

from ._common import (
    add_command,
    positive_float,
    positive_int,
)


def _keys(args):
    from volanim_core.io.frame_files import write_frames
    from volanim_core.io.keys_files import read_keys
    from volanim_core.motion.keyframes import keys

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


def parse_frames(text: str) -> slice:
    """``START:STOP:STEP`` (any part may be empty), frames counted from 0."""
    parts = text.split(":")
    if len(parts) > 3 or not all(p == "" or p.lstrip("-").isdigit() and p.isascii() for p in parts):
        raise argparse.ArgumentTypeError(f"expected START:STOP:STEP, got {text!r}")
    values = [int(p) if p else None for p in parts] + [None] * (3 - len(parts))
    if values[2] is not None and values[2] < 1:
        raise argparse.ArgumentTypeError(f"STEP must be 1 or more, got {values[2]}")
    return slice(*values)


def axis_or_auto(text: str) -> str:
    """``auto`` or a signed axis (``z``, ``-y``), checked where it is typed."""
    from volanim_core.motion.retarget import axis_vector

    if text.strip().lower() == "auto":
        return "auto"
    try:
        axis_vector(text)
    except ValueError as e:
        raise argparse.ArgumentTypeError(str(e)) from None
    return text.strip().lower()


def _bvh2trans(args):
    bones, motion, retarget, frames = _retargeted(args)
    conn = read_connect(args.connect) if args.connect else None
    mats = retarget.matrices(args.frames)
    write_frames(args.output, Path(args.clip).stem, bones, mats, frames, connect=conn,
                 progress=TextProgress(f"writing {len(frames)} frames"))
    print(f"wrote {len(frames)} frames ({motion.fps:.1f} fps in the clip; up {retarget.up}, forward "
          f"{retarget.forward}; scale {retarget.scale:.3g} voxels per BVH unit) -> {args.output}")


def _retargeted(args):
    """``args.clip`` onto ``args.bones`` as bvh2trans does it, the mapping and checks printed (refused when
    they fail, unless ``--no-check``): ``(bones, motion, retarget, frames)``."""
    bones = read_bones(args.bones).on_cubes()
    motion = read_clip(args.clip, args.animation)
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
    report = retarget.report
    if motion.animation is not None:
        names = clip_animations(args.clip)
        print(f"# animation: {motion.animation!r}" + (f" (the file has {', '.join(map(repr, names))}: --animation "
                                                     "NAME picks another)" if len(names) > 1 else ""))
    print(f"# the clip's figure: {report['kind'].kind}: {report['kind'].reason}")
    print(f"# naming scheme: {report['scheme']}; each line says what placed it (name, shape or both)")
    print(format_mapping(used, bones, report["how"]), end="")
    for note in report["notes"]:
        print(f"# note: {note}")
    if report.get("figure") is not None:
        print("# rest: each bone keeps its own (a creature's build is not the clip's); the clip's motion "
              "from its rest is applied")
    else:
        for label, angle in retarget.absorbed_degrees().items():
            print(f"# {label}: rest poses differ by {angle:.1f} degrees (absorbed)")
    print(f"# axes: up {retarget.up}, forward {retarget.forward} ({report['axes']})")
    print(f"# units: {report['units']}; scale {retarget.scale:.3g} voxels per BVH unit ({report['scale']})")
    checks, sampled = check_clip(retarget)
    for c in checks:
        print(f"# {c.line(sampled)}")
    if not args.no_check:
        refuse_failed(args.clip, checks, used)
    return bones, motion, retarget, frames


def _export_gltf(args):
    from volanim_core.io.clip_files import is_clip
    from volanim_core.io.frame_files import read_frames
    from volanim_core.render.skinned_body import export_gltf
    from volanim_core.rig.pose import root_bones
    from volanim_core.rig.tskel_tools import check_root_order

    conn = read_connect(args.connect)
    if len(args.clip) == 1 and is_clip(args.clip[0]):
        args.clip = args.clip[0]
        bones, motion, retarget, frames = _retargeted(args)
        mats, fps = retarget.matrices(args.frames), args.fps or motion.fps
        name = motion.animation or Path(args.clip).stem
    else:
        bones = read_bones(args.bones).on_cubes()
        mats, paths = read_frames(args.clip, bones, progress=TextProgress("reading frames"))
        mats, fps, name = mats[args.frames], args.fps or 24.0, Path(args.clip[0]).stem.split(".")[0]
        if not len(mats):
            raise ValueError(f"--frames selects no frame of the {len(paths)} .trans files")
    try:
        check_root_order(conn.bones, root_bones(bones), ".bones", ".connect")
    except ValueError as exc:
        raise FormatError(args.connect, str(exc)) from None
    held = export_gltf(conn, mats, fps, args.output, name, args.triangles, args.blend,
                       TextProgress("exporting glTF"))
    how = "its ownership" if conn.ownership is not None else "the rest spheres (the rig has no ownership)"
    print(f"wrote {args.output}: the body ({held['triangles']:,} triangles, {held['vertices']:,} vertices) skinned "
          f"to {held['joints']} joints by {how}, {held['frames']} frames at {fps:g} fps")


def _trans2tskel(args):
    conn = read_connect(args.connect)
    out = Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    for path in args.trans:
        target = out / (Path(path).stem + ".tskel")
        write_tskel(target, connect_to_tskel(conn, read_trans(path)))
    print(f"wrote {len(args.trans)} .tskel files -> {out}")


def _bones_and_frames(args):
    """``args.bones`` and the matrices of ``args.trans`` (files or a folder), in frame-number order."""
    from volanim_core.io.frame_files import read_frames

    bones = read_bones(args.bones).on_cubes()
    bar = TextProgress("reading frames")
    out = read_frames(args.trans, bones, progress=bar)
    bar.close()
    return (bones, *out)


def _trans2bvh(args):
    from volanim_core.io.bvh_export import write_bvh

    bones, mats, paths = _bones_and_frames(args)
    worst = write_bvh(args.output, bones, mats, args.fps, args.scale)
    print(f"wrote {args.output}: {len(bones)} bones, {len(paths)} frames at {args.fps:g} fps, z up, "
          f"{args.scale:g} BVH units per voxel")
    if worst > 0.01:
        print(f"note: a child bone moved apart from its parent by up to {worst:.2f} voxels in these frames; BVH moves "
              "children only by rotation, so the clip keeps them joined")


def _trans2positions(args):
    from volanim_core.io.frame_files import frame_number
    from volanim_core.io.positions_files import write_positions
    from volanim_core.rig.pose import joint_positions

    bones, mats, paths = _bones_and_frames(args)
    names, positions = list(bones.joints), joint_positions(bones, mats)
    numbers = [frame_number(p) if frame_number(p) is not None else i for i, p in enumerate(paths)]
    write_positions(args.output, numbers, names, positions)
    print(f"wrote {args.output}: {len(names)} joints in {len(paths)} frames")


def _positions2trans(args):
    from volanim_core.motion.positions import solve

    bones = read_bones(args.bones).on_cubes()
    names = list(bones.joints)
    numbers, positions, what = _joint_positions(args, bones, names)
    have = [n for j, n in enumerate(names) if not np.isnan(positions[:, j]).all()]
    missing = [n for n in names if n not in have]
    print(f"{len(numbers)} frames, {len(have)} of {len(names)} joints in {args.positions}{what}"
          + (f"; no data for {', '.join(missing)} (their bones follow their parents)" if missing else ""))
    if not any(b.proximal in have and b.distal in have for b in bones.bones):  # one marker: nothing turns
        raise FormatError(args.positions, f"no bone has both of its joints in the data ({', '.join(have) or 'none'} "
                                          "found): no bone can be turned; give --map, or data with more joints")
    bar = TextProgress("solving bones")
    mats = solve(bones, positions, names, progress=bar)
    bar.close()
    conn = read_connect(args.connect) if args.connect else None
    write_frames(args.output, Path(args.positions).stem, bones, mats, numbers, connect=conn,
                 progress=TextProgress(f"writing {len(numbers)} frames"))
    print(f"wrote {len(numbers)} frames -> {args.output}")


def _joint_positions(args, bones, names):
    """(frame numbers, (F, J, 3) in the bones' space, what was read and fitted) from a CSV or a C3D file."""
    from volanim_core.io.marker_files import read_c3d, read_marker_map
    from volanim_core.io.positions_files import read_positions
    from volanim_core.motion import markers

    mapping = read_marker_map(args.map) if args.map else None
    c3d = Path(args.positions).suffix.lower() == ".c3d"
    if c3d:
        labels, data, rate, unit = read_c3d(args.positions)
        numbers = np.arange(len(data))
        what = f" ({len(labels)} markers at {rate:g} Hz, in {unit or 'unnamed units'})"
    else:
        labels = sorted({m for ms in mapping.values() for m in ms}) if mapping else names
        numbers, data = read_positions(args.positions, labels)
        what = ""
    if mapping is None:
        mapping = markers.default_map(labels, names)
        if not mapping:
            raise FormatError(args.positions, f"no marker is named after a joint of {args.bones}: give --map "
                              f"(JOINT MARKER [MARKER ...] per line); its {markers.listed(labels)}")
    positions = markers.joints_from_markers(labels, data, mapping, names, args.map or args.positions)
    numbers, positions = numbers[args.frames], positions[args.frames]
    if not len(numbers):
        raise FormatError(args.positions, f"--frames selects none of its {len(data)} frames")
    auto = "auto" if c3d else None  # a CSV is in the bones' space already (as trans2positions writes it)
    up, forward = args.up or auto, args.forward or auto
    scale = args.scale if args.scale is not None else (None if c3d else 1.0)
    if up is None and forward is None:
        return numbers, positions * scale, what
    fitted = markers.fit(bones, positions, names, up or "auto", forward or "auto", scale)
    print(f"data up {fitted.up}, forward {fitted.forward}, {fitted.scale:.4g} voxels per unit ({fitted.how})")
    return numbers, fitted.apply(positions), what


def _bones_and_frames_args(p) -> None:
    p.add_argument("bones", help="our .bones file")
    p.add_argument("trans", nargs="+", help=".trans files (numbered: taken in order), or a folder of them")


def register(sub) -> None:
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

    p = add_command(sub, "bvh2trans", "Motion capture onto the bone skeleton: one .trans (and .tskel) per frame.",
                    "volanim bvh2trans walk.bvh --bones mannequin.bones --frames 0:200:10 -o walk/", _bvh2trans)
    p.add_argument("clip", help="a motion clip: .bvh, glTF 2.0 (.glb, .gltf, .vrma) or .fbx")
    p.add_argument("--animation",
                   help="glTF, FBX: which of the file's animations, by name or number (default: the first)")
    p.add_argument("--bones", required=True, help="our .bones file")
    p.add_argument("--map", help="BONE BVH_JOINT per line (default: suggested from the names; printed)")
    p.add_argument("--frames", type=parse_frames, default=slice(None), metavar="START:STOP:STEP")
    p.add_argument("--up", type=axis_or_auto, default="auto",
                   help="the clip's up axis: x, y, z, -x, ... (default: detected from the motion: the feet are lowest)")
    p.add_argument("--forward", type=axis_or_auto, default="auto",
                   help="the way the clip's figure faces at rest (default: detected from where the feet point)")
    p.add_argument("--connect", help="also write each frame's .tskel for this .connect")
    p.add_argument("--no-check", action="store_true",
                   help="write the frames even when the retargeted figure fails the plausibility checks")
    p.add_argument("-o", "--output", required=True, help="folder for NAME.0000.trans, ...")

    p = add_command(sub, "export-gltf", "The posed body for any glTF viewer: the rest body's surface skinned to "
                    "the bones and a clip (or .trans frames) as its animation, one .glb.",
                    ("volanim export-gltf mannequin.0.50.connect walk.bvh --bones mannequin.bones --frames 0:200:5 "
                     "-o walk.glb",
                     "volanim export-gltf mannequin.0.50.connect wave/ --bones mannequin.bones --fps 24 -o wave.glb"),
                    _export_gltf)
    p.add_argument("connect", help="the rig: a .connect (its ownership, NAME.owners.nrrd, skins the body)")
    p.add_argument("clip", nargs="+", help="a motion clip (.bvh, .glb, .gltf, .vrma, .fbx), retargeted as bvh2trans "
                                           "does; or .trans frames (files or a folder)")
    p.add_argument("--bones", required=True, help="our .bones file (the rig's bones, in its root order)")
    p.add_argument("--animation", help="glTF, FBX: which of the clip's animations (default: the first)")
    p.add_argument("--map", help="a clip: BONE BVH_JOINT per line (default: suggested from the names)")
    p.add_argument("--frames", type=parse_frames, default=slice(None), metavar="START:STOP:STEP")
    p.add_argument("--up", type=axis_or_auto, default="auto", help="a clip's up axis (default: detected)")
    p.add_argument("--forward", type=axis_or_auto, default="auto", help="a clip's forward axis (default: detected)")
    p.add_argument("--no-check", action="store_true", help="a clip: export even when the plausibility checks fail")
    p.add_argument("--fps", type=positive_float, help="frames per second (default: the clip's; .trans frames: 24)")
    p.add_argument("--triangles", type=positive_int, default=200_000,
                   help="at most this many triangles (default 200000: what a web viewer takes)")
    p.add_argument("--blend", type=positive_float, default=2.0,
                   help="voxels over which a vertex near a joint blends its bones (default 2)")
    p.add_argument("-o", "--output", required=True, help="the .glb to write")

    p = add_command(sub, "trans2bvh", "Our bones and their frames as a BVH clip, to refine in an animation package "
                    "(Blender, Maya) and bring back with bvh2trans.",
                    "volanim trans2bvh mannequin.bones walk/*.trans --fps 12 -o walk-mannequin.bvh", _trans2bvh)
    _bones_and_frames_args(p)
    p.add_argument("--fps", type=positive_float, default=24.0, help="frames per second (default 24)")
    p.add_argument("--scale", type=positive_float, default=1.0, help="BVH units per voxel (default 1)")
    p.add_argument("-o", "--output", required=True, help="the .bvh to write")

    p = add_command(sub, "trans2positions", "Every joint's position in each frame, as the CSV positions2trans "
                    "reads (to plot, or to compare with marker data).",
                    "volanim trans2positions mannequin.bones walk/*.trans -o walk-joints.csv", _trans2positions)
    _bones_and_frames_args(p)
    p.add_argument("-o", "--output", required=True, help="the CSV to write (frame,joint,x,y,z)")

    p = add_command(sub, "positions2trans", "Joint positions per frame (markers, a video pose estimator: a CSV of "
                    "frame,joint,x,y,z) -> one .trans per frame; the twist from a third marker (ivskelgetrot).",
                    "volanim positions2trans walk-joints.csv --bones mannequin.bones -o from-positions/",
                    _positions2trans)
    p.add_argument("positions", help="CSV: a 'frame,joint,x,y,z' header, then a row per joint and frame, in the "
                                     ".bones' coordinates (voxels) times --scale; or a C3D file (motion capture), "
                                     "fitted onto the bones")
    p.add_argument("--bones", required=True, help="our .bones file")
    p.add_argument("--map", help="JOINT MARKER [MARKER ...] per line: each joint the mean of its markers "
                                 "(default: markers named after the joints)")
    p.add_argument("--frames", type=parse_frames, default=slice(None), metavar="START:STOP:STEP")
    p.add_argument("--up", type=axis_or_auto, help="the data's up axis (x, y, z, -x, ...) or auto: from the legs' "
                   "and spine's directions (the default for C3D; a CSV is taken as in the bones' own axes unless "
                   "--up or --forward is given)")
    p.add_argument("--forward", type=axis_or_auto, help="the way the data's figure faces (x, -y, ...) or auto "
                   "(the default, as for --up)")
    p.add_argument("--scale", type=positive_float, help="voxels per data unit (default for C3D: our bone lengths "
                                                        "over the data's; for a CSV: 1)")
    p.add_argument("--connect", help="also write each frame's .tskel for this .connect")
    p.add_argument("-o", "--output", required=True, help="folder for NAME.0000.trans, ...")

    p = add_command(sub, "trans2tskel", "A .connect plus many .trans frames -> one .tskel each.",
                    "volanim trans2tskel mannequin.0.50.connect walk/*.trans -o walk/", _trans2tskel)
    p.add_argument("connect")
    p.add_argument("trans", nargs="+")
    p.add_argument("-o", "--output", required=True, help="folder for the .tskel files")
