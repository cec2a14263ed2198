"""``volanim view``: a quick look at a volume, a sequence's frame or a mesh, in a window or as a picture."""

from __future__ import annotations

from ._common import add_command, ascii_int, checked_by, parse_range

EXAMPLE = (
    "volanim view arm.vti   # a window: drag to turn, wheel to zoom, q to close",
    "volanim view frog-hull.ply --screenshot hull.png   # no window: a picture (works without a display)",
    "volanim view walk.zarr --frame 10 --style volume --screenshot walk10.png",
    "volanim view frog.VOL --slices   # one z slice at a time, a slider to move through them",
    "volanim view mannequin.VOL --slices y --slice 40 --window 0:255 --screenshot slice.png",
)


def _view(args):
    import numpy as np

    if args.slices:
        return _view_slices(args)
    if args.slice is not None or args.window is not None:
        raise ValueError("--slice and --window choose a slice: add --slices")

    from volanim_core.render.movie import write_png
    from volanim_core.render.quicklook import quick_look
    from volanim_core.render.scene import can_open_window

    window = args.screenshot is None
    if window and not can_open_window():
        raise ValueError("no display to open a window on: add --screenshot FILE.png for a picture instead")
    renderer, what = quick_look(args.file, off_screen=True if not window else None, style=args.style,
                                preset=args.preset, view=args.view, frame=args.frame, dims=args.dims,
                                size=args.size)
    if window:
        print(f"{args.file}: {what}; drag to turn, wheel to zoom, q to close")
        renderer.plotter.show(title=f"volanim view {args.file}")
    else:
        image = renderer.plotter.screenshot(return_img=True)
        write_png(args.screenshot, np.asarray(image, np.uint8)[..., :3])
        print(f"wrote {args.screenshot} ({args.size[0]}x{args.size[1]}) of {args.file}: {what}")
    renderer.close()


def _view_slices(args):
    from volanim_core.io import read_scan
    from volanim_core.render.movie import write_png
    from volanim_core.render.scene import can_open_window
    from volanim_core.render.slice_view import SliceView
    from volanim_core.render.slices import AXES, describe, parse_slice_axis

    window = args.screenshot is None
    if window and not can_open_window():
        raise ValueError("no display to open a window on: add --screenshot FILE.png for a picture instead")
    scan = read_scan(args.file, dims=args.dims, colour=True)
    axis = parse_slice_axis(args.slices)
    n = scan.data.shape[axis]
    if args.slice is not None and not 0 <= args.slice < n:
        raise ValueError(f"{args.file}: --slice {args.slice} is outside the volume: {AXES[axis]} runs 0..{n - 1}")
    grey = None
    if args.window is not None:
        lo, hi = args.window
        if hi is None or not hi > lo:
            raise ValueError(f"--window needs LO:HI with LO < HI, got {lo:g}:{'' if hi is None else f'{hi:g}'}")
        grey = (lo, hi)
    view = SliceView(scan.data, scan.geometry.spacing, axis, args.slice, grey, off_screen=True if not window else None,
                     slider=window, title=f" of {n}")
    what = f"{AXES[axis]} slices 0..{n - 1} of {describe(scan.data, view.grey)}"
    if window:
        print(f"{args.file}: {what}; drag the slider, q to close")
        view.plotter.show(title=f"volanim view {args.file}")
    else:
        write_png(args.screenshot, view.screenshot())
        print(f"wrote {args.screenshot} ({view.size[0]}x{view.size[1]}): {AXES[axis]} slice {view.index} of "
              f"{args.file}: {what}")
    view.close()


def register(sub) -> None:
    from volanim_core.reconstruct.engine import MODES
    from volanim_core.render.scene import STYLES
    from volanim_core.render.views import VIEWS

    from .render_commands import parse_size

    p = add_command(sub, "view", "A quick look at a volume (.vti .nrrd .VOL .vol ...), one frame of a .zarr "
                    "sequence, or a mesh (.ply .vtp .obj .stl): a window, or a picture with --screenshot.",
                    EXAMPLE, _view)
    p.add_argument("file", help="a volume file, a .zarr sequence or a mesh file")
    p.add_argument("--screenshot", metavar="FILE.png", help="write a picture instead of opening a window")
    p.add_argument("--style", choices=STYLES, default="surface", help="volumes: surface (default) or volume")
    p.add_argument("--preset", choices=MODES, help="volume colours (default: the sequence's mode, else sampled)")
    p.add_argument("--view", choices=VIEWS, default="three-quarter", help="the starting view (default three-quarter)")
    p.add_argument("--frame", type=ascii_int, default=0, help="a sequence's frame, counted from 0 (default 0)")
    p.add_argument("--size", type=parse_size, default=(800, 600), metavar="WxH", help="pixels (default 800x600)")
    p.add_argument("--slices", nargs="?", const="z", metavar="AXIS",
                   type=checked_by("volanim_core.render.slices:parse_slice_axis"),
                   help="volumes: one slice at a time across AXIS (default z) with a slider, instead of the body")
    p.add_argument("--slice", type=ascii_int, metavar="K", help="with --slices: the slice shown first (default the "
                   "middle one)")
    p.add_argument("--window", type=parse_range, metavar="LO:HI", help="with --slices: the grey range shown black to "
                   "white (default the volume's smallest..largest value)")
    p.add_argument("--dims", nargs=3, type=ascii_int, metavar=("X", "Y", "Z"), help="dimensions of a headerless .vol")
