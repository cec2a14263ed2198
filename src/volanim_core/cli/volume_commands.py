"""Volume subcommands: info, convert, threshold, fill, crop, tightbounds, flip,
count, diff, reverse, remap, addheader, rmheader, fitpow2, float2uchar, samples."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from volanim_core.geometry import axis_codes, mm
from volanim_core.io import add_header, histogram_file, remove_header
from volanim_core.volume import finite_range, float_to_uint8, non_finite_count

from .. import samples, volume
from ..io.raw_volumes import raw_layout
from ..io.text import parse_int, read_records
from ..progress import TextProgress
from ._common import (
    add_command,
    add_dims,
    add_volume_in,
    ascii_int,
    bounds_arg,
    finite_float,
    load,
    load_scan,
    parse_range,
    positive_float,
    positive_int,
    save,
    stop_exclusive,
)


def _info(args):
    scan = load_scan(args.volume, args, colour=True)
    vol = scan.data
    kind = f"{vol.dtype} RGB" if vol.ndim == 4 else str(vol.dtype)
    vol = volume.brightest(vol)  # values and bounds of a colour volume: of its brightest channel
    bad = non_finite_count(vol)
    with np.errstate(invalid="ignore"):
        b = volume.tight_bounds(vol)
    g = scan.geometry
    found = finite_range(vol)
    print(f"{args.volume}: {vol.shape[0]} x {vol.shape[1]} x {vol.shape[2]} voxels, {kind}")
    print(f"spacing {mm(g.spacing)} mm, origin ({mm(g.origin, ', ')}) mm, axes {axis_codes(g.matrix)} "
          f"(direction {mm(g.direction, ' ')})")
    values = f"values {found[0]:g} .. {found[1]:g}" if found else "values: none finite"
    # NaN and infinity count as non-zero to NumPy; they are background here
    print(f"{values}, non-zero {int(np.count_nonzero(vol)) - bad}"
          + (f", {bad} NaN or infinite (background)" if bad else ""))
    print(f"tight bounds (inclusive x0 y0 z0 x1 y1 z1): {b if b else 'none (all zero)'}")
    if scan.segments:
        print("segments: " + ", ".join(f"{v} {name}" for v, name in sorted(scan.segments.items())))


def _convert(args):
    scan = load_scan(args.input, args, colour=not args.grey)  # colour stays colour unless asked
    vol = float_to_uint8(scan.data) if args.rescale else scan.data
    save(args.output, vol, scan.geometry)


def _threshold(args):
    lo, hi = args.range
    scan = load_scan(args.input, args)
    save(args.output, volume.threshold(scan.data, lo, hi, value=args.value), scan.geometry)


def _fill(args):
    scan = load_scan(args.input, args)
    vol = scan.data
    if not args.cavities and args.box is None:
        raise ValueError("nothing to do: give --cavities and/or --box x0 y0 z0 x1 y1 z1")
    if args.cavities:
        before = np.count_nonzero(vol)
        vol = volume.fill_cavities(vol)
        print(f"filled {np.count_nonzero(vol) - before} cavity voxels")
    if args.box is not None:
        vol = volume.box_fill(vol, bounds_arg(args.box, inclusive=args.inclusive, option="--box"), args.value)
    save(args.output, vol, scan.geometry)


def _crop(args):
    scan = load_scan(args.input, args, colour=True)
    vol = scan.data
    if args.bounds:
        b = bounds_arg(args.bounds, inclusive=args.inclusive)
    else:
        b = volume.tight_bounds(volume.brightest(vol))  # colour: of the non-black voxels
        if b is None:
            raise ValueError(f"{args.input}: the volume is all zero, there is nothing to crop to")
    if args.pad:
        b = volume.Bounds(tuple(v - args.pad for v in b.lo), tuple(v + args.pad for v in b.hi))
    geometry = scan.geometry.shifted(b.lo)
    shown = str(b) if args.inclusive else stop_exclusive(b)
    print(f"crop bounds: {shown} ({'inclusive' if args.inclusive else 'stop excluded'}; the output's origin is "
          f"voxel {b.lo} of the input, at ({mm(geometry.origin, ', ')}) mm)")
    save(args.output, volume.each_channel(vol, lambda v: volume.crop(v, b)), geometry)


def _tightbounds(args):
    """The bounds as crop and fill take them (the stop excluded, the thesis's convention), so that
    ``volanim crop IN OUT --bounds $(volanim tightbounds IN)`` crops to them; ``--inclusive``: the last voxels."""
    b = volume.tight_bounds(volume.brightest(load(args.input, args, colour=True)), args.level)
    if b is None:
        print("none (no voxel above the level)")
    else:
        print(b if args.inclusive else stop_exclusive(b))


def _flip(args):
    """Mirror the voxels; the geometry is flipped with them, so the scan stays where it is in space
    unless ``--mirror`` asks for a mirrored body (the old tool's only meaning)."""
    scan = load_scan(args.input, args, colour=True)
    axis = "xyz".index(args.axis)
    keep = args.mirror or scan.geometry.is_identity  # a volume placed nowhere has nowhere to stay
    geometry = scan.geometry if keep else scan.geometry.flipped(axis, scan.data.shape[axis])
    save(args.output, volume.each_channel(scan.data, lambda v: volume.flip(v, args.axis)), geometry)


def _count(args):
    path = Path(args.input)
    if path.is_file() and path.suffix.lower() == ".vol":
        raw_layout(path, args.dims)  # validate before streaming
        counts = histogram_file(path, args.dims)
    else:
        counts = volume.histogram(load(args.input, args))
    total = int(counts.sum())
    print(f"{total} voxels, {total - int(counts[0])} non-zero")
    for v in range(256) if args.all else np.flatnonzero(counts):
        print(f"{v:3d} {int(counts[v])}")


def _diff(args):
    first, second = load_scan(args.first, args), load(args.second, args)
    if first.data.shape != second.shape:
        raise ValueError(f"{args.first} is {'x'.join(map(str, first.data.shape))} voxels but {args.second} is "
                         f"{'x'.join(map(str, second.shape))}: diff compares volumes of one size")
    out = volume.super_diff(first.data, second)
    counts = np.bincount(out.ravel(), minlength=201)
    for label, code in volume.SUPER_DIFF_CODES.items():
        print(f"{code:3d} {label:14s} {int(counts[code])}")
    differ = out.size - int(counts[0])
    print(f"{differ} of {out.size} voxels differ ({100 * differ / max(out.size, 1):.3g} %)"
          if differ else f"identical: all {out.size} voxels hold the same value")
    if args.output:
        save(args.output, out, first.geometry)


def _reverse(args):
    scan = load_scan(args.input, args, colour=True)  # colour: each channel, 255 - v (a photographic negative)
    save(args.output, volume.each_channel(scan.data, volume.reverse), scan.geometry)


def read_remap_table(path: str) -> np.ndarray:
    """A remap table file: ``FROM TO`` pairs (others unchanged) or single values, line k for value k:
    256 lines, or the thesis's 255 (values 0..254; 255 stays 255)."""
    rec = read_records(path)
    table = np.arange(256)
    if all(len(t) == 1 for _, t in rec.records):
        if len(rec.records) not in (255, 256):
            raise rec.error(None, f"a table of single values needs 256 lines (or the thesis's 255), "
                                  f"got {len(rec.records)}")
        for i, (line, toks) in enumerate(rec.records):
            table[i] = parse_int(rec, line, toks[0], "value")
    else:
        for line, toks in rec.records:
            if len(toks) != 2:
                raise rec.error(line, f"expected 'FROM TO', got {len(toks)} tokens")
            a, b = (parse_int(rec, line, t, "value") for t in toks)
            if not (0 <= a <= 255 and 0 <= b <= 255):
                raise rec.error(line, "values must be 0..255")
            table[a] = b
    if table.min() < 0 or table.max() > 255:
        raise rec.error(None, "values must be 0..255")
    return table


def remap_pair(text: str) -> tuple[int, int]:
    """``FROM:TO``, two values 0..255 (``--pairs``)."""
    parts = text.split(":")
    if len(parts) != 2 or not all(p.isascii() and p.isdigit() and int(p) <= 255 for p in parts):
        raise argparse.ArgumentTypeError(f"expected FROM:TO with values 0..255, e.g. 3:1, got {text!r}")
    return int(parts[0]), int(parts[1])


def _remap(args):
    if args.table:
        table = read_remap_table(args.table)
    else:
        table = np.arange(256)
        for a, b in args.pairs:
            table[a] = b
    scan = load_scan(args.input, args)
    save(args.output, volume.remap(scan.data, table), scan.geometry)


def _addheader(args):
    dims = add_header(args.input, args.output, args.dims)
    print(f"wrote {args.output} ({dims[0]}x{dims[1]}x{dims[2]} with header)")


def _rmheader(args):
    if args.dims and args.header_size is None:  # a .VOL's own header sizes it: the dims would go unchecked
        raise ValueError("--dims goes with --header-size (a .VOL's header gives its dims)")
    dims = remove_header(args.input, args.output, args.header_size, args.dims)
    size = f"{dims[0]}x{dims[1]}x{dims[2]}" if dims else f"{Path(args.output).stat().st_size} bytes"
    print(f"wrote {args.output} ({size}, no header)")


def _fitpow2(args):
    scan = load_scan(args.input, args, colour=True)
    out, offset = volume.each_channel(scan.data, lambda v: volume.fit_pow2(v, center=args.center))
    print(f"old voxel (0,0,0) is at {offset} in the output")
    save(args.output, out, scan.geometry.shifted(np.negative(offset)))


def _float2uchar(args):
    lo, hi = args.range if args.range else (None, None)
    scan = load_scan(args.input, args)
    bad = non_finite_count(scan.data)
    if bad:
        print(f"note: {bad} NaN or infinite voxels are background (0)")
    save(args.output, float_to_uint8(scan.data, lo, hi), scan.geometry)


def _resample(args):
    scan = load_scan(args.input, args, colour=True)  # colour: each channel, as the thesis resampled 24-bit slices
    g = scan.geometry
    if args.spacing:
        spacing = args.spacing if len(args.spacing) == 3 else args.spacing * 3
    elif args.factor:
        spacing = [s * args.factor for s in g.spacing]
    elif args.size:
        spacing = [s * (n - 1) / max(m - 1, 1) for s, n, m in zip(g.spacing, scan.data.shape, args.size)]
    else:
        spacing = [min(g.spacing)] * 3
    order = 0 if args.labels else 1
    vol, geometry = volume.each_channel(scan.data, lambda v: volume.resample(
        v, g, spacing, order=order, progress=TextProgress("resample")))
    print(f"{'x'.join(map(str, scan.data.shape[:3]))} voxels of {mm(g.spacing)} mm -> "
          f"{'x'.join(map(str, vol.shape))} of {mm(geometry.spacing)} mm ({'nearest' if order == 0 else 'linear'})")
    save(args.output, vol, geometry)


def _voxelize(args):
    from volanim_core.io.mesh_files import read_mesh, voxelize

    mesh = read_mesh(args.mesh)
    vol, geometry = voxelize(mesh, spacing=args.spacing, size=args.size, value=args.value)
    print(f"{args.mesh}: {mesh.n_points} vertices, {mesh.n_cells} faces -> {int(np.count_nonzero(vol))} voxels inside, "
          f"cubes of {geometry.spacing[0]:g} (the mesh's units, taken as mm)")
    save(args.output, vol, geometry)


def _samples(args):
    if args.pose:
        return _posed_sample(args)
    for name in (*samples.NAMES, *samples.FILE_SAMPLES) if args.name == "all" else [args.name]:
        bar = TextProgress(f"making {name}")
        written = samples.write_sample(name, args.output, progress=bar)
        bar.close()
        for path in written:
            print(f"wrote {path}")


def _posed_sample(args):
    """``samples NAME --pose P.trans -o truth.vti``: the mannequin's true shape in that pose (posed_truth)."""
    from volanim_core.geometry import IDENTITY
    from volanim_core.io import read_trans
    from volanim_core.posed_truth import POSABLE, posed_sample
    from volanim_core.rig.pose import root_bones
    from volanim_core.rig.tskel_tools import check_root_order

    if args.name not in POSABLE:
        raise ValueError(f"--pose: only the mannequins have a posed truth ({', '.join(POSABLE)}), not {args.name}")
    if Path(args.output).is_dir() or args.output in (".", ""):
        raise ValueError(f"--pose writes one volume: -o names it (truth.vti, .nrrd, ...), not the folder {args.output}")
    trans = read_trans(args.pose)
    bar = TextProgress(f"posing {args.name}")
    truth = posed_sample(args.name, trans.matrices, progress=bar)
    bar.close()
    check_root_order(root_bones(truth.bones), trans.bones, first=f"{args.name}'s bones")
    save(args.output, truth.volume, IDENTITY.shifted(truth.origin))
    print(f"the {args.name}'s capsules posed by {args.pose}: voxel [0, 0, 0] is {truth.origin} of the rest grid")


def _io(p, output=True):
    add_volume_in(p, "input")
    if output:
        p.add_argument("output", help="output volume (.vol, .VOL, .vti, .nrrd, .nii, .nii.gz, .mha, a 3-D .tif), or "
                                      "slices/NAME%%04d.png for one image a slice")
    add_dims(p)


def register(sub) -> None:
    p = add_command(sub, "info", "Print a volume's size, geometry (spacing, origin, axes), value range, "
                    "NaN count and tight bounds.",
                    "volanim info frog.VOL", _info)
    add_volume_in(p)
    add_dims(p)

    p = add_command(sub, "convert", "Convert between volume formats (Vol2Vtk / Vtk2Vol).",
                    ("volanim convert frog.VOL frog.vti",
                     "volanim convert frog.VOL frog.tif   # one 3-D TIFF, spacing for Fiji",
                     "volanim convert frog.VOL frog-slices/frog%04d.png   # a slice stack"), _convert)
    _io(p)
    p.add_argument("--rescale", action="store_true", help="map non-uint8 data min..max onto 0..255")
    p.add_argument("--grey", action="store_true", help="write a colour volume as grey (luminance)")

    p = add_command(sub, "threshold", "Band-pass threshold to a binary volume (Convert2Binary).",
                    "volanim threshold frog.VOL frog-body.VOL --range 1:255", _threshold)
    _io(p)
    p.add_argument("--range", type=parse_range, required=True, metavar="LO[:HI]", help="keep LO <= v <= HI")
    p.add_argument("--value", type=ascii_int, default=255, help="value of kept voxels (default 255)")

    p = add_command(sub, "fill", "Fill enclosed cavities and/or a box (Fill).",
                    "volanim fill frog-body.VOL frog-filled.VOL --cavities", _fill)
    _io(p)
    p.add_argument("--cavities", action="store_true", help="fill background regions enclosed by the object")
    p.add_argument("--box", nargs=6, type=ascii_int, metavar="N",
                   help="box x0 y0 z0 x1 y1 z1 to set, the stop excluded as in the thesis: 0 0 0 2 2 2 is 8 voxels "
                        "(volanim included it before: --inclusive)")
    p.add_argument("--inclusive", action="store_true", help="x1 y1 z1 are the box's last voxels")
    p.add_argument("--value", type=ascii_int, default=255, help="value for --box (default 255)")

    p = add_command(sub, "crop", "Crop (or pad) to bounds, or to the tight bounds (CropVolume).",
                    "volanim crop frog.VOL frog-cropped.VOL --pad 2", _crop)
    _io(p)
    p.add_argument("--bounds", nargs=6, type=ascii_int, metavar="N",
                   help="x0 y0 z0 x1 y1 z1, the stop excluded as in the thesis (default: the tight bounds)")
    p.add_argument("--inclusive", action="store_true", help="x1 y1 z1 are the last voxels kept")
    p.add_argument("--pad", type=ascii_int, default=0, help="grow the bounds by N voxels on every side")

    p = add_command(sub, "tightbounds", "Print the bounds of the non-zero voxels as crop and fill take them, the stop "
                    "excluded (TightBounds).", "volanim tightbounds frog.VOL", _tightbounds)
    _io(p, output=False)
    p.add_argument("--inclusive", action="store_true", help="print x1 y1 z1 as the last non-zero voxels")
    p.add_argument("--level", type=finite_float, default=0, help="count voxels above this value (default 0)")

    p = add_command(sub, "flip", "Reverse a volume's voxels along an axis; the geometry follows, so in a viewer that "
                    "places scans (3D Slicer, napari) it stays where it was; --mirror mirrors the body itself.",
                    "volanim flip mannequin.VOL mirrored.VOL --axis x", _flip)
    _io(p)
    p.add_argument("--axis", choices=("x", "y", "z"), required=True)
    p.add_argument("--mirror", action="store_true", help="keep the geometry: the body is mirrored in space")

    p = add_command(sub, "count", "Histogram of voxel values; streams raw files (Count).",
                    "volanim count frog.VOL", _count)
    _io(p, output=False)
    p.add_argument("--all", action="store_true", help="list all 256 values, also those with count 0")

    p = add_command(sub, "diff", "Compare two volumes, the thesis's codes: 0 same value, 100 non-zero only in the "
                    "first, 150 only in the second, 200 both non-zero with different values (VolumeSuperDiff).",
                    "volanim diff frog-body.VOL frog-filled.VOL cavities.VOL   # 150: what fill added", _diff)
    add_volume_in(p, "first")
    add_volume_in(p, "second")
    p.add_argument("output", nargs="?", help="optional coded difference volume")
    add_dims(p)

    p = add_command(sub, "reverse", "Invert intensities, 255 - v (ReverseData).",
                    "volanim reverse mannequin.VOL negative.VOL", _reverse)
    _io(p)

    p = add_command(sub, "remap", "Remap values through a table (remapVolume): a file of 'FROM TO' lines or of "
                    "256 (or the thesis's 255) lines of one value, or FROM:TO pairs on the command line; other "
                    "values are unchanged.",
                    "volanim remap frog.VOL frog-merged.VOL --pairs 2:1 3:1   # tissues 2 and 3 become 1", _remap)
    _io(p)
    how = p.add_mutually_exclusive_group(required=True)
    how.add_argument("--table", help="table file: 'FROM TO' lines, or 256 (255) lines of one value (docs/formats.md)")
    how.add_argument("--pairs", nargs="+", type=remap_pair, metavar="FROM:TO", help="value pairs, e.g. 2:1 3:1")

    p = add_command(sub, "rmheader", "Remove the 100-byte .VOL header, or a header of any size, streaming (rmhdr).",
                    ("volanim rmheader frog.VOL frog.500x470x136.vol",
                     "volanim rmheader frog.VOL body.500x470x136.vol --header-size 100 --dims 500 470 136"), _rmheader)
    p.add_argument("input", help=".VOL with header, or any raw file with --header-size")
    p.add_argument("output", help="output .vol")
    p.add_argument("--header-size", type=ascii_int, metavar="BYTES",
                   help="drop this many bytes, whatever they hold (default: the .VOL header, sized from it)")
    p.add_argument("--dims", nargs=3, type=ascii_int, metavar=("X", "Y", "Z"),
                   help="with --header-size: the voxels the rest must hold (checked)")

    p = add_command(sub, "addheader", "Add the 100-byte .VOL header, streaming (AddHeader).",
                    "volanim addheader frog.500x470x136.vol frog-again.VOL", _addheader)
    p.add_argument("input", help="headerless .vol")
    p.add_argument("output", help="output .VOL")
    add_dims(p)

    p = add_command(sub, "fitpow2", "Pad every dimension up to a power of two (FitVolume).",
                    "volanim fitpow2 mannequin.VOL mannequin-pow2.VOL --center", _fitpow2)
    _io(p)
    p.add_argument("--center", action="store_true", help="centre the data instead of padding at the end")

    p = add_command(sub, "float2uchar", "Map a range of float (or 16-bit) data onto 0..255 (float2uchar).",
                    "volanim float2uchar frog.vti frog-stretched.VOL --range 0 10", _float2uchar)
    _io(p)
    p.add_argument("--range", nargs=2, type=finite_float, metavar=("LO", "HI"),
                   help="input range (default: data min max)")

    p = add_command(sub, "resample", "Resample to another voxel size, geometry kept: linear for intensities, "
                    "nearest (--labels) for labels and masks.",
                    ("volanim resample frog.VOL frog-half.nrrd --factor 2 --labels",
                     "volanim resample mannequin.VOL mannequin-coarse.nrrd --spacing 2   # 2 mm cubes"), _resample)
    _io(p)
    how = p.add_mutually_exclusive_group()
    how.add_argument("--spacing", nargs="+", type=positive_float, metavar="MM",
                     help="new voxel size: one number (cubes) or three (default: the smallest spacing, as cubes)")
    how.add_argument("--factor", type=positive_float, help="voxel size times this (2 halves each dimension)")
    how.add_argument("--size", nargs=3, type=ascii_int, metavar=("X", "Y", "Z"), help="new dimensions")
    p.add_argument("--labels", action="store_true", help="nearest voxel (labels, masks) instead of linear")

    p = add_command(sub, "voxelize", "Fill a closed surface mesh (.ply, .obj, .stl, .vtp; or a glTF file's "
                    "surface at rest, .glb, .gltf) into a binary volume with its geometry, ready to skeletonize.",
                    ("volanim voxelize ant.ply ant.nrrd --size 160",
                     "volanim voxelize Fox.glb fox.nrrd --size 160   # `volanim samples fox`: a skinned animal"),
                    _voxelize)
    p.add_argument("mesh", help="closed surface mesh (.ply, .obj, .stl, .vtp, or glTF .glb, .gltf)")
    p.add_argument("output", help="output volume (.nrrd, .nii, .mha, .vti keep the geometry; .VOL, .vol do not)")
    size = p.add_mutually_exclusive_group()
    size.add_argument("--spacing", type=positive_float, metavar="S", help="voxel size, in the mesh's units")
    size.add_argument("--size", type=positive_int, metavar="N", help="voxels along the longest side (default 128)")
    p.add_argument("--value", type=ascii_int, default=255, help="value inside (default 255)")

    p = add_command(sub, "samples",
                    "Write a demo dataset: mannequin (-colour, -large, -ct as DICOM), aliascube, frog, the walk clip, "
                    "the ant mesh, or all.",
                    "volanim samples all -o .", _samples)
    p.add_argument("name", choices=(*samples.NAMES, *samples.FILE_SAMPLES, *samples.BY_NAME_ONLY, "all"))
    p.add_argument("--pose", metavar="TRANS", help="a mannequin's true shape in this pose (a .trans of its bones): "
                   "each body part moved whole by its bone, the volume to compare a reconstruction with "
                   "(volanim compare); -o then names that volume: samples mannequin --pose arm.trans -o truth.vti")
    p.add_argument("-o", "--output", default=".", help="folder (default: current); with --pose, the volume file")
