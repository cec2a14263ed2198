"""One off-screen picture per frame, with the same camera, colours and overlay for every frame.

    RenderSettings (style, preset, transfer function, camera, size, background, cut, overlay)
    Renderer(settings) -- one off-screen plotter, kept for every frame a worker draws
        .render(volume[x, y, z], origin, number) -> (H, W, 3) uint8

Origins and the cut-away plane are in voxels; the camera is in world units,
voxel x ``spacing`` (1 on the command line: sequences are in voxels; the
studio's own spacing when it renders with its view's camera).

Styles: ``volume`` (ray-cast through a transfer function; the CPU ray caster
with ``mapper="cpu"``) and ``surface`` (the boundary of the filled voxels,
coloured by the voxel under it -- the studio's live-preview look, far faster
in software OpenGL). Presets follow the reconstruction mode: sampled grey,
categorical bone and mottle colours, a heat map with a colour bar for hotspot.
Colour ranges are fixed by the settings, never per frame, so a sequence does
not flicker. A cut-away plane empties the voxels on the side its normal points
to before drawing, so both styles show the inside of the posed body.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from volanim_core.render.bone_colours import SKIN, rgb
from volanim_core.render.views import Camera
from volanim_core.render.volume_style import (
    LABEL_MODES,
    add_volume_uncopied,
    apply_labels,
    apply_rgba,
    label_colours,
    label_steps,
    rgba_points,
    volume_mapper,
    vtk_functions,
)
from volanim_core.transfer_function import TransferFunction
from volanim_core.volume import to_grey

STYLES = ("surface", "volume")
MAPPERS = ("auto", "cpu", "gpu")
LABELS = 255  # label colours drawn for bone/mottled presets (bone colours repeat every 32, as in the studio)


@dataclass(frozen=True)
class RenderSettings:
    camera: Camera
    style: str = "surface"
    preset: str = "sampled"  # a reconstruction mode: how values become colours
    vmax: float = 255.0  # the top of the colour range (sampled, hotspot), fixed for the whole sequence
    transfer: TransferFunction | None = None  # replaces the preset's colours (volume and surface)
    size: tuple[int, int] = (640, 480)
    background: str = "black"
    cut: tuple[tuple[float, float, float], tuple[float, float, float]] | None = None  # (point, normal)
    title: str | None = None
    frame_numbers: bool = False
    mapper: str = "auto"  # volume style: "cpu" (fixed-point ray caster), "gpu" (VTK's smart mapper), "auto"
    spacing: tuple[float, float, float] = (1.0, 1.0, 1.0)  # world units per voxel (origins, cuts: in voxels)
    floor: tuple | None = None  # (down axis like "-z", body lo, body hi in voxels): a ground plane under the body

    def check(self) -> None:
        if self.style not in STYLES:
            raise ValueError(f"unknown style {self.style!r}; choose {' or '.join(STYLES)}")
        if self.mapper not in MAPPERS:
            raise ValueError(f"unknown mapper {self.mapper!r}; choose {' or '.join(MAPPERS)}")
        w, h = self.size
        if not (16 <= w <= 8192 and 16 <= h <= 8192):
            raise ValueError(f"a picture is 16..8192 pixels each way, got {w}x{h}")
        if self.cut is not None and not np.any(np.asarray(self.cut[1], np.float64)):
            raise ValueError("the cut-away plane's normal must not be zero")
        self.camera.check()


def preset_transfer(preset: str, vmax: float) -> TransferFunction:
    """The volume-style colours and opacities of a continuous preset (sampled grey, hotspot heat)."""
    top = max(float(vmax), 1.0)
    if preset == "hotspot":  # 1 sphere: dark red, faint ... the most: opaque pale yellow
        clear, hottest = [0, 0, 0, 0], [1.0, 1.0, 0.6, 0.9]
        if top <= 1.0:
            return TransferFunction([0.0, 0.5, 1.0], [clear, clear, hottest])
        return TransferFunction([0.0, 0.5, 1.0, (1.0 + top) / 2, top],
                                [clear, clear, [0.5, 0.0, 0.0, 0.15], [1.0, 0.45, 0.0, 0.4], hottest])
    # sampled grey: empty is clear, dim tissue faint, bright tissue nearly opaque
    return TransferFunction([0.0, 0.5, max(top * 0.25, 0.75), max(top, 1.0)],  # ascending even for 0/1 data
                            [[0, 0, 0, 0], [0.15, 0.15, 0.15, 0.0], [0.45, 0.45, 0.45, 0.08], [1, 1, 1, 0.8]])


def colour_table(settings: RenderSettings, vmax: float | None = None) -> np.ndarray:
    """``(L, 3)`` uint8: the surface colour of value v at row v (rounded), for every value up to vmax. With
    the user's transfer function ``(L, 4)``: its opacity too (#83: a movie's surfaces took the function's
    colours, not its opacity), and a value it makes clear is not drawn (:func:`prepare_frame`)."""
    top = int(np.ceil(vmax if vmax is not None else settings.vmax))
    values = np.arange(max(top, 1) + 1, dtype=np.float64)
    if settings.transfer is not None:
        return np.round(np.clip(settings.transfer(values), 0, 1) * 255).astype(np.uint8)
    elif settings.preset in LABEL_MODES:
        colours = label_colours(settings.preset, LABELS)
        rgb_ = np.vstack([[0, 0, 0], colours[(np.arange(1, len(values)) - 1) % len(colours)]])
    else:
        rgb_ = preset_transfer(settings.preset, settings.vmax)(values)[:, :3]
        if settings.preset == "sampled":  # a surface is opaque: keep the grey, not the near-black of the ramp
            rgb_ = np.maximum(rgb_, 0.25)
    return np.round(np.clip(rgb_, 0, 1) * 255).astype(np.uint8)


def transfer_of(settings: RenderSettings) -> TransferFunction:
    """The transfer function a volume-style render uses, as a ``.tf`` file can hold it (``--save-tf``):
    the user's, a continuous preset's, or for a label preset one flat step of colour per label."""
    if settings.transfer is not None:
        return settings.transfer
    if settings.preset not in LABEL_MODES:
        return preset_transfer(settings.preset, settings.vmax)
    return label_steps(colour_table(settings)[1:].astype(np.float64) / 255)  # row 0: the background


def _touches_edge(part: np.ndarray) -> bool:
    """Whether any filled voxel lies on a face of ``part`` (colour: black is empty)."""
    filled = part.any(axis=3) if part.ndim == 4 else part != 0
    return bool(filled[[0, -1]].any() or filled[:, [0, -1]].any() or filled[:, :, [0, -1]].any())


def crop(volume: np.ndarray, origin, pad: int = 1):
    """The smallest box holding every filled voxel (and ``pad`` empty ones around it), and its origin."""
    from volanim_core.volume import tight_bounds

    origin = np.asarray(origin, np.float64)
    box = tight_bounds(volume.any(axis=3) if volume.ndim == 4 else volume)  # colour: black is empty
    if box is None:
        return volume[:1, :1, :1] * 0, origin
    lo = np.maximum(np.array(box.lo) - pad, 0)
    hi = np.minimum(np.array(box.hi) + pad + 1, volume.shape[:3])
    return volume[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]], origin + lo


def cut_away(volume: np.ndarray, origin, point, normal) -> np.ndarray:
    """``volume`` with every voxel on the side ``normal`` points to (from ``point``) emptied."""
    n = np.asarray(normal, np.float64)
    d = -float(np.dot(n, np.asarray(point, np.float64) - np.asarray(origin, np.float64)))
    x, y, z = (np.arange(s, dtype=np.float64) for s in volume.shape[:3])
    side = (n[0] * x[:, None, None] + n[1] * y[None, :, None]) + (n[2] * z[None, None, :] + d) > 0
    out = volume.copy()
    out[side] = 0
    return out


FLOOR = "#777777"  # mid grey: seen on black and on white backgrounds


def floor_corners(down: str, lo, hi, spacing=(1.0, 1.0, 1.0)) -> np.ndarray:
    """``(4, 3)`` world corners of the ground under the body box ``lo..hi`` (voxel centres): the face of
    the box's lowest voxels along ``down``, a square centred under the box, twice its wider side across
    (the heap of a crumble lands on this floor: the lowest voxel the standing body had)."""
    from volanim_core.sequence.effects import parse_axis

    axis, sign = parse_axis(down)
    lo, hi = np.asarray(lo, np.float64) - 0.5, np.asarray(hi, np.float64) + 0.5  # voxel faces
    centre = (lo + hi) / 2
    u, v = [a for a in range(3) if a != axis]
    half = float(max(hi[u] - lo[u], hi[v] - lo[v]))  # half of twice the wider side
    corners = np.repeat(centre[None], 4, axis=0)
    corners[:, axis] = lo[axis] if sign < 0 else hi[axis]
    corners[:, u] += [-half, half, half, -half]
    corners[:, v] += [-half, -half, half, half]
    return corners * np.asarray(spacing, np.float64)


def floor_plane(down: str, lo, hi, spacing=(1.0, 1.0, 1.0)):
    """The ground of :func:`floor_corners` as a pyvista quad."""
    import pyvista as pv

    return pv.PolyData(floor_corners(down, lo, hi, spacing), faces=[4, 0, 1, 2, 3])


def has_display() -> bool:
    """Whether an on-screen window can open (an X11 or Wayland display on Linux; always elsewhere)."""
    import os
    import sys

    return not sys.platform.startswith("linux") or bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def can_open_window() -> bool:
    """Whether a pyvista window can be shown: a display, or pyvista's ``PYVISTA_OFF_SCREEN``
    (then ``show()`` draws off-screen and returns)."""
    import pyvista

    return has_display() or bool(pyvista.OFF_SCREEN)


def prefer_egl_without_display() -> None:
    """Without a display, ask VTK for its EGL window directly (before VTK makes its first window):
    its default X window would first fail with a "bad X server connection" warning."""
    import os

    if not has_display():
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")


@dataclass(frozen=True)
class PreparedFrame:
    """A frame ready to draw: the voxels as the settings colour them and, in the surface style, their surface."""
    volume: np.ndarray
    origin: np.ndarray
    mesh: object = None  # the surface style's
    data: np.ndarray | None = None  # the volume style's point values (x fastest; colour: RGBA)


def prepare_frame(settings: RenderSettings, volume: np.ndarray, origin, table=None) -> PreparedFrame:
    """The heavy part of drawing a frame, which needs no window (a reader thread may run it: the studio's
    quick look of a large volume, #61): the cut, the colours' one value a voxel, the surface style's mesh.
    ``table``: ``colour_table`` of the settings, when the caller keeps it."""
    from volanim_core.render.surfaces import label_surface

    s = settings
    if not (volume.ndim == 3 or (volume.ndim == 4 and volume.shape[3] == 3)):  # as the volume readers refuse it
        raise ValueError(f"a volume to draw is [x, y, z] or RGB [x, y, z, 3], got shape {volume.shape}")
    if s.cut is not None:
        volume = cut_away(volume, origin, *s.cut)
    if volume.ndim == 4 and s.transfer is not None:
        volume = to_grey(volume)  # a user's transfer function reads one value a voxel
    if s.preset == "binary" and s.transfer is None and volume.ndim == 3:
        volume = (volume > 0).astype(np.uint8)
    if s.style != "surface":
        if volume.ndim == 4:  # colour: RGB drawn as it is, black (the background) transparent
            data = rgba_points(volume)
        else:
            data = volume.astype(np.float32) if volume.dtype.kind == "f" or volume.dtype.itemsize > 2 else volume
            data = data.ravel(order="F")
        return PreparedFrame(volume, np.asarray(origin), data=data)
    part, at = crop(volume, origin)  # a sequence's shared grid is mostly empty
    if _touches_edge(part):
        # an object up to the grid's edge (a scan's body, a single DICOM slice): closed there, not left open
        # or, one voxel thick, drawn as nothing (#83: pydicom's CT_small.dcm viewed as an empty window)
        part = np.pad(part, [(1, 1)] * 3 + [(0, 0)] * (part.ndim - 3))
        at = np.asarray(at, np.float64) - 1
    values = part if np.issubdtype(part.dtype, np.integer) else np.rint(part)
    spacing = np.asarray(s.spacing, np.float64)  # world = voxel x spacing (the camera's units)
    table = colour_table(s) if table is None else table
    if table.shape[1] == 4 and values.ndim == 3:  # the user's function: what it makes clear is not there
        clear = table[np.clip(values.astype(np.int64), 0, len(table) - 1), 3] == 0
        if clear.any():
            values = np.where(clear, 0, values)
    mesh = label_surface(values, np.asarray(at) * spacing, spacing, table)  # above the range: top colour
    return PreparedFrame(volume, np.asarray(origin), mesh)


class Renderer:
    """One off-screen plotter that draws frame after frame with one camera.

    ``off_screen=None`` makes an on-screen window instead (``volanim view``; pyvista's
    ``PYVISTA_OFF_SCREEN`` still turns it off-screen); ``plotter`` draws into an existing
    pyvista plotter instead (the studio's quick-look window).
    """

    def __init__(self, settings: RenderSettings, off_screen: bool | None = True, plotter=None):
        prefer_egl_without_display()
        import pyvista as pv

        settings.check()
        self.settings = settings
        self.plotter = plotter if plotter is not None else pv.Plotter(off_screen=off_screen,
                                                                       window_size=tuple(settings.size))
        self.plotter.set_background(settings.background)
        if settings.style == "surface":
            self.plotter.enable_anti_aliasing("ssaa")  # voxel staircases shimmer less between frames
        self._grid = None  # the volume style's image data, refilled per frame when its shape stays
        self._grid_key = None
        self._first = True
        self._table = colour_table(settings)  # every frame's surface colours
        self._bar = None
        if settings.title:
            self.plotter.add_text(settings.title, position="upper_left", font_size=12, name="title",
                                  color=_contrast(settings.background))
        if settings.floor is not None:
            self.plotter.add_mesh(floor_plane(*settings.floor, settings.spacing), color=FLOOR, name="floor",
                                  reset_camera=False, render=False)
        settings.camera.apply(self.plotter.renderer.GetActiveCamera())
        self.plotter.camera_set = True  # never reset to fit a frame: the camera is the sequence's

    def render(self, volume: np.ndarray, origin, number: int | None = None, camera: Camera | None = None
               ) -> np.ndarray:
        """Draw a frame (with its own ``camera``, else the settings') and return its picture, ``(H, W, 3)`` uint8."""
        self.draw(volume, origin, number, camera)
        if self._first:  # pyvista renders an off-screen plotter at its first screenshot only
            self._first = False
            image = self.plotter.screenshot(return_img=True)
        else:
            self.plotter.ren_win.Render()  # exactly one render per frame, then read the pixels
            image = self.plotter.image
        return np.asarray(image, np.uint8)[..., :3].copy()

    def draw(self, volume: np.ndarray, origin, number: int | None = None, camera: Camera | None = None) -> None:
        """Put a frame's actors in the scene (no rendering yet)."""
        self.show(prepare_frame(self.settings, volume, origin, self._table), number, camera)

    def show(self, frame: PreparedFrame, number: int | None = None, camera: Camera | None = None) -> None:
        """Put a frame :func:`~volanim_core.render.scene.prepare_frame` made (any thread) in the scene: only VTK
        actors here."""
        s = self.settings
        if s.style == "surface":
            self._draw_surface(frame.mesh)
        else:
            self._draw_volume(frame.volume, frame.origin, frame.data)
        if s.preset == "hotspot" and self._bar is None:
            self._add_colour_bar()
        if s.frame_numbers and number is not None:
            self.plotter.add_text(f"frame {number}", position="upper_right", font_size=12, name="frame",
                                  color=_contrast(s.background), render=False)
        (camera or s.camera).apply(self.plotter.renderer.GetActiveCamera())  # adding actors must not move it
        reset_clipping(self.plotter.renderer)

    def close(self) -> None:
        self.plotter.close()

    def _draw_surface(self, mesh) -> None:
        if mesh.n_points == 0:
            self.plotter.remove_actor("body", render=False)
            return
        self.plotter.add_mesh(mesh, scalars="rgb", rgb=True, name="body", reset_camera=False,
                              smooth_shading=False, show_scalar_bar=False, render=False)

    def _draw_volume(self, volume, origin, data) -> None:
        import pyvista as pv

        s = self.settings
        # the whole shared grid, refilled frame after frame: a new volume actor costs a VTK pipeline
        # set-up per frame, so cropping each frame to its body would be slower than drawing it
        key = (volume.shape, tuple(float(v) for v in np.asarray(origin) * s.spacing), data.dtype.str)
        if self._grid is not None and self._grid_key == key:
            from vtkmodules.util.numpy_support import numpy_to_vtk

            values = numpy_to_vtk(data, deep=True)
            values.SetName("v")
            self._grid.GetPointData().SetScalars(values)  # the image the mapper reads (add_volume may copy ours)
            self._grid.Modified()
            return
        grid = pv.ImageData(dimensions=volume.shape[:3], origin=key[1], spacing=s.spacing)
        grid.point_data["v"] = data
        actor = add_volume_uncopied(self.plotter, grid, "v", name="body", reset_camera=False, show_scalar_bar=False,
                                    mapper=volume_mapper("fixed_point" if self._cpu_caster() else "smart",
                                                         1 if data.ndim == 1 else data.shape[1]), render=False)
        self._grid, self._grid_key = actor.GetMapper().GetInput(), key
        prop = actor.GetProperty()
        if volume.ndim == 4:
            apply_rgba(actor)
        elif s.transfer is None and s.preset in LABEL_MODES:
            colours = (np.array([rgb(SKIN)]) if s.preset == "binary"
                       else label_colours(s.preset, LABELS))
            apply_labels(actor, colours, opacity=1.0)
        else:
            ctf, otf = vtk_functions(s.transfer or preset_transfer(s.preset, s.vmax))
            prop.SetColor(ctf)
            prop.SetScalarOpacity(otf)
            prop.SetInterpolationTypeToLinear()
        prop.ShadeOn()
        prop.SetAmbient(0.35)

    def _cpu_caster(self) -> bool:
        """``cpu``: the fixed-point ray caster; ``gpu`` and an unresolved ``auto``: VTK's smart mapper.
        (A sequence's driver resolves ``auto`` by timing both, :func:`volanim_core.render.movie.choose_mapper`.)"""
        return self.settings.mapper == "cpu"

    def _add_colour_bar(self) -> None:
        import vtk

        s = self.settings
        ctf, _ = vtk_functions(s.transfer or preset_transfer("hotspot", s.vmax))
        bar = vtk.vtkScalarBarActor()
        bar.SetLookupTable(ctf)
        bar.SetTitle("spheres per voxel")
        bar.SetNumberOfLabels(4)
        bar.SetPosition(0.88, 0.1)
        bar.SetWidth(0.1)
        bar.SetHeight(0.8)
        for text in (bar.GetTitleTextProperty(), bar.GetLabelTextProperty()):
            text.SetColor(*rgb(_contrast(s.background)))
        self.plotter.add_actor(bar, reset_camera=False, name="colour bar", render=False)
        self._bar = bar


def visible_bounds(renderer) -> list[float] | None:
    """``[x0, x1, y0, y1, z0, z1]`` of everything drawn in ``renderer``'s window with its camera -- its own
    props and those of the layers over it (the studio's x-ray layer) -- or None when nothing is."""
    renderers = [renderer]
    window = renderer.GetRenderWindow()
    if window is not None:
        collection = window.GetRenderers()
        renderers += [collection.GetItemAsObject(k) for k in range(collection.GetNumberOfItems())]
    boxes = [b for r in renderers if r.GetDraw() and r.GetActiveCamera() is renderer.GetActiveCamera()
             for b in [r.ComputeVisiblePropBounds()] if b[0] <= b[1]]
    if not boxes:
        return None
    b = np.array(boxes)
    return [float(b[:, 0].min()), float(b[:, 1].max()), float(b[:, 2].min()), float(b[:, 3].max()),
            float(b[:, 4].min()), float(b[:, 5].max())]


def reset_clipping(renderer) -> None:
    """Near and far planes from what is in view now (:func:`visible_bounds`). Every path that moves a
    camera or changes what is drawn calls this: a camera placed far from the body (a long walk's shared
    grid, a large scan, a camera file) otherwise keeps planes that cut the whole body away -- black or
    half pictures."""
    bounds = visible_bounds(renderer)
    if bounds is None:
        renderer.ResetCameraClippingRange()
    else:
        renderer.ResetCameraClippingRange(*bounds)


def check_colour(text: str) -> None:
    """Refuse (ValueError) what is not a colour name or ``#rrggbb``."""
    from pyvista import Color

    try:
        Color(text)
    except ValueError:
        raise ValueError(f"not a colour: {text!r} (a name like black, or #rrggbb)") from None


def _contrast(background: str) -> str:
    """White text on a dark background, black on a light one."""
    from pyvista import Color

    r, g, b = Color(background).float_rgb
    return "#000000" if 0.2126 * r + 0.7152 * g + 0.0722 * b > 0.5 else "#ffffff"
