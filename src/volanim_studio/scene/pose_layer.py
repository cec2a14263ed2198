"""The pose stage of the scene: posed bones and preview reconstructions.

    doc.events.pose --> posed bones and their axes (x-ray layer); while the timeline plays, the bones of
                        the preview drawn (its ``joints``), so bones and body are always one frame
    doc.events.preview, settings.show_rest / slices --> draw(): the preview (or the rest pose's, to compare)
    doc.events.preview (with a report) --> the stumps' red boxes, the lumps' white ones
    doc.events.transfer --> the full preview's colours and opacities (the user's function, or the mode's own)
    doc.events.stale / preview, settings.dragging / playing --> "Old picture: ... changed" in the view's top
                        corner while the preview shown is of an earlier state (not during a drag or playback,
                        whose live pictures follow at once)

Owned by :class:`~volanim_studio.scene.view.SceneView`. Full previews are
volumes with a transfer function per mode (``volanim_core.render``); live
previews are label-coloured surfaces, which software OpenGL draws far faster.
"""

from __future__ import annotations

import numpy as np
import pyvista as pv
from matplotlib.colors import ListedColormap

from volanim_core.render.bone_colours import SKIN, label_table
from volanim_core.render.volume_style import (
    LABEL_MODES,
    add_volume_uncopied,
    apply_labels,
    apply_rgba,
    binary_view,
    gl_renderer,
    limit_ray_cost,
    rgba_points,
    software_gl,
    volume_mapper,
    volume_style,
    vtk_functions,
)
from volanim_core.rig.pose import apply_matrices
from volanim_core.volume import to_grey

from ..model.preview import live_surface

STUMP_COLOUR = "#ff3030"  # over a black halo, seen on a red bone colour too
LUMP_COLOUR = "#ffffff"  # flesh carried off (reconstruct/lumps.py): white over a black halo, seen on any bone colour
STALE_NOTE = "stale_note"  # the view's "Old picture" text
AXIS_COLOURS = ((230, 60, 60), (60, 200, 80), (70, 120, 255))  # x, y, z: the Pose tab names them so


def bone_lines(segments: np.ndarray) -> pv.PolyData:
    """One line cell per ``(proximal, distal)`` world segment, ``segments`` shaped ``(n, 2, 3)``."""
    n = len(segments)
    lines = np.hstack([np.full((n, 1), 2), np.arange(2 * n).reshape(-1, 2)]).ravel()
    return pv.PolyData(np.asarray(segments).reshape(-1, 3).astype(np.float32), lines=lines)


def unit_axes() -> pv.PolyData:
    """Arrows of length 1 along x (red), y (green) and z (blue) from the origin, coloured per cell."""
    arrows = []
    for k, colour in enumerate(AXIS_COLOURS):
        arrow = pv.Arrow(start=(0.0, 0.0, 0.0), direction=np.eye(3)[k], scale=1.0, tip_length=0.2,
                         shaft_radius=0.03, tip_radius=0.08)
        arrow.cell_data["rgb"] = np.tile(np.array(colour, np.uint8), (arrow.n_cells, 1))
        arrows.append(arrow)
    return pv.merge(arrows)


