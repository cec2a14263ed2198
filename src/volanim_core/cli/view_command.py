"""``volanim view``: a quick look at a volume, a sequence's frame or a mesh, in a window or as a picture."""

from __future__ import annotations

import os
import sys

from ._common import add_command, ascii_int

EXAMPLE = (
    "volanim view arm.vti   # a window: drag to turn, wheel to zoom, q to close",
    "volanim view frog-hull.ply --screenshot hull.png   # no window: a picture (works without a display)",
    "volanim view walk.zarr --frame 10 --style volume --screenshot walk10.png",
)


def has_display() -> bool:
    """Whether an on-screen window can open (an X11 or Wayland display on Linux; always elsewhere)."""
    if sys.platform.startswith("linux"):
        return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
    return True


def _view(args):
    from pathlib import Path

    import numpy as np

    from volanim_core.io.mesh_files import MESH_SUFFIXES, read_mesh
    from volanim_core.render.camera import named_view
    from volanim_core.render.colours import SKIN
    from volanim_core.render.run import open_inputs, read_frame, write_png
    from volanim_core.render.scene import Renderer, RenderSettings

    window = args.screenshot is None
    off_screen_env = os.environ.get("PYVISTA_OFF_SCREEN", "").lower() == "true"
    if window and not has_display() and not off_screen_env:
        raise ValueError("no display to open a window on: add --screenshot FILE.png for a picture instead")
    w, h = args.size
    path = Path(args.file)
    if path.suffix.lower() in MESH_SUFFIXES:
        mesh = read_mesh(path)
        lo, hi = np.asarray(mesh.bounds[0::2]), np.asarray(mesh.bounds[1::2])
        settings = RenderSettings(named_view(args.view, tuple(lo), tuple(hi), aspect=w / h), size=(w, h))
        renderer = Renderer(settings, off_screen=True if not window else None)
        renderer.plotter.add_mesh(mesh, color=SKIN, smooth_shading=True, name="body", reset_camera=False)
        what = f"{mesh.n_points:,} points, {mesh.n_cells:,} faces"
    else:
        inputs = open_inputs([path], slice(args.frame, args.frame + 1), dims=args.dims)
        settings = RenderSettings(named_view(args.view, inputs.lo, inputs.hi, aspect=w / h), style=args.style,
                                  preset=args.preset or inputs.mode or "sampled", vmax=inputs.vmax, size=(w, h))
        renderer = Renderer(settings, off_screen=True if not window else None)
        ref = inputs.frames[0]
        volume, origin = read_frame(ref, args.dims)
        renderer.draw(volume, origin, ref.number)
        what = f"{volume.shape[0]}x{volume.shape[1]}x{volume.shape[2]} voxels, {settings.preset} colours"
    settings.camera.apply(renderer.plotter.camera)
    if window:
        print(f"{path}: {what}; drag to turn, wheel to zoom, q to close")
        renderer.plotter.show(title=f"volanim view {path.name}")
    else:
        image = renderer.plotter.screenshot(return_img=True)
        write_png(args.screenshot, np.asarray(image, np.uint8)[..., :3])
        print(f"wrote {args.screenshot} ({w}x{h}) of {path}: {what}")
    renderer.close()


def register(sub) -> None:
    from volanim_core.reconstruct.engine import MODES
    from volanim_core.render.camera import VIEWS
    from volanim_core.render.scene import STYLES

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
    p.add_argument("--dims", nargs=3, type=ascii_int, metavar=("X", "Y", "Z"), help="dimensions of a headerless .vol")
