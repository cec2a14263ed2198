"""How a reconstructed volume is drawn: one transfer function per reconstruction mode.

    mode --volume_style--> add_volume keyword arguments (+ label colours for label modes)
    label colours --apply_labels--> VTK colour/opacity steps at half-integers (no blending)
"""

from __future__ import annotations

import numpy as np

from volanim_core.render.bone_colours import SKIN, bone_colours, rgb
from volanim_core.transfer_function import TransferFunction

LABEL_MODES = ("bone", "mottled", "binary")


def volume_style(mode: str, volume: np.ndarray, n_bones: int) -> dict:
    """Keyword arguments for ``pyvista.Plotter.add_volume``.

    Labels (bone, mottled, binary) get categorical colours (key ``categories``,
    for :func:`apply_labels`), nearest-neighbour interpolation and transparent 0;
    sampled grey data a grey ramp; hotspot a hot colour map with a colour bar.
    """
    vmax = float(volume.max()) if volume.size else 1.0
    if mode in LABEL_MODES:
        return {"cmap": "gray", "clim": (0, max(vmax, 1.0)), "show_scalar_bar": False,
                "categories": label_colours(mode, n_bones)}
    if mode == "hotspot":
        return {"cmap": "hot", "clim": (0, max(vmax, 1.0)), "opacity": "linear", "show_scalar_bar": True,
                "scalar_bar_args": {"title": "spheres per voxel"}}
    return {"cmap": "gray", "clim": (0, max(vmax, 1.0)), "opacity": "sigmoid_5", "show_scalar_bar": False}


def vtk_functions(tf) -> tuple:
    """A :class:`~volanim_core.transfer_function.TransferFunction` as VTK's
    ``(vtkColorTransferFunction, vtkPiecewiseFunction)``, with exactly its points."""
    import vtk

    ctf, otf = vtk.vtkColorTransferFunction(), vtk.vtkPiecewiseFunction()
    for v, (r, g, b, a) in zip(tf.values, tf.rgba):
        ctf.AddRGBPoint(float(v), float(r), float(g), float(b))
        otf.AddPoint(float(v), float(a))
    return ctf, otf


def label_colours(mode: str, n_bones: int) -> np.ndarray:
    """RGB (0..1) per label value 1..N: bone colours, a per-sphere mottle, or one colour."""
    if mode == "bone":
        return bone_colours(max(n_bones, 1))
    if mode == "mottled":
        return np.random.default_rng(7).uniform(0.25, 1.0, (255, 3))
    return np.array([rgb(SKIN)])


LABEL_STEP = 0.49  # label v is its colour over v +- 0.49: neighbouring labels never mix
LABEL_OPACITY = 0.85


def label_steps(colours: np.ndarray, opacity: float = LABEL_OPACITY) -> TransferFunction:
    """Labels as a transfer function: value v (1..N) -> ``colours[v - 1]`` (RGB 0..1) at ``opacity``, flat over
    v +- 0.49; 0 transparent. The one rule the studio's label previews, ``render --save-tf`` and the studio's
    transfer-function editor (its starting point in a label mode) share."""
    values, rgba = [0.0, 0.5], [[0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]]
    for v, c in enumerate(np.asarray(colours, np.float64).reshape(-1, 3), start=1):
        values += [v - LABEL_STEP, v + LABEL_STEP]
        rgba += [[*c, opacity]] * 2
    return TransferFunction(values, rgba)


def apply_labels(volume_actor, colours: np.ndarray, opacity: float = LABEL_OPACITY) -> None:
    """Label transfer functions (:func:`label_steps`) on a VTK volume, with no blending between voxels."""
    ctf, otf = vtk_functions(label_steps(colours, opacity))
    prop = volume_actor.GetProperty()
    prop.SetColor(ctf)
    prop.SetScalarOpacity(otf)
    prop.SetInterpolationTypeToNearest()


def rgba_points(volume: np.ndarray) -> np.ndarray:
    """A colour volume ``[x, y, z, 3]`` as VTK point scalars ``(N, 4)`` uint8, x fastest: its RGB and
    an alpha of 255 where a voxel is filled, 0 where it is black (the background)."""
    opaque = (volume.max(axis=3, keepdims=True) > 0).astype(np.uint8) * 255
    return np.ascontiguousarray(np.concatenate([volume, opaque], axis=3).transpose(2, 1, 0, 3)).reshape(-1, 4)


def apply_rgba(volume_actor, opacity: float = 0.9) -> None:
    """Draw :func:`rgba_points` scalars as they are: RGB straight to the screen (no transfer function),
    the 4th component through the opacity (VTK's dependent components)."""
    import vtk

    prop = volume_actor.GetProperty()
    prop.SetIndependentComponents(False)
    otf = vtk.vtkPiecewiseFunction()
    otf.AddPoint(0.0, 0.0)
    otf.AddPoint(255.0, opacity)
    prop.SetScalarOpacity(otf)
    prop.SetInterpolationTypeToLinear()


SOFTWARE_RENDERERS = ("llvmpipe", "softpipe", "swrast", "software rasterizer", "swr ")


