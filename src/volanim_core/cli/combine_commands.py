"""Look into volumes and combine them: peek (Peek), onevolume (OneVolume), addskel (AddSkel2Vol / Merger).

    VOLUME + X Y Z ...          --peek-->       the values there (and where that is in mm)
    VOLUME.1 ... VOLUME.N       --onevolume-->  one volume: each one's voxels above a threshold
    VOLUME + .mskel/.skel       --addskel-->    the volume with the skeleton points burnt in
"""

from __future__ import annotations

import numpy as np

from volanim_core.geometry import mm
from volanim_core.io import read_skeleton

from ._common import add_command, add_dims, add_volume_in, ascii_int, finite_float, load_scan, save

MERGER_VALUE = 250  # the thesis's Merger draws the points at 250 over the scan at half its intensity (A.28)


def _peek(args):
    scan = load_scan(args.volume, args, colour=True)
    vol, g = scan.data, scan.geometry
    if len(args.xyz) % 3:
        raise ValueError(f"give voxels as X Y Z triples: {len(args.xyz)} numbers is not a whole number of them")
    for xyz in np.reshape(args.xyz, (-1, 3)):
        if np.any(xyz < 0) or np.any(xyz >= vol.shape[:3]):
            raise ValueError(f"{args.volume}: voxel ({', '.join(map(str, xyz))}) is outside its "
                             f"{'x'.join(map(str, vol.shape[:3]))} voxels (0-based)")
        value = vol[tuple(xyz)]
        shown = " ".join(f"{v:g}" for v in value) if np.ndim(value) else f"{value:g}"
        print(f"({', '.join(map(str, xyz))}) = {shown}   at ({mm(g.to_physical(xyz), ', ')}) mm")


def _onevolume(args):
    from volanim_core.io.volume_files import natural_order

    paths = natural_order(args.volumes)
    if args.label and len(paths) > 255:  # before reading any: a long series takes a while
        raise ValueError(f"--label numbers volumes 1..255 in a byte; {len(paths)} given")
    first = load_scan(paths[0], args)
    out = np.zeros(first.data.shape, np.uint8 if args.label else first.data.dtype, order="F")
    for k, path in enumerate(paths, start=1):
        vol = first.data if k == 1 else load_scan(path, args).data
        if vol.shape != out.shape:
            raise ValueError(f"{path} is {'x'.join(map(str, vol.shape))} voxels, {paths[0]} "
                             f"{'x'.join(map(str, out.shape))}: onevolume merges volumes of one grid")
        # the thesis's OneVolume zeroes what falls below the threshold: a value equal to it stays (#66); a zero
        # is background whatever the threshold, never written over another volume's voxel
        keep = (vol >= args.threshold) & (vol != 0)
        out[keep] = k if args.label else vol[keep]  # a later volume wins where two overlap
        print(f"{path}: {int(keep.sum())} non-zero voxels at or above {args.threshold:g}"
              + (f" -> label {k}" if args.label else ""))
    save(args.output, out, first.geometry)


def _addskel(args):
    scan = load_scan(args.volume, args, colour=True)  # colour: the points grey (value, value, value)
    skel = read_skeleton(args.skeleton)
    vol, g = scan.data, scan.geometry
    # the skeleton's voxels may be cubes resampled from the scan's: place them through physical space
    at = g.to_index(skel.geometry.to_physical(skel.points)) if not skel.geometry.is_identity else skel.points
    at = np.rint(at).astype(np.int64)
    if args.half_grid:
        vol, g, at = vol[::2, ::2, ::2].copy(order="F"), g.with_spacing(np.multiply(g.spacing, 2)), at // 2
    if args.half:  # the thesis's Merger: the scan at half its intensity, so the points stand out
        vol = vol / 2 if np.issubdtype(vol.dtype, np.floating) else vol // 2
    value = args.value if args.value is not None else (MERGER_VALUE if args.half else 255)
    inside = np.all((at >= 0) & (at < vol.shape[:3]), axis=1)
    if not inside.any():
        raise ValueError(f"{args.skeleton}: none of its {len(at)} points is inside {args.volume}")
    out = np.array(vol, order="F")
    out[tuple(at[inside].T)] = value
    outside = len(at) - int(inside.sum())
    print(f"burnt {int(inside.sum())} points of {args.skeleton} in as {value}"
          + (" over the scan at half its intensity" if args.half else "")
          + (f"; {outside} outside the volume left out" if outside else ""))
    save(args.output, out, g)


def register(sub) -> None:
    p = add_command(sub, "peek", "Print the values at voxels (Peek); the studio's status bar shows the voxel under "
                    "the cursor.", "volanim peek mannequin.VOL 80 50 150 0 0 0", _peek)
    add_volume_in(p)
    p.add_argument("xyz", nargs="+", type=ascii_int, metavar="X Y Z", help="voxel coordinates, 0-based, one or more")
    add_dims(p)

    p = add_command(sub, "onevolume", "Merge numbered volumes into one (OneVolume): each one's voxels above the "
                    "threshold, later ones on top; --label writes each volume's number instead of its values.",
                    "volanim onevolume mannequin.VOL negative.VOL -o merged.VOL --threshold 200 --label", _onevolume)
    p.add_argument("volumes", nargs="+", help="volumes on one grid, taken in their numbers' order")
    p.add_argument("-o", "--output", required=True, help="the merged volume")
    p.add_argument("--threshold", type=finite_float, default=0,
                   help="zero the values below this; equal ones stay, as in the thesis (volanim kept only those "
                        "above it before); zeros are background (default 0)")
    p.add_argument("--label", action="store_true", help="write volume k's voxels as k (1..255), not their values")
    add_dims(p)

    p = add_command(sub, "addskel", "Burn skeleton points into a volume (AddSkel2Vol / Merger), to look at them "
                    "with any volume viewer; --half as the thesis's Merger: the scan at half its intensity, the "
                    "points at 250.", "volanim addskel mannequin.VOL mannequin.mskel -o with-skeleton.VOL --half",
                    _addskel)
    add_volume_in(p)
    p.add_argument("skeleton", help=".mskel or .skel")
    p.add_argument("-o", "--output", required=True, help="the volume with the points in it")
    p.add_argument("--value", type=ascii_int, default=None,
                   help=f"the points' value (default 255; {MERGER_VALUE} with --half, as Merger)")
    p.add_argument("--half", action="store_true",
                   help="the thesis's Merger: halve the scan's intensity so the points stand out (volanim's --half "
                        "halved the grid before: --half-grid)")
    p.add_argument("--half-grid", action="store_true",
                   help="at half size: every second voxel, points at half coordinates")
    add_dims(p)
