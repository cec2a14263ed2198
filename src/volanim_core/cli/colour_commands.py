"""Colour subcommands: ``palette build|apply|sort`` and ``alpha interpolate|factor|merge``.

The thesis's MapImages, InvCMap + mapImages, its palette sorts, InterpolateAlpha,
AlphaFactor and MergeMaps (docs/formats.md#palette for the files).
"""

from __future__ import annotations

import re
import time
from pathlib import Path

import numpy as np

from volanim_core.progress import TextProgress

from ._common import EXAMPLES_HEADER, add_command, add_dims, ascii_int, finite_float, non_negative_int, positive_int

PALETTE_EXAMPLES = (
    "volanim palette build mannequin-colour.VOL -o mannequin.palette.txt --colours 255",
    "volanim palette apply mannequin-colour.VOL mannequin.palette.txt -o mannequin-index.VOL",
    "volanim palette sort mannequin.palette.txt -o mannequin-sorted.palette.txt --remap mannequin.remap.txt \\\n"
    "    --volume mannequin-index.VOL",
)
ALPHA_EXAMPLES = (
    "volanim alpha ramp 0:0 1:0.02 254:0.6 -o mannequin-ramp.alpha   # see-through skin, solid bone",
    "volanim alpha merge mannequin-sorted.palette.txt mannequin-ramp.alpha --clear-black -o mannequin.tf",
    "volanim alpha factor mannequin-ramp.alpha 0.5 -o mannequin-faint.alpha",
    "volanim alpha interpolate mannequin-ramp.alpha mannequin-faint.alpha -n 3 -o mannequin-fade --start 41",
)


def _build(args):
    from volanim_core.colour.palette import build_palette, colour_errors, weighted_error
    from volanim_core.colour.slabs import ColourSlabs, sample_colours
    from volanim_core.io.palette_files import write_palette

    slabs = ColourSlabs.open(args.volume, args.dims)
    colours, counts = sample_colours(slabs, args.sample, progress=TextProgress("sampling slices"))
    t0 = time.perf_counter()
    palette = build_palette(colours, counts, args.colours, method=args.method,
                            progress=TextProgress(f"building ({args.method})"))
    built = time.perf_counter() - t0
    summary = (f"{len(palette)} colours from {int(counts.sum()):,} sampled voxels ({len(colours):,} distinct) "
               f"by {args.method} in {built:.1f} s\nCIEDE2000 of voxels to their palette colour:")
    errors = colour_errors(colours, palette)
    body = colours.any(axis=1)  # black is the background of a scan; its voxels would flatter the mean
    for name, keep in (("all voxels", slice(None)), ("not black", body)):
        if counts[keep].sum():
            mean, p95 = weighted_error(errors[keep], counts[keep])
            summary += f"\n  {name:11s} mean {mean:.2f}, 95th percentile {p95:.2f}"
    write_palette(args.output, palette, f"from {Path(args.volume).name}\n{summary}")
    print(summary)
    print(f"wrote {args.output}")


def _apply(args):
    from volanim_core.colour.slabs import ColourSlabs, apply_palette
    from volanim_core.io.palette_files import read_palette, write_palette

    palette = read_palette(args.palette)
    slabs = ColourSlabs.open(args.volume, args.dims)
    t0 = time.perf_counter()
    path, counts = apply_palette(slabs, palette, args.output, progress=TextProgress("mapping slices"))
    seconds = time.perf_counter() - t0
    voxels = int(np.prod(slabs.shape))
    beside = palette_beside(path)  # an index volume means nothing without its palette: they travel together
    write_palette(beside, palette, f"the palette of {path.name} (from {Path(args.palette).name})")
    print(f"wrote {path} ({'x'.join(map(str, slabs.shape))}, indices 0..{len(palette) - 1}; "
          f"{np.count_nonzero(counts)} used) at {voxels / max(seconds, 1e-9) / 1e6:.1f} M voxels/s, and {beside}")


def palette_beside(index_volume: Path) -> Path:
    """``NAME.palette.txt`` next to ``NAME.VOL`` / ``NAME.XxYxZ.vol`` / ``NAME.vti`` / ``NAME.nrrd``."""
    name = re.sub(r"(\.\d+x\d+x\d+)?\.(vol|vti|nrrd)$", "", index_volume.name, flags=re.IGNORECASE)
    return index_volume.with_name(f"{name}.palette.txt")


