"""``volanim render``: volumes and sequences to pictures and movies (the old ``vtkRender``)."""

from __future__ import annotations

import argparse
import sys

from ._common import (
    FrameProgress,
    add_command,
    add_pool,
    ascii_int,
    checked_by,
    dask_scheduler,
    finite_float,
    local_workers,
    positive_float,
)

EXAMPLE = (
    "volanim render walk.zarr -o walk.mp4   # the sequence's mode picks the colours",
    "volanim render walk.zarr -o walk.gif --size 320x240 --view front --frame-numbers --save-camera front.camera",
    "volanim render arm.vti -o arm.png --style volume --save-tf arm.tf   # the preset, to edit",
    "volanim render arm.vti -o arm-edited.png --style volume --tf arm.tf",
    "volanim render walk.zarr -o frames/ --camera front.camera --cut 80 50 150 0 -1 0   # cut away the front half",
    "volanim render walk.zarr -o walk-follow.mp4 --camera follow --view side   # the camera walks along",
    "volanim render crumble.zarr -o heap.png --frames=-1: --view side --floor   # the heap on its ground",
)


def parse_size(text: str) -> tuple[int, int]:
    parts = text.lower().split("x")
    if len(parts) != 2 or not all(p.isascii() and p.isdigit() for p in parts):
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT in pixels, e.g. 640x480, got {text!r}")
    w, h = (int(p) for p in parts)
    if not (16 <= w <= 8192 and 16 <= h <= 8192):
        raise argparse.ArgumentTypeError(f"a picture is 16..8192 pixels each way, got {text}")
    return w, h


class CutAction(argparse.Action):
    """``--cut X Y Z NX NY NZ``: a point and a normal that is not zero."""

    def __call__(self, parser, namespace, values, option_string=None):
        if not any(values[3:]):
            parser.error(f"argument {option_string}: the normal NX NY NZ must not be 0 0 0")
        setattr(namespace, self.dest, values)


def _render(args):
    import numpy as np

    from volanim_core import io
    from volanim_core.parallel import RunOn
    from volanim_core.render.framing import place_camera
    from volanim_core.render.movie import open_inputs, render
    from volanim_core.render.scene import RenderSettings, transfer_of

    inputs = open_inputs(args.inputs, args.range, dims=args.dims)
    if inputs.unverified:  # every frame of a store with regions is checked against its sha256 as it is read
        print(f"note: {inputs.unverified} frames were not verified: the store predates frame checksums by region "
              "(rerun `volanim sequence --force` to record them)", file=sys.stderr)
    preset = args.preset or inputs.mode or "sampled"
    w, h = args.size
    if args.view and args.camera not in (None, "follow"):
        raise ValueError("--view and a camera file both place the camera: give one (or --camera follow --view ...)")
    args.view = args.view or "three-quarter"
    voxels = 1 / np.asarray(inputs.spacing)  # camera files are in voxels, the scene in voxel x spacing
    given = args.camera if args.camera in (None, "follow") else io.read_camera(args.camera).scaled(inputs.spacing)
    camera, inputs = place_camera(inputs, args.view, given, aspect=w / h)
    if args.save_camera:
        io.write_camera(args.save_camera, camera.scaled(voxels))
    cut = None
    if args.cut:
        cut = (tuple(args.cut[:3]), tuple(args.cut[3:]))
    settings = RenderSettings(camera, style=args.style, preset=preset, vmax=inputs.vmax,
                              transfer=io.read_transfer_function(args.tf) if args.tf else None, size=(w, h),
                              background=args.background, cut=cut, title=args.title,
                              frame_numbers=args.frame_numbers, mapper=args.mapper, spacing=inputs.spacing,
                              floor=(args.floor, inputs.lo, inputs.hi) if args.floor else None)
    if args.save_tf:
        io.write_transfer_function(args.save_tf, transfer_of(settings))
        print(f"wrote {args.save_tf} (the {'--tf' if args.tf else preset + ' preset'}'s transfer function)")
    workers = local_workers(args)
    with dask_scheduler(args) as scheduler:
        rep = render(inputs, settings, args.output, on=RunOn(workers=workers or 1, scheduler=scheduler), fps=args.fps,
                     force=args.force, keep_frames=args.keep_frames, dims=args.dims, on_frame=FrameProgress())
    print(file=sys.stderr)
    print(f"wrote {rep.out}: {rep.frames} frame{'s' if rep.frames != 1 else ''} of {w}x{h} ({args.style}, {preset} "
          f"colours), {rep.drawn} drawn, {rep.skipped} already there; {rep.workers}; {rep.seconds:.1f} s"
          + (f"; {rep.fps:g} fps" if rep.frames > 1 else "") + (f"; {rep.mapper} mapper" if args.style == "volume"
                                                                   else ""))


