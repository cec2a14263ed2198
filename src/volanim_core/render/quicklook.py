"""A quick look at one file: a volume, one frame of a zarr sequence, or a mesh, from a named view.

Used by ``volanim view`` (a pyvista window or a picture) and by the studio's
*File → View volume or mesh…* (a window of its own); both draw through the
same ``Renderer`` as ``volanim render``, so a quick look shows what a movie will.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .scene import Renderer, RenderSettings, reset_clipping


def quick_look(path, *, plotter=None, off_screen: bool | None = True, style: str = "surface",
               preset: str | None = None, view: str = "three-quarter", frame: int = 0, dims=None,
               size=(800, 600)) -> tuple[Renderer, str]:
    """Draw ``path`` (not rendered yet) and return the renderer and a one-line description of what it shows."""
    from volanim_core.io.mesh_files import MESH_SUFFIXES, read_mesh

    from .bone_colours import SKIN
    from .camera import named_view, place_camera
    from .movie import open_inputs, read_frame

    path = Path(path)
    w, h = size
    if path.suffix.lower() in MESH_SUFFIXES:
        mesh = read_mesh(path)
        lo, hi = tuple(np.asarray(mesh.bounds[0::2])), tuple(np.asarray(mesh.bounds[1::2]))
        settings = RenderSettings(named_view(view, lo, hi, aspect=w / h, faces=0.0), size=(w, h))
        renderer = Renderer(settings, off_screen=off_screen, plotter=plotter)
        renderer.plotter.add_mesh(mesh, color=SKIN, smooth_shading=True, name="body", reset_camera=False)
        settings.camera.apply(renderer.plotter.renderer.GetActiveCamera())  # (a volume's draw() applies it)
        reset_clipping(renderer.plotter.renderer)
        what = f"{mesh.n_points:,} points, {mesh.n_cells:,} faces"
    else:
        camera, inputs = place_camera(open_inputs([path], slice(frame, frame + 1), dims=dims), view, aspect=w / h)
        settings = RenderSettings(camera, style=style, preset=preset or inputs.mode or "sampled", vmax=inputs.vmax,
                                  size=(w, h), spacing=inputs.spacing)
        renderer = Renderer(settings, off_screen=off_screen, plotter=plotter)
        ref = inputs.frames[0]
        volume, origin = read_frame(ref, dims)
        renderer.draw(volume, origin, ref.number)
        shown = "RGB" if volume.ndim == 4 else settings.preset
        what = f"{volume.shape[0]}x{volume.shape[1]}x{volume.shape[2]} voxels, {shown} colours"
        if ref.index >= 0:
            what = f"frame {ref.number}: {what}"
    return renderer, what