def _sort(args):
    from volanim_core.colour import sort
    from volanim_core.io import read_volume
    from volanim_core.io.palette_files import read_palette, write_palette, write_remap_table

    palette = read_palette(args.palette)
    if args.volume:
        index = read_volume(args.volume, dims=args.dims)
        if index.dtype != np.uint8 or (index.size and int(index.max()) >= len(palette)):
            raise ValueError(f"{args.volume}: not an index volume of this {len(palette)}-colour palette "
                             f"(values up to {int(index.max()) if index.size else 0})")
        pairs, weights = sort.colour_pairs(index, len(palette))
    else:
        pairs, weights = sort.near_pairs(palette)  # once, for both scores
    before = sort.score(palette, np.arange(len(palette)), pairs, weights)
    t0 = time.perf_counter()
    order = sort.sort_palette(palette, args.method, keep_first=args.keep_first, interval=args.interval,
                              penalty=args.penalty)
    seconds = time.perf_counter() - t0
    after = sort.score(palette, order, pairs, weights)
    where = f"colours touching in {Path(args.volume).name}" if args.volume else "each colour's 4 nearest colours"
    print(f"{args.method}: {seconds:.2f} s; CIEDE2000 between neighbouring indices, midpoint error over {where}")
    print(f"{'':10s}{'sum':>10s}{'max':>8s}{'midpoint':>10s}")
    for name, s in (("before", before), ("after", after)):
        print(f"{name:10s}{s['sum']:10.1f}{s['max']:8.2f}{s['midpoint']:10.2f}")
    write_palette(args.output, palette[order], f"{args.method} order of {Path(args.palette).name}")
    write_remap_table(args.remap, sort.remap_table(order)[:len(palette)])
    print(f"wrote {args.output} and {args.remap} (apply it: volanim remap INDEX.VOL SORTED.VOL --table {args.remap})")


def _alpha_arg(text: str):
    """An alpha map file, or one opacity for every index."""
    import argparse

    from volanim_core.io.palette_files import read_alpha_map

    if Path(text).exists():
        return read_alpha_map(text)
    try:
        value = finite_float(text)
    except argparse.ArgumentTypeError:
        raise ValueError(f"{text}: neither an alpha map file nor an opacity 0..1") from None
    return np.array([0.0]), np.array([value])


def _merge(args):
    from volanim_core.colour.alpha import black_indices, merge_maps
    from volanim_core.io import write_transfer_function
    from volanim_core.io.palette_files import read_palette

    palette = read_palette(args.palette)
    clear = list(args.clear or ()) + (black_indices(palette).tolist() if args.clear_black else [])
    tf = merge_maps(palette, _alpha_arg(args.alpha), clear)
    write_transfer_function(args.output, tf)
    print(f"wrote {args.output} ({len(palette)} colours; render with: volanim render INDEX.VOL --tf {args.output})")


def _point(text: str) -> tuple[float, float]:
    """``INDEX:ALPHA`` with alpha 0..1."""
    import argparse

    index, _, alpha = text.partition(":")
    try:
        v, a = finite_float(index), finite_float(alpha)
    except argparse.ArgumentTypeError:
        v = a = None
    if v is None or not 0 <= a <= 1:
        raise argparse.ArgumentTypeError(f"expected INDEX:ALPHA with alpha 0..1, e.g. 254:0.6, got {text!r}")
    return v, a


def _ramp(args):
    from volanim_core.io.palette_files import write_alpha_map

    points = sorted(args.points)
    values = [v for v, _ in points]
    if len(set(values)) != len(values):
        raise ValueError("each index may be given once")
    write_alpha_map(args.output, values, [a for _, a in points])
    print(f"wrote {args.output} ({len(points)} points, linear between)")


def _factor(args):
    from volanim_core.colour.alpha import alpha_factor
    from volanim_core.io.palette_files import read_alpha_map, write_alpha_map

    write_alpha_map(args.output, *alpha_factor(read_alpha_map(args.alpha), args.factor))
    print(f"wrote {args.output}")


def _interpolate(args):
    from volanim_core.colour.alpha import interpolate_alpha
    from volanim_core.io.palette_files import read_alpha_map, write_alpha_map

    maps = interpolate_alpha(read_alpha_map(args.first), read_alpha_map(args.second), args.n)
    width = len(str(args.start + len(maps) - 1))
    for k, (values, alphas) in enumerate(maps, start=args.start):
        path = f"{args.output}-{k:0{width}d}.alpha"
        write_alpha_map(path, values, alphas)
        print(f"wrote {path}")


def _group(sub, name, help, examples):
    p = add_command(sub, name, help, examples, None)
    p.set_defaults(func=lambda args: p.print_help())
    return p.add_subparsers(dest=f"{name}_action", metavar="ACTION", required=True)


def _action(group, name, help, example, func):
    p = group.add_parser(name, help=help, description=help, epilog=EXAMPLES_HEADER + "\n  " + example)
    p.set_defaults(func=func)
    return p