def gl_renderer(render_window) -> str:
    """The OpenGL renderer string of a VTK render window ('' until its context exists)."""
    for line in (render_window.ReportCapabilities() or "").splitlines():
        if "renderer string" in line.lower():
            return line.split(":", 1)[1].strip()
    return ""


def software_gl(renderer: str) -> bool:
    """Whether an OpenGL renderer string (:func:`gl_renderer`) names a software rasteriser
    (Mesa's llvmpipe and kin).

    There VTK's fixed-point CPU ray caster draws a posed reconstruction as fast as the smart
    mapper's shader or faster -- the frog's bone preview at 1200x800: 0.37 s against 0.86 s, its
    sampled preview 0.85 against 0.87 s -- while on a GPU the shader is far faster.
    """
    name = renderer.lower() + " "
    return any(soft in name for soft in SOFTWARE_RENDERERS)


def volume_mapper(requested: str, components: int) -> str:
    """pyvista's name of the volume mapper that draws this case right: ``requested`` is ``"fixed_point"``
    (the CPU ray caster) or ``"smart"``. The fixed-point caster draws 4-component RGBA (dependent
    components) wrong -- the colour mannequin lost both arms and the front of its chest, 30 % of its
    silhouette (tests/core/render/test_picture_oracle.py) -- so colour always goes to the smart mapper."""
    return "smart" if components == 4 else requested


def add_volume_uncopied(plotter, grid, scalars: str, **kwargs):
    """``plotter.add_volume(grid, ...)`` without its copy of the grid.

    pyvista's ``add_volume`` runs ``cell_data_to_point_data`` on any dataset it is
    given -- a full copy through a VTK filter, 1.8 s for the frog's posed 45 M
    voxels, longer than the reconstruction. The actor is made on a 2^3 corner of
    the grid (same array name, dtype and components; give ``clim`` so the colour
    range does not come from it) and then reads the grid itself.
    """
    import pyvista as pv

    corner = pv.ImageData(dimensions=(2, 2, 2), origin=grid.origin, spacing=grid.spacing)
    values = np.asarray(grid.point_data[scalars])
    corner.point_data[scalars] = values[: 8]
    actor = plotter.add_volume(corner, scalars=scalars, **kwargs)
    actor.GetMapper().SetInputData(grid)
    return actor


#: Ray samples a still frame of the CPU ray caster may take with one ray per pixel (~50 ms of the GUI thread
#: here, on software GL). The mannequin's posed preview in the studio's view takes ~6e7 (drawn with every ray,
#: as the picture tests compare it with its voxels); mannequin-large's ~2.5e8.
RAY_SAMPLES_BUDGET = 1.2e8


def ray_spacing(rays: float, samples_per_ray: float) -> float:
    """Pixels between two rays of the CPU ray caster so that a still frame takes about
    :data:`RAY_SAMPLES_BUDGET` samples (#83: mannequin-large's posed preview held the GUI thread 0.17 s a
    frame, every frame, on software GL). Rays fall as the square of their spacing. Decided by the picture's
    size on screen and the volume's depth alone, never by a timing, so a picture is the same on a busy
    machine (VTK's own auto-adjust, by timing, is left to interaction)."""
    return float(max(1.0, min(4.0, np.sqrt(rays * samples_per_ray / RAY_SAMPLES_BUDGET))))


def limit_ray_cost(actor, renderer, step: float = 1.0) -> float:
    """Bound the cost of a still frame of ``actor``'s CPU ray-cast mapper (a GPU mapper is left as it is):
    one sample per ``step`` world units along a ray (``step`` > 1: a coarser copy of the volume, sampled at
    its own resolution) and rays spaced by :func:`ray_spacing` for the pixels its box covers in
    ``renderer``'s view now. Returns the spacing."""
    mapper = actor.GetMapper()
    if not hasattr(mapper, "SetMinimumImageSampleDistance"):
        return 1.0
    mapper.SetSampleDistance(float(step))
    b = np.asarray(mapper.GetInput().GetBounds(), np.float64)
    diagonal = float(np.linalg.norm(b[1::2] - b[::2]))
    d = ray_spacing(_covered_pixels(renderer, b), diagonal / step)
    mapper.SetImageSampleDistance(d)
    mapper.SetMinimumImageSampleDistance(d)  # auto-adjust (interaction) may go coarser, never finer
    mapper.SetMaximumImageSampleDistance(max(d, mapper.GetMaximumImageSampleDistance()))
    return d


def _covered_pixels(renderer, bounds) -> float:
    """The pixels of ``renderer``'s viewport inside the screen rectangle of a box's eight corners."""
    xs, ys = [], []
    for x in bounds[0:2]:
        for y in bounds[2:4]:
            for z in bounds[4:6]:
                renderer.SetWorldPoint(float(x), float(y), float(z), 1.0)
                renderer.WorldToDisplay()
                px, py, _ = renderer.GetDisplayPoint()
                xs.append(px)
                ys.append(py)
    width, height = renderer.GetSize()
    w = min(max(xs), width) - max(min(xs), 0)
    h = min(max(ys), height) - max(min(ys), 0)
    return float(max(w, 0) * max(h, 0))


def binary_view(volume: np.ndarray) -> np.ndarray:
    """A binary-mode volume as labels 0/1 (one colour for every filled voxel)."""
    return (volume > 0).astype(np.uint8)
