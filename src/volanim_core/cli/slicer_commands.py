"""To and from 3D Slicer: markups (joints), ITK transform files (bones), a displacement field (a frame).

    volanim markups BONES.bones -o JOINTS.mrk.json          our joints, to place or check in Slicer
    volanim markups A.mrk.json [B.mrk.json] --like SCAN -o BONES.bones   bones placed in Slicer
    volanim transforms CONNECT FRAME.trans -o DIR/          DIR/BONE.tfm per bone (posed -> rest, LPS)
    volanim displacement CONNECT FRAME.trans --like SCAN -o FIELD.nrrd  Slicer's grid transform
"""

from __future__ import annotations

import re
from pathlib import Path

from volanim_core.io import read_bones, read_connect, read_trans, write_bones

from ._common import add_command, add_dims, load_scan


def _markups(args):
    from volanim_core.io.slicer_files import read_markups, write_markups

    out = args.output
    if all(p.lower().endswith(".json") for p in args.inputs):
        if not out.endswith(".bones"):
            raise ValueError(f"cannot write {out}: markups in, so the output is a .bones file")
        if not args.like:
            raise ValueError("give --like SCAN: the .bones file records its joints on the scan's voxel grid")
        bones = read_markups(args.inputs, load_scan(args.like, args, colour=True).geometry)
        write_bones(out, bones)
        print(f"{len(bones.joints)} joints, {len(bones)} bones (on {args.like}'s grid) -> {out}")
        return
    if len(args.inputs) != 1 or not args.inputs[0].endswith(".bones"):
        raise ValueError("expected one .bones file, or one or more .mrk.json files")
    if not out.endswith(".json"):
        raise ValueError(f"cannot write {out}: a .bones file in, so the output is a .mrk.json file")
    bones = read_bones(args.inputs[0])
    geometry = bones.geometry  # the grid the file records wins; --like places a file that records none
    if geometry.is_identity and args.like:
        geometry = load_scan(args.like, args, colour=True).geometry
    if geometry.is_identity:
        print(f"note: {args.inputs[0]} records no voxel grid: its voxels are written as 1 mm cubes at the origin "
              "(give --like SCAN to place them in the scan)")
    write_markups(out, bones, geometry)
    print(f"{len(bones.joints)} joints, {len(bones)} bones -> {out} (LPS mm)")


def _transforms(args):
    from volanim_core.io.slicer_files import write_transform
    from volanim_core.reconstruct.displacement import transforms

    conn = read_connect(args.connect)
    mats = transforms(conn, read_trans(args.trans))
    folder = Path(args.output)
    folder.mkdir(parents=True, exist_ok=True)
    names = [re.sub(r"[^\w.-]+", "_", label) for label in mats]
    if len(set(names)) < len(names):  # unnamed bones' labels are coordinates; keep them apart by root order
        names = [f"{i:02d}_{n}" for i, n in enumerate(names)]
    for name, m in zip(names, mats.values()):
        write_transform(folder / f"{name}.{args.format}", m)
    if conn.geometry.is_identity:
        print(f"note: {args.connect} records no voxel grid: voxels are taken as 1 mm cubes at the origin")
    print(f"{len(mats)} bone transforms (posed -> rest, LPS mm: Slicer's and ITK's resampling direction) "
          f"-> {folder}/*.{args.format}")


def _displacement(args):
    from volanim_core.io.nrrd_files import write_nrrd
    from volanim_core.progress import TextProgress
    from volanim_core.reconstruct.displacement import displacement

    if not args.output.endswith(".nrrd"):
        raise ValueError(f"cannot write {args.output}: a displacement field is written as .nrrd")
    conn = read_connect(args.connect)
    scan = load_scan(args.like, args, colour=True)
    if conn.geometry.is_identity and not scan.geometry.is_identity:
        raise ValueError(f"{args.connect} records no voxel grid, so where its voxels lie in {args.like} is not "
                         "known; make the connectivity from a skeleton of this scan")
    field = displacement(conn, read_trans(args.trans), scan.data.shape[:3], scan.geometry, outside=args.outside,
                         progress=TextProgress("displacement"))
    write_nrrd(args.output, field, scan.geometry)
    print(f"displacement field {'x'.join(str(n) for n in field.shape[:3])} (posed -> rest, LPS mm, on "
          f"{args.like}'s grid) -> {args.output}")


def register(sub) -> None:
    p = add_command(sub, "markups", "Joints to 3D Slicer markups (.mrk.json) and bones placed in Slicer back.",
                    ("volanim markups mannequin.bones -o mannequin.mrk.json",
                     "volanim markups mannequin.mrk.json --like mannequin.VOL -o from-slicer.bones"), _markups)
    p.add_argument("inputs", nargs="+", help="a .bones file, or .mrk.json files (one chain of bones per point "
                                             "list; a label seen before is the same joint)")
    p.add_argument("--like", help="the scan whose grid the joints are on (markups in; a .bones file that records "
                                  "no grid)")
    add_dims(p)
    p.add_argument("-o", "--output", required=True, help=".mrk.json or .bones")

    p = add_command(sub, "transforms", "Each bone's transform in a frame as an ITK file Slicer applies (.tfm/.h5).",
                    "volanim transforms mannequin.0.50.connect arm.trans -o arm-transforms/", _transforms)
    p.add_argument("connect")
    p.add_argument("trans")
    p.add_argument("--format", choices=("tfm", "h5"), default="tfm", help="tfm: ITK text (default); h5 needs "
                                                                          "SimpleITK")
    p.add_argument("-o", "--output", required=True, help="folder for BONE.tfm")

    p = add_command(sub, "displacement", "A frame as a dense displacement field (Slicer's grid transform, ITK's "
                                         "DisplacementFieldTransform) on a scan's grid.",
                    "volanim displacement mannequin.0.50.connect arm.trans --like mannequin.VOL -o arm-field.nrrd",
                    _displacement)
    p.add_argument("connect")
    p.add_argument("trans")
    p.add_argument("--like", required=True, help="the scan whose grid the field is on (the one to resample)")
    add_dims(p)
    p.add_argument("--outside", choices=("empty", "identity"), default="empty",
                   help="outside the posed body: point off the image (default: nothing stays behind) or stay")
    p.add_argument("-o", "--output", required=True, help="FIELD.nrrd")