def register(sub) -> None:
    from volanim_core.reconstruct.engine import MODES
    from volanim_core.render.scene import MAPPERS, STYLES
    from volanim_core.render.views import VIEWS

    from .motion_commands import parse_frames

    p = add_command(sub, "render", "Render a volume, several volumes or a zarr sequence to a PNG, a folder of "
                    "PNGs, an .mp4 or a .gif, with one fixed camera, off-screen.", EXAMPLE, _render)
    p.add_argument("inputs", nargs="+", help="a .zarr sequence, or volume files (.vti .nrrd .vol .VOL ...)")
    p.add_argument("-o", "--output", required=True, type=checked_by("volanim_core.render.movie:check_output"),
                   help="NAME.png (one frame), a folder, NAME.mp4 or NAME.gif")
    p.add_argument("--style", choices=STYLES, default="surface",
                   help="surface: the filled voxels' boundary (fast); volume: ray-cast (default surface)")
    p.add_argument("--preset", choices=MODES, help="colours for this reconstruction mode (default: the "
                   "sequence's mode, else sampled)")
    p.add_argument("--tf", metavar="FILE.tf", help="a transfer function: VALUE RED GREEN BLUE ALPHA per line (0..1)")
    p.add_argument("--view", choices=VIEWS, help="a named view (default three-quarter)")
    p.add_argument("--camera", metavar="FILE.camera|follow", help="a camera file (the studio: View > Save "
                       "view as camera file), or follow: the --view direction, each frame centred on its body "
                       "(smoothed). Default: --view framing every frame's body")
    p.add_argument("--save-camera", metavar="FILE.camera", help="also write the camera used, to edit or reuse")
    p.add_argument("--save-tf", metavar="FILE.tf", help="also write the transfer function used (the preset's, "
                   "for a label preset one colour step per label), to edit and pass to --tf")
    p.add_argument("--size", type=parse_size, default=(640, 480), metavar="WxH",
                   help="pixels (default 640x480; .mp4 needs multiples of 16)")
    p.add_argument("--background", default="black",
                   type=checked_by("volanim_core.render.scene:check_colour"), help="a colour name or #rrggbb")
    p.add_argument("--cut", nargs=6, type=finite_float, action=CutAction, metavar=("X", "Y", "Z", "NX", "NY", "NZ"),
                   help="cut away everything on the side the normal (NX NY NZ) points to from voxel (X Y Z)")
    p.add_argument("--floor", nargs="?", const="-z", metavar="DOWN",
                   type=checked_by("volanim_core.sequence.effects:parse_axis"),
                   help="a grey ground under the lowest voxel any frame fills along DOWN (default -z): where a "
                   "crumble's heap lands")
    p.add_argument("--title", help="text in the top left corner")
    p.add_argument("--frame-numbers", action="store_true", help="the frame number in the top right corner")
    p.add_argument("--fps", type=positive_float, help="movie frame rate (default: the sequence's, else 24)")
    p.add_argument("--frames", dest="range", type=parse_frames, default=slice(None), metavar="START:STOP:STEP",
                   help="which frames (counted from 0)")
    add_pool(p, "draw")
    p.add_argument("--mapper", choices=MAPPERS, default="auto",
                   help="volume style: cpu (the fixed-point ray caster), gpu (VTK's smart mapper) or auto (the "
                   "faster of the two on this data, timed once before the run)")
    p.add_argument("--force", action="store_true", help="draw every frame again")
    p.add_argument("--keep-frames", action="store_true", help="keep a movie's PNG frames (.NAME.frames/)")
    p.add_argument("--dims", nargs=3, type=ascii_int, metavar=("X", "Y", "Z"), help="dimensions of a headerless .vol")
