"""Skeleton subcommands: skeletonize, isosurface."""

from __future__ import annotations

import time

import numpy as np

from volanim_core.geometry import mm
from volanim_core.io import write_skeleton
from volanim_core.io.mesh_files import write_mesh
from volanim_core.progress import TextProgress
from volanim_core.skeleton.hull import isosurface
from volanim_core.skeleton.skeletonize import DEFAULT_MIN_THINNESS, skeletonize

from .. import volume
from ._common import (
    add_command,
    add_dims,
    add_volume_in,
    ascii_float,
    ascii_int,
    load,
    load_scan,
    parse_range,
    positive_float,
)


def segment(vol: np.ndarray, threshold, fill: bool) -> np.ndarray:
    """The object mask: ``threshold`` band (default: non-zero), cavities filled if asked."""
    lo, hi = threshold if threshold else (1, None)
    return volume.segment(vol, lo, hi, fill=fill)


def mask_like_skeleton(args, skeleton):
    """``args.volume`` segmented as skeletonize did (``--threshold``, ``--fill-cavities``) on the skeleton's
    grid: the cubes skeletonize resampled the scan to. What connect's and autorig's paths run inside."""
    scan = load_scan(args.volume, args, colour="luminance")
    mask = segment(scan.data, args.threshold, args.fill_cavities)
    return volume.isotropic_mask(mask, scan.geometry, min(skeleton.geometry.spacing))[0]


def _skeletonize(args):
    scan = load_scan(args.volume, args, colour="luminance")  # a colour scan is segmented by its luminance
    mask = segment(scan.data, args.threshold, args.fill_cavities)
    mask, geometry = _cubic(mask, scan.geometry, args.voxel_size)
    bar = TextProgress("skeletonize")
    t0 = time.perf_counter()
    skel = skeletonize(mask, metric=args.metric, min_thinness=args.min_thinness, geometry=geometry, progress=bar)
    elapsed = time.perf_counter() - t0
    write_skeleton(args.output, skel)
    lo, hi = (skel.thinness.min(), skel.thinness.max()) if len(skel) else (float("nan"),) * 2
    print(f"{len(skel)} points from {int(mask.sum())} object voxels, thinness {lo:.3f} .. {hi:.3f}, "
          f"dt up to {skel.dt.max() if len(skel) else 0:.2f} ({args.metric}), {elapsed:.2f} s -> {args.output}")


def _cubic(mask: np.ndarray, geometry, voxel_size):
    """The mask on cubic voxels (:func:`volume.isotropic_mask`), saying so when it resampled."""
    cubes, cubic = volume.isotropic_mask(mask, geometry, voxel_size, progress=TextProgress("resample"))
    if cubes is not mask:
        print(f"resampled {mm(geometry.spacing)} mm voxels to {cubic.spacing[0]:g} mm cubes: "
              f"{'x'.join(map(str, mask.shape))} -> {'x'.join(map(str, cubes.shape))} voxels")
    return cubes, cubic


def _isosurface(args):
    vol = load(args.volume, args, colour="luminance")
    mask = segment(vol, args.threshold, args.fill_cavities)
    t0 = time.perf_counter()
    verts, faces = isosurface(mask, step=args.step, engine=args.engine)
    write_mesh(args.output, verts, faces)
    print(f"{len(verts)} vertices, {len(faces)} triangles in {time.perf_counter() - t0:.2f} s -> {args.output}")


def _segment_args(p):
    add_volume_in(p)
    add_dims(p)
    p.add_argument("--threshold", type=parse_range, metavar="LO[:HI]",
                   help="object = LO <= v <= HI (default: every non-zero voxel)")
    p.add_argument("--fill-cavities", action="store_true", help="fill enclosed background first")


def register(sub) -> None:
    p = add_command(sub, "skeletonize", "Distance transform + thinness -> multi-resolution skeleton (.mskel), or one "
                    "resolution (.skel).",
                    ("volanim skeletonize mannequin.VOL -o mannequin.mskel",
                     "volanim skeletonize frog.VOL --threshold 1:255 --fill-cavities -o frog.mskel",
                     "volanim skeletonize mannequin.VOL --min-thinness -inf -o every-voxel.mskel   # all voxels",
                     "volanim skeletonize mannequin.VOL --min-thinness 0.5 -o mannequin.0.5.skel   # one resolution"),
                    _skeletonize)
    _segment_args(p)
    p.add_argument("--metric", choices=("euclid", "345"), default="euclid", help="distance metric (default euclid)")
    p.add_argument("--min-thinness", type=ascii_float, default=DEFAULT_MIN_THINNESS,
                   help=f"keep points with thinness >= this (default {DEFAULT_MIN_THINNESS}; -inf keeps all)")
    p.add_argument("--voxel-size", type=positive_float, metavar="MM",
                   help="skeletonize on cubes of this size (default: the scan's smallest spacing); a scan whose "
                        "voxels are not cubes is resampled, so spheres stay spheres in the body")
    p.add_argument("-o", "--output", required=True,
                   help="output .mskel (every thinness), or .skel (the points at --min-thinness, no thinness column)")

    p = add_command(sub, "isosurface", "Isosurface hull of the object as a mesh (.ply, .vtp, .obj, .stl).",
                    "volanim isosurface frog.VOL --threshold 1:255 -o frog-hull.ply", _isosurface)
    _segment_args(p)
    p.add_argument("--step", type=ascii_int, default=1, help="sampling step; > 1 gives a coarser mesh (skimage)")
    p.add_argument("--engine", choices=("vtk", "skimage"), default="vtk", help="marching cubes engine (default vtk)")
    p.add_argument("-o", "--output", required=True, help="output mesh")
