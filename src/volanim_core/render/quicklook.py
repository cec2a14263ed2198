"""A quick look at one file: a volume, one frame of a zarr sequence, or a mesh, from a named view.

Used by ``volanim view`` (a pyvista window or a picture) and by the studio's
*File → View volume or mesh…* (a window of its own); both draw through the
same ``Renderer`` as ``volanim render``, so a quick look shows what a movie will.

    file --read_look (reads, and makes the surface: any thread)--> Look (settings, mesh or prepared frame,
         description) --draw_look (the GUI thread: VTK actors only)--> Renderer
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .scene import PreparedFrame, Renderer, RenderSettings, prepare_frame, reset_clipping


@dataclass
class Look:
    """What a quick look draws, read from its file: a mesh, or a volume and its origin and frame number,
    with the settings to draw it by and a one-line description. Making one reads the file and opens no
    window, so a worker thread may make it (the studio does) and the GUI thread draw it."""

    settings: RenderSettings
    what: str
    mesh: object = None
    volume: np.ndarray | None = None
    origin: np.ndarray | None = None
    number: int = 0
    frame: PreparedFrame | None = None  # the volume, ready to draw


def read_look(path, *, style: str = "surface", preset: str | None = None, view: str = "three-quarter",
              frame: int = 0, dims=None, size=(800, 600), transfer=None) -> Look:
    """Read ``path`` (a mesh, a volume, or frame ``frame`` of a sequence) for :func:`draw_look`;
    ``transfer`` (a :class:`~volanim_core.transfer_function.TransferFunction`) colours a volume instead of
    its preset (a colour volume by its luminance; a colour sequence's frame likewise, through its palette)."""
    from volanim_core.io.mesh_files import READ_MESH_SUFFIXES, read_mesh

    from .framing import place_camera
    from .movie import open_inputs, read_frame
    from .views import named_view

    path = Path(path)
    w, h = size
    if path.suffix.lower() in READ_MESH_SUFFIXES:
        mesh = read_mesh(path)
        lo, hi = tuple(np.asarray(mesh.bounds[0::2])), tuple(np.asarray(mesh.bounds[1::2]))
        settings = RenderSettings(named_view(view, lo, hi, aspect=w / h, faces=0.0), size=(w, h))
        return Look(settings, f"{mesh.n_points:,} points, {mesh.n_cells:,} faces", mesh=mesh)
    camera, inputs = place_camera(open_inputs([path], slice(frame, frame + 1), dims=dims), view, aspect=w / h)
    settings = RenderSettings(camera, style=style, preset=preset or inputs.mode or "sampled", vmax=inputs.vmax,
                              size=(w, h), spacing=inputs.spacing, transfer=transfer)
    ref = inputs.frames[0]
    volume, origin = read_frame(ref, dims)  # a colour sequence's frame in colours: the function reads luminance
    shown = "RGB" if volume.ndim == 4 else settings.preset
    what = f"{volume.shape[0]}x{volume.shape[1]}x{volume.shape[2]} voxels, {shown} colours"
    level = _object_level(volume) if style == "surface" and settings.preset == "sampled" and transfer is None \
        else None
    if level is not None:  # a scan's surface: the object's, not the box of its noisy background
        volume = np.where(volume >= level, volume, 0).astype(volume.dtype)
        what += f", surface at {level:g} and above (Otsu's level: the scan's background is not empty)"
    if ref.index >= 0:
        what = f"frame {ref.number}: {what}"
    # the surface (or the volume's point values) made here, off the GUI thread: only actors are left to draw
    return Look(settings, what, volume=volume, origin=origin, number=ref.number,
                frame=prepare_frame(settings, volume, origin))


def _object_level(volume: np.ndarray) -> float | None:
    """The value a grey scan's object starts at, when the scan has no empty background (over half its voxels
    non-zero: an MRI's noise, a CT's air at -1000): Otsu's threshold of (up to 2 M of) its values. None for a
    volume with an empty background (a reconstruction, a segmented scan): its surface is its non-zero voxels.
    #83: nibabel's anatomical.nii, viewed, showed a few specks -- the inside of the box its noise filled."""
    if volume.ndim != 3 or volume.size == 0:
        return None
    sample = volume.ravel()[:: max(1, volume.size // 2_000_000)]
    sample = sample[np.isfinite(sample)] if sample.dtype.kind == "f" else sample
    if sample.size == 0 or (sample != 0).mean() <= 0.5 or sample.min() == sample.max():
        return None
    from skimage.filters import threshold_otsu

    level = float(threshold_otsu(sample))
    return float(np.ceil(level)) if volume.dtype.kind in "ui" else level


def draw_look(look: Look, *, plotter=None, off_screen: bool | None = True) -> Renderer:
    """Draw a :class:`Look` (not rendered yet) into ``plotter`` (or a renderer's own window)."""
    from .bone_colours import SKIN

    renderer = Renderer(look.settings, off_screen=off_screen, plotter=plotter)
    if look.mesh is not None:
        renderer.plotter.add_mesh(look.mesh, color=SKIN, smooth_shading=True, name="body", reset_camera=False)
        look.settings.camera.apply(renderer.plotter.renderer.GetActiveCamera())  # (a volume's draw() applies it)
        reset_clipping(renderer.plotter.renderer)
    else:
        renderer.show(look.frame, look.number)
    return renderer


def quick_look(path, *, plotter=None, off_screen: bool | None = True, style: str = "surface",
               preset: str | None = None, view: str = "three-quarter", frame: int = 0, dims=None,
               size=(800, 600)) -> tuple[Renderer, str]:
    """Draw ``path`` (not rendered yet) and return the renderer and a one-line description of what it shows."""
    look = read_look(path, style=style, preset=preset, view=view, frame=frame, dims=dims, size=size)
    return draw_look(look, plotter=plotter, off_screen=off_screen), look.what