class PoseLayer:
    """Posed bones (following ``doc.events.pose``) and the preview volume or surface."""

    def __init__(self, view):
        self.view = view
        self.preview_actor = None
        self.preview_key = None  # (mode, shape, origin, spacing, bones, max): same key -> swap data only
        self._surface = (None, None)  # a live picture's actor and its colouring: the next one swaps its faces in
        self._mapper = None  # the volume mapper for full previews, chosen once the GL context exists
        self._bone_lines = None  # the posed bones' lines as drawn: a drag's step moves their points
        self._note = None  # the "Old picture" text actor, once made
        view.doc.events.pose.connect(self.on_pose_changed)
        view.doc.events.preview.connect(lambda **_: self.draw())
        view.doc.events.preview.connect(self.on_report)
        view.doc.settings.events.show_rest.connect(lambda **_: self.draw())
        view.doc.settings.events.slices.connect(lambda **_: self.draw())
        view.doc.events.transfer.connect(self.on_transfer)
        view.doc.events.selection.connect(lambda **_: self.draw_axes() if view.posing else None)
        # stopped: the bones follow the pose again (drawn now, not at the next pose change)
        view.doc.settings.events.playing.connect(lambda value: None if value else self.on_pose_changed())
        view.doc.settings.events.dragging.connect(lambda value: None if value else self.on_pose_changed())
        for event in (view.doc.events.stale, view.doc.events.preview, view.doc.settings.events.dragging,
                      view.doc.settings.events.playing, view.doc.settings.events.mode):
            event.connect(lambda **_: self.draw_stale_note())

    def draw_stale_note(self) -> None:
        """Say in the view when the picture shown is of an earlier state (#83: an old body after an
        auto-connect or an undo looked current)."""
        view, doc = self.view, self.view.doc
        st = doc.settings
        old = (view.posing and doc.preview is not None and not doc.preview_is_current and not st.dragging
               and not st.playing and not st.show_rest)
        if old:
            text = f"Old picture: {doc.picture_change or 'the session'} changed since. F5 redraws."
            if self._note is None:  # made once: pyvista's add_text took 45-65 ms of the GUI thread each time
                # drawn by the widget's next paint (view.render below): pyvista's own render draws the whole
                # view on the GUI thread at once (130-190 ms of software GL under load)
                self._note = view.plotter.add_text(text, position="upper_left", font_size=9, color="#d0d0d0",
                                                   name=STALE_NOTE, render=False)
            else:
                self._note.SetText(2, text)  # a corner annotation: corner 2 is upper left
                if STALE_NOTE not in view.plotter.actors:
                    view.plotter.add_actor(self._note, name=STALE_NOTE, reset_camera=False, render=False)
        elif STALE_NOTE in view.plotter.actors:
            view.plotter.remove_actor(STALE_NOTE, render=False)
        else:
            return
        view.render()

    def on_pose_changed(self, **_) -> None:
        view = self.view
        for name in ("stumps", "lumps"):  # they were where the previous pose put them
            self._marks(name, [], "", 0)
        if not view.posing:
            return
        if self._bones_wait():
            return  # the bones wait for the body of their pose (draw() puts them with it)
        self.draw_bones(view.doc.pose.posed_joints())

    def _bones_wait(self) -> bool:
        """Playing, or dragging with live pictures coming: the bones are drawn with the body of their pose, not
        on each pose change. One render per picture, not two: a render holds Python's lock (VTK's wheels never
        release it), and the frog's 60 ms software-GL draws of bones alone kept the live thread from making the
        next picture (#85: 16 renders for 10 pictures in a drag)."""
        view = self.view
        st, p = view.doc.settings, view.doc.preview
        if p is None or p.joints is None:
            return False
        return st.playing or (st.dragging and st.live_preview and p.live)

    def draw_bones(self, pj: dict) -> None:
        """The posed bones through the joints ``pj`` (name -> rest-grid voxels), and the working bone's axes.
        A drag's step moves the drawn lines and axes in place: making their actors anew cost 25 ms of each
        step on software GL (#65)."""
        view = self.view
        bones = view.doc.bones
        if not len(bones):
            view.xray.remove("posed_bones")
        else:
            segments = view.world(np.array([[pj[b.proximal], pj[b.distal]] for b in bones.bones]))
            actor = view.xray.actors.get("posed_bones")
            if actor is not None and self._bone_lines is not None and self._bone_lines.n_cells == len(bones):
                self._bone_lines.points = segments.reshape(-1, 3).astype(np.float32)
            else:
                poly = bone_lines(segments)
                poly.cell_data["rgb"] = label_table(len(bones))[1:]
                # over the preview (x-ray): the bones the user poses and clicks are never hidden inside it
                view.xray.put("posed_bones", view.plotter.add_mesh(
                    poly, scalars="rgb", rgb=True, line_width=5, render_lines_as_tubes=True, name="posed_bones",
                    render=False, reset_camera=False))
                self._bone_lines = poly
        self.draw_axes()

    def draw_axes(self) -> None:
        """The axes the Pose sliders turn the working bone about, at its posed proximal joint: x red,
        y green, z blue (the rest axes carried by the parent's pose, as ``pose_frames`` composes them):
        three unit arrows placed by the actor's matrix."""
        view = self.view
        doc = view.doc
        b = doc.working_bone
        if b is None or b >= len(doc.bones):
            view.xray.remove("rot_axes")
        else:
            mats = doc.pose.matrices()  # once: this runs on every step of a slider drag
            parent = doc.bones.parents()[b]
            frame = np.eye(3) if parent is None else mats[parent][:3, :3]  # row k: where axis k points now
            proximal = doc.bones.joints[doc.bones.bones[b].proximal]
            origin = apply_matrices(proximal[None], np.array([b]), mats)[0]  # the joint turns with its bone
            length = max(0.6 * float(np.linalg.norm(np.subtract(*doc.bones.segment(b)))), 8.0)
            place = np.eye(4)
            place[:3, :3] = (view.world(frame / np.linalg.norm(frame, axis=1, keepdims=True)) * length).T
            place[:3, 3] = view.world(origin[None])[0]
            actor = view.xray.actors.get("rot_axes")
            if actor is None:
                actor = view.plotter.add_mesh(unit_axes(), scalars="rgb", rgb=True, name="rot_axes", render=False,
                                              reset_camera=False, pickable=False)
                view.xray.put("rot_axes", actor)
            actor.user_matrix = place
        view.apply_stage()
        view.render()

    def draw(self) -> None:
        """Show the last preview (or, with ``settings.show_rest``, the rest pose's, to compare)."""
        doc = self.view.doc
        p = doc.preview
        if doc.settings.show_rest:
            try:
                p = doc.pose.rest_preview(p.mode if p is not None else "bone")
            except ValueError as exc:
                doc.message(str(exc))
                return
        if self._bones_wait() and self.view.posing:
            self.draw_bones(doc.preview.joints)  # the body's own pose: bones and body never show two poses
        if p is None:
            self.clear()
        elif p.live and p.mode in ("bone", "binary"):  # a live preview: a surface draws fastest
            self.show_surface(p)
        elif p.view is not None:  # made by the worker: every second voxel of a large one (Preview.view_volume)
            self.show_volume(p.view, p.origin_voxels, np.multiply(p.spacing, p.view_step), p.mode)
        else:
            self.show_volume(p.reconstruction.volume, p.origin_voxels, p.spacing, p.mode)

    def on_report(self, **_) -> None:
        """Mark the last full preview's stumps in 3-D (red boxes), where the pose left them; a pose
        change hides the marks until the next report."""
        view = self.view
        p = view.doc.preview
        if p is not None and p.report is None:
            return  # a live preview: the marks of the last report stay until the pose changes
        lumps = [] if p is None else p.report.lumps
        stumps = [] if p is None else p.report.stumps
        # a white box around each lump (flesh the pose carried off); a red one around each stump (its spheres
        # sit inside the preview, which would hide points)
        self._marks("lumps", [(lump.lo - 1, lump.hi + 1) for lump in lumps], LUMP_COLOUR, 2)
        self._marks("stumps", [(st.posed.min(0) - st.margin, st.posed.max(0) + st.margin) for st in stumps],
                    STUMP_COLOUR, 3)
        view.apply_stage()
        view.render()

    def _marks(self, name: str, boxes, colour: str, width: int) -> None:
        """Boxes (rest-grid voxels ``(lo, hi)``) drawn as ``name``: coloured lines over a black halo
        (``name_halo``), seen on any bone colour (#61: a red line alone vanished on a red body part)."""
        plotter = self.view.plotter
        plotter.remove_actor(name, render=False)
        plotter.remove_actor(f"{name}_halo", render=False)
        if not boxes:
            return
        edges = []
        for lo, hi in boxes:
            lo, hi = self.view.world(np.asarray(lo)[None])[0], self.view.world(np.asarray(hi)[None])[0]
            edges.append(pv.Box(bounds=(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2])).extract_all_edges())
        edges = pv.merge(edges)
        plotter.add_mesh(edges, color="black", line_width=width + 4, name=f"{name}_halo", render=False,
                         reset_camera=False, pickable=False)
        plotter.add_mesh(edges.copy(), color=colour, line_width=width, name=name, render=False,
                         reset_camera=False, pickable=False)

    def _image(self, volume, origin_voxels, spacing_voxels) -> pv.ImageData:
        world_origin = self.view.world(origin_voxels)
        world_spacing = np.asarray(spacing_voxels, np.float64) * self.view.spacing
        img = pv.ImageData(dimensions=volume.shape[:3], origin=world_origin, spacing=world_spacing)
        colour = np.ndim(volume) == 4  # RGB with an alpha for the background (drawn as it is)
        img.point_data["values"] = rgba_points(volume) if colour else np.asarray(volume).ravel(order="F")
        return img

    def on_transfer(self, function, **_) -> None:
        """The user's transfer function changed: recolour the preview drawn with one in place (an edit is
        drawn at once, with no new actor), or draw it again when it gains or loses one."""
        if function is not None and self.preview_actor is not None and self.preview_key[-1]:
            self._apply_transfer(function, self.preview_key[0])
            if self.view.settings.slices:
                self.draw()  # the slices' colours too
            else:
                self.view.render()
        elif self.preview_actor is not None or (self.view.doc.preview is not None and self.view.doc.preview.live):
            self.draw()  # a live preview's surface takes the function's colours when drawn

    def _part_thickness(self) -> float:
        """A body part's typical thickness in world units: twice the skeleton's median distance to the
        surface (the mannequin's limbs: ~10 voxels); 1 without a skeleton."""
        skel = self.view.doc.skeleton
        if skel is None or not len(skel.dt):
            return 1.0
        return float(max(2.0 * np.median(skel.dt), 1.0) * np.min(self.view.spacing))

    def _apply_transfer(self, tf, mode: str) -> None:
        ctf, otf = vtk_functions(tf)
        prop = self.preview_actor.GetProperty()
        prop.SetColor(ctf)
        prop.SetScalarOpacity(otf)
        if mode in LABEL_MODES:  # labels are never blended between voxels, whatever colours they have
            prop.SetInterpolationTypeToNearest()
            # a label's opacity is the whole part's, as a surface shows it (live pictures, movies): a ray through
            # a limb takes it once, not once a voxel (#83: the head at 0.1 drew solid, 30 samples deep)
            prop.SetScalarOpacityUnitDistance(self._part_thickness())
        else:
            prop.SetInterpolationTypeToLinear()

    def show_volume(self, volume: np.ndarray, origin_voxels, spacing_voxels, mode: str) -> None:
        """Draw a reconstruction; a live update with the same grid and mode only swaps the data. With the
        user's transfer function (``doc.transfer``) its colours and opacities replace the mode's; a colour
        volume is then drawn by its luminance (the function reads one value a voxel), as ``volanim render``
        draws it."""
        view, plotter = self.view, self.view.plotter
        n_bones = len(view.doc.bones)
        tf = view.doc.transfer.function
        if mode == "binary":
            volume = binary_view(volume)
        if tf is not None and volume.ndim == 4:
            volume = to_grey(volume)
        img = self._image(volume, origin_voxels, spacing_voxels)
        key = (mode, volume.shape, tuple(img.origin), tuple(img.spacing), n_bones,
               float(volume.max()) if mode == "hotspot" else 0, tf is not None)
        if self.preview_actor is not None and key == self.preview_key:
            self.preview_actor.mapper.SetInputData(img)
        else:
            plotter.remove_actor("preview", render=False)
            if plotter.scalar_bars:
                plotter.remove_scalar_bar(render=False)  # the new volume's paint draws it
            colour = volume.ndim == 4
            style = volume_style(mode, volume, n_bones) if not colour else {"show_scalar_bar": False}
            labels = style.pop("categories", None)
            self.preview_actor = add_volume_uncopied(plotter, img, "values", name="preview", render=False,
                                                     reset_camera=False, **style,
                                                     mapper=self.volume_mapper(4 if colour else 1))
            if labels is not None:
                apply_labels(self.preview_actor, labels)
            if volume.ndim == 4:
                apply_rgba(self.preview_actor)
            self.preview_key = key
        # a coarser copy (a large preview's every second voxel, a half-resolution one) is sampled as coarsely
        limit_ray_cost(self.preview_actor, plotter.renderer, float(np.max(spacing_voxels)))
        if tf is not None:
            self._apply_transfer(tf, mode)
        self.preview_actor.SetVisibility(view.posing)
        plotter.remove_actor("slices", render=False)
        if view.settings.slices and volume.ndim == 4:
            plotter.add_mesh(img.slice_orthogonal(), scalars="values", rgb=True, name="slices", render=False,
                             reset_camera=False)
        elif view.settings.slices and tf is not None:  # the function's colours, over its values' range
            lo = float(tf.values[0])
            hi = max(float(tf.values[-1]), lo + 1)  # one point: a range of 1 around it
            cmap = ListedColormap(np.clip(tf(np.linspace(lo, hi, 256))[:, :3], 0, 1))
            plotter.add_mesh(img.slice_orthogonal(), scalars="values", cmap=cmap, clim=(lo, hi), n_colors=256,
                             show_scalar_bar=False, name="slices", render=False, reset_camera=False)
        elif view.settings.slices:
            style = volume_style(mode, volume, n_bones)
            labels = style.get("categories")
            cmap = style["cmap"] if labels is None else ListedColormap(np.vstack([[0.1, 0.1, 0.1], labels]))
            clim = style["clim"] if labels is None else (0, len(labels))
            plotter.add_mesh(img.slice_orthogonal(), scalars="values", cmap=cmap, clim=clim,
                             n_colors=256 if labels is None else len(labels) + 1, show_scalar_bar=False,
                             name="slices", render=False, reset_camera=False)
        view.render()

    def volume_mapper(self, components: int = 1) -> str:
        """pyvista's name of the mapper full previews use: the CPU ray caster on software OpenGL
        (2.3x faster there on label volumes, as fast on grey ones), VTK's smart mapper on a GPU; colour
        (``components`` 4) always the smart mapper (:func:`~volanim_core.render.volume_style.volume_mapper`)."""
        if self._mapper is None:
            ren_win = self.view.plotter.ren_win
            renderer = gl_renderer(ren_win) if ren_win is not None else ""
            if not renderer:
                return "smart"  # no GL context yet (never drawn): decide on a later preview
            self._mapper = "fixed_point" if software_gl(renderer) else "smart"
        return volume_mapper(self._mapper, components)

    def show_surface(self, p) -> None:
        """A live preview: its surface (:func:`live_surface`, made by the live worker in world units; made
        here for a preview that has none), drawn."""
        view, plotter = self.view, self.view.plotter
        surf = p.surface  # drawn as it is: never scaled here (a shallow copy's new points were the picture's
        # own, and each redraw of a body with 1.5 mm voxels grew it 1.5 times)
        if surf is None:
            surf = live_surface(p, view.doc.transfer.function, len(view.doc.bones), view.spacing)
        # its colouring: RGB, RGBA (a transfer function's opacities: add_mesh sets the actor up for them) or none
        kind = np.asarray(surf.point_data["rgb"]).shape[1] if "rgb" in surf.point_data else "skin"
        actor = plotter.actors.get("preview")
        if surf.n_points and actor is not None and actor is self._surface[0] and kind == self._surface[1]:
            # the last picture's actor, given this one's faces: pyvista's add_mesh made a mapper and an actor anew
            # each picture, 8 ms of the GUI thread's a live picture on the mannequin (#85)
            if kind != "skin":
                surf.point_data.active_scalars_name = "rgb"
            actor.mapper.SetInputData(surf)
        else:
            self.clear(render=False)
            if surf.n_points and kind != "skin":
                actor = plotter.add_mesh(surf, scalars="rgb", rgb=True, name="preview", render=False,
                                         reset_camera=False)
            elif surf.n_points:
                actor = plotter.add_mesh(surf, color=SKIN, name="preview", render=False, reset_camera=False)
            self._surface = (actor, kind) if surf.n_points else (None, None)
        view.apply_stage()
        view.render()
        if p.stages is not None:  # the draw the last live picture took (this one's is known once drawn)
            p.stages["last draw"] = view.frames.seconds

    def clear(self, render: bool = True) -> None:
        self.view.plotter.remove_actor("preview", render=False)
        self.view.plotter.remove_actor("slices", render=False)
        self.preview_actor = self.preview_key = None
        self._surface = (None, None)
        if render:
            self.view.render()
