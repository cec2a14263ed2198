"""The rendering layer: owns the VTK actors and turns clicks into pick events.

    Document events --> SceneView._on_<prop>_changed --> actors --> render()
    VTK mouse press/release (no drag) --> pick(x, y) --> PickEvent --> on_pick callback

The scene never edits the document; the main window routes pick events to the active mode. Picking projects
the shown points with the renderer's own camera matrices (``projection``), so the translucent hull can never
intercept a click and HiDPI scaling cannot offset it.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pyvista as pv

from volanim_core.render.bone_colours import label_table, scalar_colours
from volanim_core.render.scene import reset_clipping

from ..model.document import Document
from ..model.interaction import PickEvent
from . import camera_moves
from .bones_layer import BonesLayer
from .frame_watch import FrameWatch
from .hull_layer import HullLayer
from .names_layer import ACTORS as NAME_ACTORS
from .names_layer import NamesLayer
from .overlays import CubeOverlay, LassoOverlay
from .pose_layer import PoseLayer
from .projection import CLICK_SLOP, nearest_in_radius, project, segment_distance_2d
from .xray_layer import XRayLayer

LOD_POINTS = 30_000  # drawn while the thinness slider is held: with the hull, a frame in ~50 ms of software GL
PICK_RADIUS = 8.0  # logical pixels; scaled by the device pixel ratio


class SceneView:
    """Actors for hull, cloud, bones and joints over a pyvista ``QtInteractor`` (the studio's, whose renders
    are gathered into one per pass of Qt's event loop) or an off-screen ``pyvista.Plotter`` (tests, scripts:
    each render at once), as napari draws its layers on any vispy canvas.

    Composed of parts that each own their actors: ``hull``, ``bone_layer`` (rest bones, joints, the
    selected bones' halo), ``names``, ``cube`` and ``lasso`` (selection overlays), ``xray`` and
    ``pose_layer`` (posed bones, previews). The view keeps the point cloud, which picking reads.
    """

    EDIT_ACTORS = ("cloud", "bones", "joints", "selected", "picked", "cube", *NAME_ACTORS)
    POSE_ACTORS = ("preview", "posed_bones", "slices", "stumps", "stumps_halo", "lumps", "lumps_halo", "rot_axes")

    def __init__(self, plotter, doc: Document, on_pick: Callable[[PickEvent], None] | None = None):
        self.plotter = plotter
        # a Qt widget (the studio's QtInteractor) or an off-screen pyvista Plotter (tests, scripts): decided once
        self.in_qt = hasattr(plotter, "isVisible")
        self.doc = doc
        self.on_pick = on_pick
        self.settings = doc.settings
        self._cloud_actor = self._picked_actor = None
        self._world = np.zeros((0, 3), np.float32)
        self._colours = np.zeros((0, 3), np.uint8)
        self._press = None
        self._shown = np.zeros(0, np.int64)
        self.posing = False
        self.dragging = False  # settings.dragging (a slider held): draw a level-of-detail subset
        self._after_drag: tuple[bool, bool] | None = None  # the renderer's FXAA and OIT, put back on release
        self._render_pending = False
        self._drawn_once = False
        # draws' times; what waits for the next; after model changes a draw's start fits the clipping planes
        self.frames = FrameWatch(plotter, before=lambda: reset_clipping(plotter.renderer))
        plotter.set_background("#1e1f24")
        self._fix_pixel_ratio()
        self._quiet_keys()
        # the orientation widget: which way is x, y, z (pyvista's, drawn in a corner viewport)
        plotter.add_axes(interactive=False, line_width=2, color="white")
        iren = plotter.iren
        iren.add_observer("LeftButtonPressEvent", self._on_press)
        iren.add_observer("LeftButtonReleaseEvent", self._on_release)
        iren.add_observer("RightButtonPressEvent", self._on_press)
        iren.add_observer("RightButtonReleaseEvent", self._on_release)
        ev = doc.events
        ev.skeleton.connect(self._on_skeleton_changed)
        ev.thinness.connect(self._on_thinness_changed)
        ev.bones.connect(self._on_bones_changed)
        ev.selection.connect(self._on_selection_changed)
        ev.picked.connect(self._on_picked_changed)
        ev.attachments.connect(self._on_attachments_changed)
        ev.filter.connect(self._on_thinness_changed)
        st = doc.settings.events
        st.colour_by.connect(self._on_colour_by_changed)
        st.point_size.connect(lambda **_: self._update_cloud())
        st.spheres.connect(lambda **_: self._update_cloud())
        st.dragging.connect(lambda value: self.set_dragging(value))
        doc.view_camera = self.camera  # a project saves the camera on screen, and doc.set_camera puts one back
        ev.camera.connect(lambda camera: self.set_camera(camera) if camera is not None else None)
        self.xray = XRayLayer(plotter)  # posed bones and their axes, drawn over the preview
        self.names = NamesLayer(self)  # first: the other layers switch stages, which the labels follow
        self.hull = HullLayer(self)
        self.bone_layer = BonesLayer(self)  # the rest bones, joints and selection halo
        self.cube = CubeOverlay(self)
        self.lasso = LassoOverlay(self)
        self.pose_layer = PoseLayer(self)

    def _fix_pixel_ratio(self) -> None:
        # VTK's QVTKRenderWindowInteractor scales events by the DPR of the screen under the *cursor*, wrong
        # on mixed-DPI desktops (pyvistaqt #20, VTK MR 4201); the widget's own ratio for size and events.
        widget = self.plotter
        if hasattr(widget, "_getPixelRatio"):
            widget._getPixelRatio = lambda: float(widget.devicePixelRatioF())

    def _quiet_keys(self) -> None:
        """No keys of VTK's or pyvista's own (W: wireframe, Q and V snapped the camera, +/- the point size
        behind the Display tab's back): the window's actions (Qt shortcuts) are the only keys."""
        self.plotter.iren.clear_key_event_callbacks()
        # a style with an observer for an event skips its own handler (OnChar: w, s, e, q, f, r, 3, p, j, t)
        self.plotter.iren.style.AddObserver("CharEvent", lambda *_: None)

    # ---------------------------------------------------------- coordinates
    @property
    def spacing(self) -> np.ndarray:
        return np.asarray(self.doc.spacing, np.float64)

    def world(self, voxel_xyz) -> np.ndarray:
        return np.asarray(voxel_xyz, np.float64) * self.spacing

    def project_world(self, world_points) -> tuple[np.ndarray, np.ndarray]:
        """Display pixels (device, bottom-left origin) and depth of world points."""
        matrix, viewport = camera_moves.composite_matrix(self.plotter.renderer)
        return project(world_points, matrix, viewport)

    def display_of_point(self, index: int) -> np.ndarray:
        """Where skeleton point ``index`` is drawn, in display pixels."""
        return self.project_world(self.world(self.doc.skeleton.points[index])[None])[0][0]

    def shown_projection(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(shown indices, display xy, normalised depth, distance along the view)`` of the shown points."""
        world = self._world[self._shown].astype(np.float64)
        xy, depth = self.project_world(world)
        return self._shown, xy, depth, camera_moves.view_distances(self.plotter.renderer, world)

    def camera(self) -> dict:  # the view's camera as plain lists (saved in projects)
        return camera_moves.camera_state(self.plotter.renderer)

    def set_camera(self, data: dict) -> None:
        camera_moves.set_camera_state(self.plotter.renderer, data)
        self.render()

    def front_view(self) -> None:  # the front of the object (stood up by its shape), everything in view
        self.view_preset("front")

    def view_preset(self, name: str) -> None:
        """A named view of the body (in Pose mode its posed spheres' box: a preview still drawing the last
        pose must not count), stood up by the rest skeleton's shape (a walk must not lay it down)."""
        shape = (self._world.min(0), self._world.max(0)) if len(self._world) else None
        box = self.doc.pose.posed_box() if self.posing else None
        box = None if box is None else (self.world(box[0]), self.world(box[1]))
        if camera_moves.preset_view(self.plotter.renderer, name, box, shape):
            self.render()

    def frame_all(self) -> None:
        if camera_moves.frame(self.plotter.renderer):
            self.render()

    def shown_joints(self) -> dict:  # joints as drawn: where the pose put them in Pose mode, else at rest
        return self.doc.pose.posed_joints() if self.posing else self.doc.bones.joints

    def frame_selected(self) -> bool:
        """Fill the view with the selected bones, else the picked point, else the cube/lasso selection."""
        doc = self.doc
        pts = []
        if doc.selected_bones and len(doc.bones):
            joints = self.shown_joints()
            pts = np.array([joints[j] for i in doc.selected_bones if i < len(doc.bones)
                            for j in (doc.bones.bones[i].proximal, doc.bones.bones[i].distal)])
        elif doc.picked_point is not None:
            pts = doc.skeleton.points[[doc.picked_point]]
        elif len(doc.point_selection):
            pts = doc.skeleton.points[doc.point_selection]
        if not len(pts):
            return False
        world = self.world(pts)
        camera_moves.frame(self.plotter.renderer, world.min(0), world.max(0))
        self.render()
        return True

    def jump_to(self, voxel_xyz) -> None:  # centre the view on a point and move closer
        camera_moves.move_closer_to(self.plotter.renderer, self.world(voxel_xyz))
        self.render()

    def pixel_ratio(self) -> float:
        return float(self.plotter.devicePixelRatioF()) if self.in_qt else 1.0

    # ---------------------------------------------------------------- picks
    def pick(self, x: float, y: float) -> PickEvent:
        """What is under display position ``(x, y)``: point, joint and bone (each may be None)."""
        radius = PICK_RADIUS * self.pixel_ratio()
        point = None
        shown = self._shown
        if len(shown):
            xy, depth = self.project_world(self._world[shown])
            k = nearest_in_radius(xy, depth, (x, y), radius)
            point = None if k is None else int(shown[k])
        joint, bone = self.joint_and_bone_at(x, y)
        return PickEvent(point=point, joint=joint, bone=bone)

    def joint_and_bone_at(self, x: float, y: float) -> tuple[str | None, int | None]:
        """The joint and the bone within the pick radius of display ``(x, y)`` (each may be None); no points
        are projected: cheap enough for every mouse move (hover)."""
        radius = PICK_RADIUS * self.pixel_ratio()
        joint = bone = None
        bones = self.doc.bones
        names = list(bones.joints)
        if names:
            joints = self.shown_joints()  # Pose mode: the posed forearm is clicked where it is drawn
            jxy, jdepth = self.project_world(self.world(np.array([joints[k] for k in names])))
            k = nearest_in_radius(jxy, jdepth, (x, y), radius)
            joint = names[k] if k is not None else None
            segs = np.array([[joints[b.proximal], joints[b.distal]] for b in bones.bones])
            if len(segs):
                a, _ = self.project_world(self.world(segs[:, 0]))
                b, _ = self.project_world(self.world(segs[:, 1]))
                d = segment_distance_2d((x, y), a, b)
                if d.min() <= radius:
                    bone = int(np.argmin(d))
        return joint, bone

    def event_position(self) -> tuple[int, int]:
        # pyvista hangs button observers on the interactor *style*; the position is the interactor's
        return self.plotter.iren.interactor.GetEventPosition()

    def _on_press(self, obj, event) -> None:
        if self.lasso.enabled and event.startswith("Left"):
            return
        self._press = self.event_position()

    def _on_release(self, obj, event) -> None:
        if event.startswith("Right"):
            # pyvista hangs release observers on the style, and a style with an observer for an event
            # skips its own handler: without this the camera stays in dolly after a right click,
            # zooming on every mouse move and swallowing the next left click. (pyvista's own left
            # release observer calls OnLeftButtonUp itself.)
            self.plotter.iren.style.OnRightButtonUp()
        if self._press is None:
            return
        x, y = self.event_position()
        px, py = self._press
        self._press = None
        if abs(x - px) > CLICK_SLOP or abs(y - py) > CLICK_SLOP:
            return  # a drag moved the camera
        self.click_at(x, y, "right" if event.startswith("Right") else "left")

    def click_at(self, x: float, y: float, button: str = "left") -> None:
        """A click at display ``(x, y)``: what is there, and the Shift key, to the ``on_pick`` callback."""
        ev = self.pick(x, y)
        shift = bool(self.plotter.iren.interactor.GetShiftKey())
        if self.on_pick is not None:
            self.on_pick(PickEvent(ev.point, ev.joint, ev.bone, button, shift))

    # ---------------------------------------------------------------- cloud
    def _on_skeleton_changed(self, **_) -> None:
        s = self.doc.skeleton
        self._world = np.zeros((0, 3), np.float32) if s is None else self.world(s.points).astype(np.float32)
        self._recolour()
        self._update_cloud()
        if self.hull.actor is None and len(self._world):
            self.front_view()

    def _recolour(self) -> None:
        s = self.doc.skeleton
        if s is None or not len(s):
            self._colours = np.zeros((0, 3), np.uint8)
            return
        self._colours = self.point_colours()

    def point_colours(self) -> np.ndarray:
        """RGB per skeleton point for the current colour-by setting."""
        s = self.doc.skeleton
        if self.settings.colour_by == "bone":
            return self._bone_rgb()[self.doc.attachments.bone + 1]
        if self.settings.colour_by == "dt":
            return scalar_colours(s.dt, "viridis")
        return scalar_colours(s.thinness, "plasma")

    def _bone_rgb(self) -> np.ndarray:
        """Row 0: unconnected grey; row b + 1: bone b's colour."""
        return label_table(len(self.doc.bones))

    def _on_attachments_changed(self, indices=None, **_) -> None:
        if self.settings.colour_by == "bone" and self.doc.skeleton is not None:
            if indices is None or len(self._colours) != len(self.doc.skeleton):
                self._recolour()
            else:
                self._colours[indices] = self._bone_rgb()[self.doc.attachments.bone[indices] + 1]
        self._update_cloud()

    def _on_colour_by_changed(self, **_) -> None:
        self._recolour()
        self._update_cloud()

    def set_dragging(self, on: bool) -> None:
        """``settings.dragging``: at most LOD_POINTS, the coarse hull, no FXAA (Pose mode: no FXAA only)."""
        self.dragging = bool(on)
        self.hold_quality(self.dragging)
        if not self.posing:
            self.hull.set_dragging(self.dragging)
            self._update_cloud()

    def hold_quality(self, on: bool) -> None:
        """While held: no FXAA (~16 ms of a held 42 ms frame, software GL 1200x800; live preview 10.3 -> 12.6
        f/s) and no order-independent transparency: the translucent hull blends straight into the frame instead
        of through OIT's float buffers and full-window composite (#65: a held frame of mannequin-large 60 -> 25
        ms on llvmpipe). The hull is one colour, so the order it is blended in barely shows; the frame after
        release has both again."""
        renderer = self.plotter.renderer
        if on and self._after_drag is None:
            self._after_drag = (bool(renderer.GetUseFXAA()), bool(renderer.GetUseOIT()))
            renderer.SetUseFXAA(False)
            renderer.SetUseOIT(False)
        elif not on and self._after_drag is not None:
            fxaa, oit = self._after_drag
            renderer.SetUseFXAA(fxaa)
            renderer.SetUseOIT(oit)
            self._after_drag = None
            self.render()

    def _drawn(self) -> tuple[np.ndarray, np.ndarray]:
        shown = self._shown
        if self.dragging and len(shown) > LOD_POINTS:
            shown = shown[np.linspace(0, len(shown) - 1, LOD_POINTS).astype(np.int64)]
        elif len(shown) == self.doc.visible_count:  # the plain prefix: slices, no copies
            n = len(shown)
            return self._world[:n], self._colours[:n]
        return self._world[shown], self._colours[shown]

    def _update_cloud(self) -> None:
        self._shown = self.doc.shown_indices() if self.doc.skeleton is not None else np.zeros(0, np.int64)
        n = len(self._shown)
        world, colours = self._drawn()
        spheres = self.settings.spheres and not self.dragging  # held slider: flat points (software GL: ~2x faster)
        if self._cloud_actor is None:
            if not n:
                return
            poly = pv.PolyData(world)
            poly.point_data["rgb"] = colours
            self._cloud_actor = self.plotter.add_mesh(
                poly, scalars="rgb", rgb=True, point_size=self.settings.point_size,
                render_points_as_spheres=spheres, name="cloud", render=False, reset_camera=False)
            self._cloud_actor.GetProperty().SetLighting(spheres)
        else:
            poly = pv.PolyData(world) if n else pv.PolyData()
            if n:
                poly.point_data["rgb"] = colours
            self._cloud_actor.mapper.SetInputData(poly)
            prop = self._cloud_actor.GetProperty()
            prop.SetPointSize(self.settings.point_size)
            prop.SetRenderPointsAsSpheres(spheres)
            # flat points have no normals to light: unlit they look the same and draw 2x faster in software GL
            prop.SetLighting(spheres)
        self.apply_stage()
        self.render()

    def _on_thinness_changed(self, **_) -> None:
        self._update_cloud()

    @property
    def shown(self) -> np.ndarray:
        """Indices of the skeleton points on screen (thinness prefix, then filters)."""
        return self._shown

    @property
    def shown_points(self) -> int:
        """How many points the cloud actor draws right now."""
        if self._cloud_actor is None:
            return 0
        return int(self._cloud_actor.mapper.GetInput().GetNumberOfPoints())

    # ----------------------------------------------- what bones and selection change in the cloud
    def _on_bones_changed(self, **_) -> None:  # the actors of the bones are BonesLayer's
        if self.doc.skeleton is not None and self.settings.colour_by == "bone":
            self._recolour()
            self._update_cloud()
        elif self.doc.only_working:
            self._update_cloud()

    def _on_selection_changed(self, **_) -> None:  # "only the working bone's points" follows the selection
        if self.doc.only_working:
            self._update_cloud()

    def _on_picked_changed(self, index=None, **_) -> None:
        self.plotter.remove_actor("picked", render=False)
        self._picked_actor = None
        if index is not None:
            self._picked_actor = self.plotter.add_mesh(
                pv.PolyData(self._world[index : index + 1]), color="#00ffff", point_size=self.settings.point_size * 2.5,
                render_points_as_spheres=True, name="picked", render=False, reset_camera=False)
        self.apply_stage()
        self.render()

    # ---------------------------------------------------------------- stages
    def set_posing(self, on: bool) -> None:
        """Pose stage: the preview and the posed bones; edit stage: hull, cloud and rest bones."""
        self.posing = bool(on)
        self.apply_stage()
        if self.posing:
            self.pose_layer.on_pose_changed()
        self.render()

    def apply_stage(self) -> None:
        """Show the edit stage's actors or the pose stage's, whichever is current."""
        actors = self.plotter.renderer.actors
        for name in self.EDIT_ACTORS:
            if name in actors:
                actors[name].SetVisibility(not self.posing)
        if "hull" in actors:
            actors["hull"].SetVisibility(not self.posing and self.settings.hull_visible)
        for name in self.POSE_ACTORS:
            if name in actors:
                actors[name].SetVisibility(self.posing)
        self.xray.show(self.posing)
        self.names.show(not self.posing)

    def render(self) -> None:
        """Request a frame; many model changes in one event-loop pass draw once (software GL takes 100-500 ms for a
        large cloud). On screen, the widget's update() at once: Qt composes it with the labels changed beside it.
        A zero timer composed a live picture's status line first, then the picture: 15-20 ms more a picture (#85)."""
        self.frames.changed()
        if not self.in_qt:  # an off-screen Plotter: no event loop to gather renders in, so now
            self._render_now()
        elif self._drawn_once and self.plotter.isVisible():
            self.plotter.update()  # the widget's paint renders (plotter.render() would render the frame twice)
        elif not self._render_pending:
            from PySide6.QtCore import QTimer

            self._render_pending = True
            QTimer.singleShot(0, self._render_now)

    def _render_now(self) -> None:
        self._render_pending = False
        if getattr(self.plotter, "_closed", False):
            return
        if self._drawn_once and self.in_qt and self.plotter.isVisible():
            self.plotter.update()
            return
        self.frames.prepare()  # pyvista skips a window's render before it is shown: fitted here all the same
        self.plotter.render()  # also tells pyvista the window has rendered (screenshots need it)
        self._drawn_once = True