def register(sub) -> None:
    palette = _group(sub, "palette", "Colour volumes to 8-bit index volumes: build a palette (MapImages), map voxels "
                     "to it (InvCMap), sort it so renderers blend smoothly.", PALETTE_EXAMPLES)
    p = _action(palette, "build", "A palette of at most N colours from a colour volume (k-means in CIELAB on a "
                "sample of slices, or median cut); prints the CIEDE2000 error.", PALETTE_EXAMPLES[0], _build)
    p.add_argument("volume", help="colour volume: RGB .vol/.VOL (3 bytes a voxel), .vti, .nrrd or a folder of "
                   "RGB slices")
    p.add_argument("-o", "--output", required=True, help="palette file to write (R G B a line)")
    p.add_argument("--colours", type=ascii_int, default=255, help="at most this many colours, 1..256 (default 255)")
    p.add_argument("--method", choices=("kmeans", "median-cut"), default="kmeans",
                   help="kmeans (default, accurate) or median-cut (fast)")
    p.add_argument("--sample", type=ascii_int, default=1 << 23, metavar="VOXELS",
                   help="voxels to sample, from slices spread over the volume (default 8388608)")
    add_dims(p)

    p = _action(palette, "apply", "Map every voxel to its nearest palette colour (CIELAB), a slab of slices at a "
                "time; writes the 8-bit index volume.", PALETTE_EXAMPLES[1], _apply)
    p.add_argument("volume", help="colour volume")
    p.add_argument("palette", help="palette file")
    p.add_argument("-o", "--output", required=True, help="index volume to write (.vol/.VOL streamed, .vti, .nrrd)")
    add_dims(p)

    p = _action(palette, "sort", "Reorder a palette so similar colours get neighbouring indices; writes the sorted "
                "palette and the table for 'volanim remap'.", PALETTE_EXAMPLES[2], _sort)
    from volanim_core.colour.sort import CLUSTER_INTERVAL, DEFAULT_METHOD, GRADIENT_PENALTY, METHODS

    p.add_argument("palette", help="palette file")
    p.add_argument("-o", "--output", required=True, help="sorted palette file to write")
    p.add_argument("--remap", required=True, help="remap table to write (old index -> new index)")
    p.add_argument("--method", choices=METHODS, default=DEFAULT_METHOD,
                   help=f"ordering (default {DEFAULT_METHOD}: lightness order, then runs of colours moved to "
                        f"where they fit best); intensity, cluster-seeds, gradient-penalty and supergradient are "
                        f"the thesis's sorts as section 4.2 describes them (intensity = R + G + B); lightness, "
                        f"farthest-seeds, darker-penalty and moved are what those names meant in volanim before")
    p.add_argument("--interval", type=positive_int, default=CLUSTER_INTERVAL,
                   help=f"cluster-seeds: a seed every N colours of the intensity order (default {CLUSTER_INTERVAL})")
    p.add_argument("--penalty", type=finite_float, default=GRADIENT_PENALTY,
                   help=f"gradient-penalty: the weight of turning back, P in D + {GRADIENT_PENALTY:g}P")
    p.add_argument("--volume", help="the index volume, to score the midpoint error on colours that touch in it")
    p.add_argument("--keep-first", action="store_true", help="keep index 0 (a background colour) in place")
    add_dims(p)

    alpha = _group(sub, "alpha", "Alpha maps for index volumes: merge with a palette into a transfer function "
                   "(MergeMaps), scale (AlphaFactor), fade between two (InterpolateAlpha).", ALPHA_EXAMPLES)
    p = _action(alpha, "ramp", "An alpha map from INDEX:ALPHA points, linear between and held beyond.",
                ALPHA_EXAMPLES[0], _ramp)
    p.add_argument("points", nargs="+", type=_point, metavar="INDEX:ALPHA", help="control points, e.g. 0:0 254:0.6")
    p.add_argument("-o", "--output", required=True, help="alpha map to write")

    p = _action(alpha, "merge", "A palette + an alpha map (file, or one opacity) -> an RGBA transfer function "
                "file that 'volanim render --tf' reads.", ALPHA_EXAMPLES[1], _merge)
    p.add_argument("palette", help="palette file")
    p.add_argument("alpha", help="alpha map file (INDEX ALPHA lines), or one opacity 0..1 for every index")
    p.add_argument("-o", "--output", required=True, help="transfer function file to write (.tf)")
    p.add_argument("--clear", nargs="+", type=ascii_int, metavar="INDEX", help="indices made transparent")
    p.add_argument("--clear-black", action="store_true", help="make black (a scan's background) transparent, "
                   "wherever the palette has it")

    p = _action(alpha, "factor", "Multiply an alpha map by a factor, clipped to 0..1 (AlphaFactor).",
                ALPHA_EXAMPLES[2], _factor)
    p.add_argument("alpha", help="alpha map file")
    p.add_argument("factor", type=finite_float, help="factor >= 0")
    p.add_argument("-o", "--output", required=True, help="alpha map to write")

    p = _action(alpha, "interpolate", "N alpha maps evenly between two (InterpolateAlpha): PREFIX-1.alpha ...",
                ALPHA_EXAMPLES[3], _interpolate)
    p.add_argument("first", help="alpha map file")
    p.add_argument("second", help="alpha map file")
    p.add_argument("-n", type=ascii_int, required=True, help="maps between the two")
    p.add_argument("--start", type=non_negative_int, default=1, metavar="K",
                   help="number of the first map (default 1), e.g. the frame the fade starts on, as the thesis's "
                        "InterpolateAlpha took")
    p.add_argument("-o", "--output", required=True, metavar="PREFIX",
                   help="write PREFIX-K.alpha ... PREFIX-(K+N-1).alpha")
