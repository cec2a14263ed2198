"""Preview reconstructions for the studio: full or reduced resolution, plus the report. Qt-free.

A reduced preview reconstructs on a ``factor``-times coarser grid: the bone
matrices are followed by a 1/factor scale and radii shrink alike, so the
voxel count (the cost) drops by factor^3 while the shape stays.

Live previews (a drag, the timeline playing) come from :class:`LivePreviews`: one
:class:`~volanim_core.reconstruct.live_owned.LiveOwned` (the rig's owned body: only the box the moved
bones reach is redone, #85) or :class:`~volanim_core.reconstruct.live.LiveFrame` (the thesis's spheres:
only the slices the moved spheres reach, #65) on a grid with room around the body; what it hands out is
cropped to the frame's own grid, the very preview :func:`make_preview` makes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from volanim_core.reconstruct.breakage import BreakageReport, RestParts, breakage_report
from volanim_core.reconstruct.engine import Reconstruction, grid_bounds, moves_owned, reconstruct
from volanim_core.reconstruct.live import LiveFrame
from volanim_core.reconstruct.live_owned import LiveOwned
from volanim_core.reconstruct.owned import posed_bounds
from volanim_core.rig.connectivity import Tskel
from volanim_core.rig.tskel_tools import coarse_tskel
from volanim_core.volume import Bounds
from volanim_studio.model.live_resolution import LiveResolution

#: A full preview of more voxels than this is drawn from every second voxel (:meth:`Preview.view_volume`).
VIEW_FULL_VOXELS = 32_000_000


@dataclass
class Preview:
    reconstruction: Reconstruction
    factor: int
    mode: str
    report: BreakageReport | None = None
    rest_parts: RestParts | None = None  # what the report used, for the caller to keep
    joints: dict | None = None  # the posed joints it was made for: playing, the bones drawn are these
    frame: int | None = None  # the timeline frame it shows (None: not a frame of the timeline)
    live: bool = False  # made while a pose changes (LivePreviews): drawn as a surface, no report
    basis: int | None = None  # Document.picture_basis when it was asked for: older than the document's is old
    surface: object = None  # a live preview's surface (pyvista PolyData in world units), made off the GUI thread
    view: np.ndarray | None = None  # what the view draws of a full preview ([x, y, z] in Fortran order, every
    view_step: int = 1  # ``view_step``-th voxel of the reconstruction), made off the GUI thread (view_volume)
    #: a live preview's cost by stage, seconds: pose (the frame and its ownership), body (the kernel: only what
    #: moved), surface (the mesh drawn); the scene adds draw (software GL) once it has drawn it
    stages: dict | None = None

    def view_volume(self) -> None:
        """Make :attr:`view`: the reconstruction, or every second voxel of one over :data:`VIEW_FULL_VOXELS`,
        laid out as VTK reads it. Called in the worker that made the preview: on the GUI thread the copy
        for VTK (0.17 s) and VTK's first pass over a new volume (0.4 s) of mannequin-large's posed 100 M
        voxels held the window (#83 item 13), and a picture of that size shows no more at 1200x800."""
        v = self.reconstruction.volume
        self.view_step = 2 if v.shape[0] * v.shape[1] * v.shape[2] > VIEW_FULL_VOXELS else 1
        step = self.view_step
        self.view = np.asfortranarray(v[::step, ::step, ::step] if step > 1 else v)

    @property
    def spacing(self) -> tuple[float, float, float]:
        return (float(self.factor),) * 3

    @property
    def origin_voxels(self) -> np.ndarray:
        """Where voxel [0, 0, 0] of the preview sits, in full-resolution voxel coordinates."""
        return np.asarray(self.reconstruction.origin, np.float64) * self.factor


def live_surface(preview: Preview, function=None, n_bones: int = 0, spacing=(1.0, 1.0, 1.0)):
    """The surface a live preview is drawn as (pyvista PolyData in world units: voxels x ``spacing``): the
    faces of its filled voxels (:func:`~volanim_core.render.surfaces.voxel_faces`) coloured by label --
    software GL draws a surface far faster than it ray-casts a volume. With the user's transfer ``function``,
    its colours and opacities by label (a label it makes clear is not drawn, #83); else the bone colours
    (``n_bones``) in bone mode, none in binary.
    Pure arrays and VTK: made in the live worker, so the GUI thread only hands it to the view.
    :meth:`LivePreviews.surface` makes the same, keeping the faces of what a drag did not change."""
    from volanim_core.render.surfaces import label_surface, voxel_faces

    volume = preview.reconstruction.volume
    table, clear = _surface_colours(preview.mode, volume, function, n_bones)
    if clear is not None:
        volume = np.where(clear[volume], 0, volume)
    world = np.asarray(spacing, np.float64)
    # the voxels' own faces: a quarter of flying edges' time on a live picture (colour volumes: flying edges)
    surface = voxel_faces if volume.ndim == 3 else label_surface
    return surface(volume, preview.origin_voxels * world, np.asarray(preview.spacing) * world, table)


def _surface_colours(mode: str, volume: np.ndarray, function, n_bones: int):
    """``(table, clear)``: a live surface's colour a label (the transfer ``function``'s RGBA, or the bone colours
    in bone mode, or None) and the labels it makes clear (None: none), for the labels ``volume`` can hold."""
    from volanim_core.render.bone_colours import label_table

    if function is None or volume.ndim != 3:
        return (label_table(n_bones) if mode == "bone" else None), None
    # every label a byte can hold (no pass over the volume for its largest), or up to the largest of wider ones
    labels = 256 if volume.dtype.itemsize == 1 else int(volume.max()) + 1
    rgba = function(np.arange(labels, dtype=np.float64))
    clear = rgba[:, 3] <= 0
    table = np.round(np.clip(rgba, 0, 1) * 255).astype(np.uint8)  # RGBA: translucent where it says
    return table, (clear if clear[1:].any() else None)


def make_preview(tskel: Tskel, *, mode: str = "bone", kernel: int = 1, padding: int = 2, source=None,
                 factor: int = 1, joints=None, posed_joints=None, report: bool = False,
                 rest_parts: RestParts | None = None, progress=None, cancel=None) -> Preview:
    """Reconstruct the frame (and, when asked, the breakage report at full resolution).

    ``rest_parts``: a previous report's :class:`~volanim_core.reconstruct.breakage.RestParts` of the
    same attachments (made when None; the result carries them either way).
    """
    if not len(tskel):
        raise ValueError("no attached points to reconstruct: connect points to bones first")
    # neighbour lists: reconstruct() remembers them per connectivity (pose-independent)
    r = reconstruct(coarse_tskel(tskel, factor), mode=mode, source=source, kernel=kernel,
                    padding=max(1, padding // factor), progress=progress, cancel=cancel)
    out = Preview(r, factor, mode)
    out.view_volume()
    return with_report(out, tskel, joints=joints, posed_joints=posed_joints, rest_parts=rest_parts,
                       cancel=cancel) if report else out


def with_report(preview: Preview, tskel: Tskel, *, joints=None, posed_joints=None,
                rest_parts: RestParts | None = None, cancel=None) -> Preview:
    """``preview`` (of ``tskel``) with its breakage report at full resolution: a new Preview, the same
    reconstruction. The studio shows the picture first and this after it (#65: mannequin-large's picture
    takes 0.2 s, its report 5 s more). ``rest_parts`` as in :func:`make_preview`."""
    from dataclasses import replace

    r = preview.reconstruction
    # up to three more reconstructions: each checks ``cancel`` between its chunks
    own = preview.mode == "bone" and preview.factor == 1
    posed_bone = r if own else reconstruct(tskel, mode="bone", cancel=cancel)
    if rest_parts is None:
        rest_parts = RestParts.of(tskel.connectivity, cancel)
    report = breakage_report(tskel, joints or {}, posed_joints or {}, posed=posed_bone, rest=rest_parts,
                             cancel=cancel)
    return replace(preview, report=report, rest_parts=rest_parts)


# grids up to this many voxels are previewed live at full resolution (#65: the mannequin's posed grid,
# ~4 M: its redo and surface take ~40 ms); larger ones at half (the frog's 43 M, mannequin-large's 97 M)
LIVE_FULL_VOXELS = 8_000_000


def live_factor(tskel: Tskel) -> int:
    """1 (full resolution) when the frame's grid is small enough to redo live, else 2."""
    return 1 if np.prod(grid_bounds(tskel, 2).shape, dtype=np.int64) <= LIVE_FULL_VOXELS else 2


class LivePreviews:
    """The live previews of one studio: frame after frame on a :class:`LiveFrame` whose grid holds the
    first frame with ``margin`` of its size to spare each side. A frame outside that grid, another mode
    or factor start a new one (every slice once); other attachments are found by the LiveFrame itself."""

    def __init__(self, margin: float = 0.15, resolution: LiveResolution | None = None):
        self.margin = margin
        self.resolution = resolution or LiveResolution()  # each picture's factor (auto: the one keeping the rate)
        self._live: LiveFrame | None = None  # the last picture's
        self._key = None
        # one live grid per factor of this mode: a factor left and taken again redoes only what moved since its last
        # picture, not its whole grid (the frog's half-size grid: 3.9 M voxels, 100 ms)
        self._kept: dict = {}
        self._faces: dict = {}  # key -> the faces kept of its grid's last surface (surface())
        self._made = None  # (the faces kept of its grid, the grid's volume, its origin, factor) of the last picture
        self.faces_redone = 0  # z-slices of its grid whose faces the last surface made again

    def make(self, tskel: Tskel, *, mode: str = "bone", factor: int | None = None, padding: int = 2) -> Preview:
        """The preview :func:`make_preview` makes of ``tskel`` (same voxels, same grid), redoing only what moved.
        ``factor`` None: :attr:`resolution`'s (:func:`live_factor`'s on the first frame of a mode, then the one
        that keeps the rate; tell it each picture's cost, :meth:`LiveResolution.took`)."""
        if not len(tskel):
            raise ValueError("no attached points to reconstruct: connect points to bones first")
        if self._live is None or self._key[0] != mode:  # another mode: the size rule again, no grid kept
            self._kept.clear()
            if factor is None:
                self.resolution.reset()
        if factor is None:
            factor = self.resolution.factor_for(lambda: live_factor(tskel))
        coarse = coarse_tskel(tskel, factor)
        pad = max(1, padding // factor)
        if moves_owned(coarse, "auto"):  # the rig's owned body (reconstruct's default), only the moved bones redone
            rig = coarse.ownership  # pooled on the coarse grid (Ownership.coarse), kept with the rig
            matrices = rig.rest_matrices(coarse.matrices)
            own, key = posed_bounds(rig, matrices, pad), (mode, factor, id(rig))
            live = self._kept.get(key)
            if live is None or not _inside(own, live.bounds):
                live = LiveOwned(rig, _grown(own, self.margin), mode=mode)
            r = live.update(matrices, copy=False)
        else:
            own, key = grid_bounds(coarse, pad), (mode, factor)
            live = self._kept.get(key)
            if live is None or not _inside(own, live.bounds):
                live = LiveFrame(_grown(own, self.margin), mode=mode)
            r = live.update(coarse, copy=False)
        self._kept = {k: v for k, v in self._kept.items() if k[0] == mode and k[1] != factor}  # another rig's: gone
        self._kept[key] = self._live = live
        self._key = key
        faces = self._faces.get(key)
        if faces is None or faces.live is not live:
            faces = _GridFaces(live)
        else:  # the slices changed since its last surface: this picture's, and any a picture made without one did
            faces.pending = _either(faces.pending, live.changed)
        self._faces = {k: v for k, v in self._faces.items() if k in self._kept}
        self._faces[key] = faces
        self._made = (faces, r.volume, r.origin, factor)
        lo = np.subtract(own.lo, r.origin)
        box = tuple(slice(a, a + n) for a, n in zip(lo, own.shape))
        # copied in its memory's order (the [x, y, z] view of [z, y, x] arrays, as reconstruct returns them):
        # a C-order copy of the frog's half-size grid took 18 ms, and the surface then copied it again
        cropped = Reconstruction(r.volume[box].copy(order="K"), own.lo, r.stats, r.geometry.shifted(lo))
        return Preview(cropped, factor, mode, live=True)

    def surface(self, preview: Preview, function=None, n_bones: int = 0, spacing=(1.0, 1.0, 1.0)):
        """:func:`live_surface` of the picture :meth:`make` made last (``preview``), from the faces of its grid kept
        since that grid's last surface: only the slices the bones moved since then are made again (the mannequin's
        full-size faces were more than half a live picture's stages). The same faces, in the same order."""
        faces, volume, origin, factor = self._made
        if volume.ndim != 3:  # colour: flying edges, made whole
            return live_surface(preview, function, n_bones, spacing)
        from volanim_core.render.surfaces import faces_mesh
        from volanim_core.voxel_faces import KeptFaces

        table, clear = _surface_colours(preview.mode, volume, function, n_bones)
        world = np.asarray(spacing, np.float64) * factor
        style = (None if table is None else table.tobytes(), None if clear is None else clear.tobytes(),
                 tuple(world))
        if faces.kept is None or faces.style != style:  # another colour table or spacing: made afresh
            faces.kept = KeptFaces(np.asarray(origin) * world, world, table, clear)
            faces.style, faces.pending = style, "all"
        points, cells, rgb = faces.kept.update(volume, faces.pending)
        faces.pending, self.faces_redone = None, faces.kept.redone
        return faces_mesh(points, cells, None if table is None else rgb)

    @property
    def bounds(self) -> Bounds | None:
        """The live grid the previews are cut from (None before the first)."""
        return None if self._live is None else self._live.bounds

    @property
    def redone(self) -> int:
        """What the last preview redid: output slices of the spheres' grid, or voxels of the owned body's (all
        of its grid's on a fresh one)."""
        return 0 if self._live is None else self._live.redone


def _inside(inner: Bounds, outer: Bounds) -> bool:
    return all(o <= i for i, o in zip(inner.lo, outer.lo)) and all(i <= o for i, o in zip(inner.hi, outer.hi))


def _grown(b: Bounds, margin: float) -> Bounds:
    room = [max(4, int(np.ceil(margin * n))) for n in b.shape]
    return Bounds(tuple(v - r for v, r in zip(b.lo, room)), tuple(v + r for v, r in zip(b.hi, room)))


class _GridFaces:
    """The faces kept of one live grid (``live``, a LiveOwned or LiveFrame) and the slices changed since."""

    def __init__(self, live):
        self.live, self.kept, self.style = live, None, None
        self.pending: tuple[int, int] | None | str = "all"


def _either(a, b):
    """The z-slices of two changes together: ``(first, last)``, None (no change) or "all"."""
    if a is None or b is None:
        return b if a is None else a
    if isinstance(a, str) or isinstance(b, str):
        return "all"
    return (min(a[0], b[0]), max(a[1], b[1]))
