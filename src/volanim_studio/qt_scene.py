"""The rendering layer: owns the VTK actors and turns clicks into pick events.

    Document events --> SceneView._on_<prop>_changed --> actors --> render()
    VTK mouse press/release (no drag) --> pick(x, y) --> PickEvent --> on_pick callback

The scene never edits the document; the main window routes pick events to
the active mode. Picking projects the shown points with the renderer's own
camera matrices (``scene_projection``), so the translucent hull can never
intercept a click and HiDPI scaling cannot offset it.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pyvista as pv
from matplotlib import colormaps
from matplotlib.colors import ListedColormap

from .model.document import Document
from .model.modes import PickEvent
from .model.palette import UNCONNECTED, bone_colour, rgb
from .scene_preview import apply_labels, binary_view, rgb255, volume_style
from .scene_projection import nearest_in_radius, project, segment_distance_2d

LOD_POINTS = 50_000  # drawn while the thinness slider is dragged (software GL renders ~5x fewer per second)
PICK_RADIUS = 8.0  # logical pixels; scaled by the device pixel ratio
CLICK_SLOP = 4.0  # a press and release further apart than this is a drag (camera), not a click


def _vtk_matrix(m) -> np.ndarray:
    return np.array([[m.GetElement(i, j) for j in range(4)] for i in range(4)])


class SceneView:
    """Actors for hull, cloud, bones and joints over a pyvista ``QtInteractor``."""

    def __init__(self, plotter, doc: Document, on_pick: Callable[[PickEvent], None] | None = None):
        self.plotter = plotter
        self.doc = doc
        self.on_pick = on_pick
        self.colour_by = "thinness"
        self.point_size = 6.0
        self.spheres = True
        self.hull_opacity = 0.15
        self.hull_visible = True
        self.clip_axis: int | None = None
        self.clip_position = 0.5
        self._hull_actor = self._cloud_actor = self._bones_actor = self._joints_actor = None
        self._selected_actor = self._picked_actor = None
        self._world = np.zeros((0, 3), np.float32)
        self._colours = np.zeros((0, 3), np.uint8)
        self._press = None
        self._shown = np.zeros(0, np.int64)
        self._lasso: list | None = None  # display points of the outline being drawn
        self.lasso_enabled = False
        self.on_lasso = None  # callback(polygon, ctrl)
        self._lasso_actor = None
        self._cube_actor = None
        self._trackball = None
        self._preview_actor = None
        self._preview_key = None
        self.posing = False
        self.slices = False
        self.dragging = False  # the thinness slider is held: draw a level-of-detail subset
        self._render_pending = False
        plotter.set_background("#1e1f24")
        self._fix_pixel_ratio()
        iren = plotter.iren
        iren.add_observer("LeftButtonPressEvent", self._on_press)
        iren.add_observer("LeftButtonReleaseEvent", self._on_release)
        iren.add_observer("RightButtonPressEvent", self._on_press)
        iren.add_observer("RightButtonReleaseEvent", self._on_release)
        ev = doc.events
        ev.volume.connect(self._on_hull_changed)
        ev.hull.connect(self._on_hull_changed)
        ev.skeleton.connect(self._on_skeleton_changed)
        ev.thinness.connect(self._on_thinness_changed)
        ev.bones.connect(self._on_bones_changed)
        ev.selection.connect(self._on_selection_changed)
        ev.picked.connect(self._on_picked_changed)
        ev.attachments.connect(self._on_attachments_changed)
        ev.filter.connect(self._on_thinness_changed)
        ev.cube.connect(self._on_cube_changed)
        ev.pose.connect(self._on_pose_changed)
        raw = plotter.iren.interactor  # raw VTK observers: they run before the camera style
        raw.AddObserver("LeftButtonPressEvent", self._lasso_press, 10.0)
        raw.AddObserver("MouseMoveEvent", self._lasso_move, 10.0)
        raw.AddObserver("LeftButtonReleaseEvent", self._lasso_release, 10.0)

    def _fix_pixel_ratio(self) -> None:
        # VTK's QVTKRenderWindowInteractor scales events by the DPR of the screen
        # under the *cursor*, which is wrong on mixed-DPI desktops (pyvistaqt #20,
        # VTK MR 4201); use the widget's own ratio for both size and events.
        widget = self.plotter
        if hasattr(widget, "_getPixelRatio"):
            widget._getPixelRatio = lambda: float(widget.devicePixelRatioF())

    # ---------------------------------------------------------- coordinates
    @property
    def spacing(self) -> np.ndarray:
        return np.asarray(self.doc.spacing, np.float64)

    def world(self, voxel_xyz) -> np.ndarray:
        return np.asarray(voxel_xyz, np.float64) * self.spacing

    def _camera(self):
        ren = self.plotter.renderer
        width, height = ren.GetSize()
        x0, y0 = ren.GetOrigin()
        m = ren.GetActiveCamera().GetCompositeProjectionTransformMatrix(width / max(height, 1), -1, 1)
        return _vtk_matrix(m), (x0, y0, width, height)

    def project_world(self, world_points) -> tuple[np.ndarray, np.ndarray]:
        """Display pixels (device, bottom-left origin) and depth of world points."""
        matrix, viewport = self._camera()
        return project(world_points, matrix, viewport)

    def display_of_point(self, index: int) -> np.ndarray:
        """Where skeleton point ``index`` is drawn, in display pixels."""
        return self.project_world(self.world(self.doc.skeleton.points[index])[None])[0][0]

    def pixel_ratio(self) -> float:
        return float(self.plotter.devicePixelRatioF())

    # ---------------------------------------------------------------- picks
    def pick(self, x: float, y: float) -> PickEvent:
        """What is under display position ``(x, y)``: point, joint and bone (each may be None)."""
        radius = PICK_RADIUS * self.pixel_ratio()
        point = joint = bone = None
        shown = self._shown
        if len(shown):
            xy, depth = self.project_world(self._world[shown])
            k = nearest_in_radius(xy, depth, (x, y), radius)
            point = None if k is None else int(shown[k])
        names = list(self.doc.bones.joints)
        if names:
            jw = self.world(np.array([self.doc.bones.joints[k] for k in names]))
            jxy, jdepth = self.project_world(jw)
            k = nearest_in_radius(jxy, jdepth, (x, y), radius)
            joint = names[k] if k is not None else None
            segs = self.doc.bones.segments()
            if len(segs):
                a, _ = self.project_world(self.world(segs[:, 0]))
                b, _ = self.project_world(self.world(segs[:, 1]))
                d = segment_distance_2d((x, y), a, b)
                if d.min() <= radius:
                    bone = int(np.argmin(d))
        return PickEvent(point=point, joint=joint, bone=bone)

    def _event_position(self) -> tuple[int, int]:
        # pyvista hangs button observers on the interactor *style*; the position is the interactor's
        return self.plotter.iren.interactor.GetEventPosition()

    def _on_press(self, obj, event) -> None:
        if self.lasso_enabled and event.startswith("Left"):
            return
        self._press = self._event_position()

    def _on_release(self, obj, event) -> None:
        if self._press is None:
            return
        x, y = self._event_position()
        px, py = self._press
        self._press = None
        if abs(x - px) > CLICK_SLOP or abs(y - py) > CLICK_SLOP:
            return  # a drag moved the camera
        ev = self.pick(x, y)
        button = "right" if event.startswith("Right") else "left"
        if self.on_pick is not None:
            self.on_pick(PickEvent(ev.point, ev.joint, ev.bone, button))

    # ---------------------------------------------------------------- hull
    def _on_hull_changed(self, **_) -> None:
        if self._hull_actor is not None:
            self.plotter.remove_actor(self._hull_actor, render=False)
            self._hull_actor = None
        if self.doc.hull is None:
            self.render()
            return
        verts, faces = self.doc.hull
        cells = np.hstack([np.full((len(faces), 1), 3), faces]).ravel()
        mesh = pv.PolyData(self.world(verts).astype(np.float32), cells)
        self._hull_actor = self.plotter.add_mesh(
            mesh, color="#d8c8b0", opacity=self.hull_opacity, pickable=False, smooth_shading=True,
            name="hull", render=False, reset_camera=False)
        self._apply_hull_state()
        self._apply_stage()
        self.front_view()

    def _apply_hull_state(self) -> None:
        a = self._hull_actor
        if a is None:
            return
        a.SetVisibility(self.hull_visible)
        a.GetProperty().SetOpacity(self.hull_opacity)
        mapper = a.GetMapper()
        mapper.RemoveAllClippingPlanes()
        if self.clip_axis is not None and self.doc.shape is not None:
            import vtk

            plane = vtk.vtkPlane()
            origin = [0.0, 0.0, 0.0]
            extent = (self.doc.shape[self.clip_axis] - 1) * self.spacing[self.clip_axis]
            origin[self.clip_axis] = self.clip_position * extent
            normal = [0.0, 0.0, 0.0]
            normal[self.clip_axis] = -1.0
            plane.SetOrigin(origin)
            plane.SetNormal(normal)
            mapper.AddClippingPlane(plane)

    def set_hull(self, *, visible=None, opacity=None, clip_axis="keep", clip_position=None) -> None:
        if visible is not None:
            self.hull_visible = bool(visible)
        if opacity is not None:
            self.hull_opacity = float(opacity)
        if clip_axis != "keep":
            self.clip_axis = clip_axis
        if clip_position is not None:
            self.clip_position = float(clip_position)
        self._apply_hull_state()
        self.render()

    # ---------------------------------------------------------------- cloud
    def _on_skeleton_changed(self, **_) -> None:
        s = self.doc.skeleton
        self._world = np.zeros((0, 3), np.float32) if s is None else self.world(s.points).astype(np.float32)
        self._recolour()
        self._update_cloud()
        if self._hull_actor is None and len(self._world):
            self.front_view()

    def front_view(self) -> None:
        """Look along +y (from the front of a figure facing -y), z up, everything in view."""
        ren = self.plotter.renderer
        b = ren.ComputeVisiblePropBounds()
        if b[0] > b[1]:
            return
        c = [(b[0] + b[1]) / 2, (b[2] + b[3]) / 2, (b[4] + b[5]) / 2]
        cam = ren.GetActiveCamera()
        cam.SetFocalPoint(*c)
        cam.SetPosition(c[0], c[1] - 3 * max(b[1] - b[0], b[5] - b[4], 1.0), c[2])
        cam.SetViewUp(0, 0, 1)
        ren.ResetCamera()
        self.render()

    def _recolour(self) -> None:
        s = self.doc.skeleton
        if s is None or not len(s):
            self._colours = np.zeros((0, 3), np.uint8)
            return
        self._colours = self.point_colours()

    def point_colours(self) -> np.ndarray:
        """RGB per skeleton point for the current colour-by setting."""
        s = self.doc.skeleton
        if self.colour_by == "bone":
            return self._bone_rgb()[self.doc.attachments.bone + 1]
        values = s.dt if self.colour_by == "dt" else s.thinness
        lo, hi = float(values.min()), float(values.max())
        t = (values - lo) / (hi - lo) if hi > lo else np.zeros(len(values))
        cmap = colormaps["viridis" if self.colour_by == "dt" else "plasma"]
        return (cmap(t)[:, :3] * 255).astype(np.uint8)

    def _bone_rgb(self) -> np.ndarray:
        """Row 0: unconnected grey; row b + 1: bone b's colour."""
        cols = [rgb(UNCONNECTED)] + [rgb(bone_colour(i)) for i in range(len(self.doc.bones))]
        return (np.array(cols) * 255).astype(np.uint8)

    def _on_attachments_changed(self, indices=None, **_) -> None:
        if self.colour_by == "bone" and self.doc.skeleton is not None:
            if indices is None or len(self._colours) != len(self.doc.skeleton):
                self._recolour()
            else:
                self._colours[indices] = self._bone_rgb()[self.doc.attachments.bone[indices] + 1]
        self._update_cloud()

    def set_cloud_style(self, *, colour_by=None, point_size=None, spheres=None) -> None:
        if colour_by is not None:
            self.colour_by = colour_by
            self._recolour()
        if point_size is not None:
            self.point_size = float(point_size)
        if spheres is not None:
            self.spheres = bool(spheres)
        self._update_cloud()

    def set_dragging(self, on: bool) -> None:
        """While the slider is held draw at most LOD_POINTS; the full prefix on release."""
        self.dragging = bool(on)
        self._update_cloud()

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
        if self._cloud_actor is None:
            if not n:
                return
            poly = pv.PolyData(world)
            poly.point_data["rgb"] = colours
            self._cloud_actor = self.plotter.add_mesh(
                poly, scalars="rgb", rgb=True, point_size=self.point_size,
                render_points_as_spheres=self.spheres, name="cloud", render=False, reset_camera=False)
        else:
            poly = pv.PolyData(world) if n else pv.PolyData()
            if n:
                poly.point_data["rgb"] = colours
            self._cloud_actor.mapper.SetInputData(poly)
            prop = self._cloud_actor.GetProperty()
            prop.SetPointSize(self.point_size)
            prop.SetRenderPointsAsSpheres(self.spheres)
        self._apply_stage()
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

    # ---------------------------------------------------------------- bones
    def _on_bones_changed(self, **_) -> None:
        if self.colour_by == "bone" and self.doc.skeleton is not None:
            self._recolour()
            self._update_cloud()
        for name in ("bones", "joints", "selected"):
            self.plotter.remove_actor(name, render=False)
        self._bones_actor = self._joints_actor = self._selected_actor = None
        bones = self.doc.bones
        if len(bones.joints):
            jpos = self.world(np.array(list(bones.joints.values())))
            self._joints_actor = self.plotter.add_mesh(
                pv.PolyData(jpos.astype(np.float32)), color="white", point_size=14,
                render_points_as_spheres=True, name="joints", render=False, reset_camera=False)
        if len(bones):
            segs = self.world(bones.segments().reshape(-1, 3))
            lines = np.hstack([np.full((len(bones), 1), 2), np.arange(2 * len(bones)).reshape(-1, 2)]).ravel()
            poly = pv.PolyData(segs.astype(np.float32), lines=lines)
            poly.cell_data["rgb"] = (np.array([rgb(bone_colour(i)) for i in range(len(bones))]) * 255).astype(
                np.uint8)
            self._bones_actor = self.plotter.add_mesh(
                poly, scalars="rgb", rgb=True, line_width=6, render_lines_as_tubes=True, name="bones",
                render=False, reset_camera=False)
        self._on_selection_changed()

    def _on_selection_changed(self, **_) -> None:
        if self.doc.only_working:
            self._update_cloud()
        self.plotter.remove_actor("selected", render=False)
        self._selected_actor = None
        sel = [i for i in self.doc.selected_bones if i < len(self.doc.bones)]
        if sel:
            segs = self.world(self.doc.bones.segments()[sel].reshape(-1, 3))
            lines = np.hstack([np.full((len(sel), 1), 2), np.arange(2 * len(sel)).reshape(-1, 2)]).ravel()
            self._selected_actor = self.plotter.add_mesh(
                pv.PolyData(segs.astype(np.float32), lines=lines), color="white", line_width=12,
                render_lines_as_tubes=True, opacity=0.5, name="selected", render=False, reset_camera=False)
        self._apply_stage()
        self.render()

    def _on_picked_changed(self, index=None, **_) -> None:
        self.plotter.remove_actor("picked", render=False)
        self._picked_actor = None
        if index is not None:
            self._picked_actor = self.plotter.add_mesh(
                pv.PolyData(self._world[index : index + 1]), color="#00ffff", point_size=self.point_size * 2.5,
                render_points_as_spheres=True, name="picked", render=False, reset_camera=False)
        self._apply_stage()
        self.render()

    # ---------------------------------------------------------------- cube
    def _on_cube_changed(self, **_) -> None:
        self.plotter.remove_actor("cube", render=False)
        self._cube_actor = None
        if self.doc.cube_centre is not None:
            c = self.world(self.doc.cube_centre)
            size = self.doc.cube_size * self.spacing
            box = pv.Box(bounds=(c[0] - size[0] / 2, c[0] + size[0] / 2, c[1] - size[1] / 2, c[1] + size[1] / 2,
                                 c[2] - size[2] / 2, c[2] + size[2] / 2))
            self._cube_actor = self.plotter.add_mesh(box, style="wireframe", color="#00ffff", line_width=2,
                                                     name="cube", render=False, reset_camera=False, pickable=False)
        self._apply_stage()
        self.render()

    # ---------------------------------------------------------------- lasso
    def set_lasso_enabled(self, on: bool) -> None:
        """In lasso mode a left drag draws an outline; the camera keeps the wheel only."""
        import vtk

        iren = self.plotter.iren.interactor
        if on and not self.lasso_enabled:
            self._trackball = iren.GetInteractorStyle()
            iren.SetInteractorStyle(vtk.vtkInteractorStyleUser())
        elif not on and self.lasso_enabled and self._trackball is not None:
            iren.SetInteractorStyle(self._trackball)
        self.lasso_enabled = bool(on)

    def _lasso_press(self, obj, event) -> None:
        if self.lasso_enabled:
            self._lasso = [self._event_position()]

    def _lasso_move(self, obj, event) -> None:
        if self.lasso_enabled and self._lasso is not None:
            self._lasso.append(self._event_position())
            self._draw_lasso()

    def _lasso_release(self, obj, event) -> None:
        if not self.lasso_enabled or self._lasso is None:
            return
        polygon = np.asarray(self._lasso + [self._event_position()], np.float64)
        self._lasso = None
        self._draw_lasso()
        ctrl = bool(self.plotter.iren.interactor.GetControlKey())
        if self.on_lasso is not None and len(polygon) >= 3:
            self.on_lasso(polygon, ctrl)

    def _draw_lasso(self) -> None:
        import vtk

        ren = self.plotter.renderer
        if self._lasso_actor is not None:
            ren.RemoveViewProp(self._lasso_actor)
            self._lasso_actor = None
        if self._lasso and len(self._lasso) > 1:
            pts = vtk.vtkPoints()
            for x, y in self._lasso:
                pts.InsertNextPoint(x, y, 0)
            line = vtk.vtkPolyLine()
            line.GetPointIds().SetNumberOfIds(len(self._lasso) + 1)
            for i in range(len(self._lasso)):
                line.GetPointIds().SetId(i, i)
            line.GetPointIds().SetId(len(self._lasso), 0)
            cells = vtk.vtkCellArray()
            cells.InsertNextCell(line)
            poly = vtk.vtkPolyData()
            poly.SetPoints(pts)
            poly.SetLines(cells)
            mapper = vtk.vtkPolyDataMapper2D()
            mapper.SetInputData(poly)
            actor = vtk.vtkActor2D()
            actor.SetMapper(mapper)
            actor.GetProperty().SetColor(1.0, 0.85, 0.2)
            actor.GetProperty().SetLineWidth(2)
            ren.AddViewProp(actor)
            self._lasso_actor = actor
        self.render()

    def shown_projection(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(shown indices, display xy, normalised depth, distance along the view)`` of the shown points."""
        shown = self._shown
        world = self._world[shown].astype(np.float64)
        xy, depth = self.project_world(world)
        cam = self.plotter.renderer.GetActiveCamera()
        pos, focal = np.array(cam.GetPosition()), np.array(cam.GetFocalPoint())
        direction = (focal - pos) / max(np.linalg.norm(focal - pos), 1e-12)
        return shown, xy, depth, (world - pos) @ direction

    # ------------------------------------------------------------- posing
    def set_posing(self, on: bool) -> None:
        """Pose stage: the preview and the posed bones; edit stage: hull, cloud and rest bones."""
        self.posing = bool(on)
        self._apply_stage()
        if self.posing:
            self._on_pose_changed()
        self.render()

    EDIT_ACTORS = ("cloud", "bones", "joints", "selected", "picked", "cube")
    POSE_ACTORS = ("preview", "posed_bones", "slices")

    def _apply_stage(self) -> None:
        """Show the edit stage's actors or the pose stage's, whichever is current."""
        actors = self.plotter.renderer.actors
        for name in self.EDIT_ACTORS:
            if name in actors:
                actors[name].SetVisibility(not self.posing)
        if "hull" in actors:
            actors["hull"].SetVisibility(not self.posing and self.hull_visible)
        for name in self.POSE_ACTORS:
            if name in actors:
                actors[name].SetVisibility(self.posing)

    def _on_pose_changed(self, **_) -> None:
        if not self.posing:
            return
        self.plotter.remove_actor("posed_bones", render=False)
        bones = self.doc.bones
        if len(bones):
            pj = self.doc.pose.posed_joints()
            segs = self.world(np.array([[pj[b.proximal], pj[b.distal]] for b in bones.bones]).reshape(-1, 3))
            lines = np.hstack([np.full((len(bones), 1), 2), np.arange(2 * len(bones)).reshape(-1, 2)]).ravel()
            poly = pv.PolyData(segs.astype(np.float32), lines=lines)
            poly.cell_data["rgb"] = np.array([rgb255(bone_colour(i)) for i in range(len(bones))])
            self.plotter.add_mesh(poly, scalars="rgb", rgb=True, line_width=5, render_lines_as_tubes=True,
                                  name="posed_bones", render=False, reset_camera=False)
        self.render()

    def show_volume(self, volume: np.ndarray, origin_voxels, spacing_voxels, mode: str) -> None:
        """Draw a reconstruction; a live update with the same grid and mode only swaps the data."""
        n_bones = len(self.doc.bones)
        if mode in ("binary",):
            volume = binary_view(volume)
        world_origin = self.world(origin_voxels)
        world_spacing = np.asarray(spacing_voxels, np.float64) * self.spacing
        img = pv.ImageData(dimensions=volume.shape, origin=world_origin, spacing=world_spacing)
        img.point_data["values"] = np.asarray(volume).ravel(order="F")
        key = (mode, volume.shape, tuple(world_origin), tuple(world_spacing), n_bones,
               float(volume.max()) if mode == "hotspot" else 0)
        if self._preview_actor is not None and key == self._preview_key:
            self._preview_actor.mapper.SetInputData(img)
        else:
            self.plotter.remove_actor("preview", render=False)
            self.plotter.remove_scalar_bar() if self.plotter.scalar_bars else None
            style = volume_style(mode, volume, n_bones)
            labels = style.pop("categories", None)
            self._preview_actor = self.plotter.add_volume(img, scalars="values", name="preview", render=False,
                                                          reset_camera=False, **style)
            if labels is not None:
                apply_labels(self._preview_actor, labels)
            self._preview_key = key
        self._preview_actor.SetVisibility(self.posing)
        self.plotter.remove_actor("slices", render=False)
        if self.slices:
            style = volume_style(mode, volume, n_bones)
            labels = style.get("categories")
            cmap = style["cmap"] if labels is None else ListedColormap(np.vstack([[0.1, 0.1, 0.1], labels]))
            clim = style["clim"] if labels is None else (0, len(labels))
            self.plotter.add_mesh(img.slice_orthogonal(), scalars="values", cmap=cmap, clim=clim,
                                  n_colors=256 if labels is None else len(labels) + 1, show_scalar_bar=False,
                                  name="slices", render=False, reset_camera=False)
        self.render()

    def show_surface(self, volume: np.ndarray, origin_voxels, spacing_voxels, mode: str) -> None:
        """A live preview: the reconstruction's surface coloured by label (software GL draws a
        surface far faster than it ray-casts a volume)."""
        world_origin = self.world(origin_voxels)
        world_spacing = np.asarray(spacing_voxels, np.float64) * self.spacing
        img = pv.ImageData(dimensions=volume.shape, origin=world_origin, spacing=world_spacing)
        img.point_data["values"] = (np.asarray(volume) > 0).astype(np.uint8).ravel(order="F")
        surf = img.contour([0.5], scalars="values", method="flying_edges")
        self.plotter.remove_actor("preview", render=False)
        self.plotter.remove_actor("slices", render=False)
        self._preview_actor = self._preview_key = None
        if surf.n_points:
            idx = np.rint((np.asarray(surf.points) - world_origin) / world_spacing).astype(np.int64)
            idx = np.clip(idx, 0, np.array(volume.shape) - 1)
            labels = np.asarray(volume)[tuple(idx.T)].astype(np.int64)
            if mode == "bone":
                table = np.vstack([[140, 140, 140], [rgb255(bone_colour(i)) for i in range(len(self.doc.bones))]])
                surf.point_data["rgb"] = table[np.clip(labels, 0, len(table) - 1)].astype(np.uint8)
                self.plotter.add_mesh(surf, scalars="rgb", rgb=True, name="preview", render=False,
                                      reset_camera=False)
            else:
                self.plotter.add_mesh(surf, color="#e8c9a0", name="preview", render=False, reset_camera=False)
        self._apply_stage()
        self.render()

    def clear_volume(self) -> None:
        self.plotter.remove_actor("preview", render=False)
        self.plotter.remove_actor("slices", render=False)
        self._preview_actor = self._preview_key = None
        self.render()

    def jump_to(self, voxel_xyz) -> None:
        """Centre the view on a point and move closer."""
        cam = self.plotter.renderer.GetActiveCamera()
        target = self.world(voxel_xyz)
        pos, focal = np.array(cam.GetPosition()), np.array(cam.GetFocalPoint())
        cam.SetFocalPoint(*target)
        cam.SetPosition(*(target + 0.5 * (pos - focal)))
        self.plotter.renderer.ResetCameraClippingRange()
        self.render()

    def render(self) -> None:
        """Request a frame; many model changes in one event-loop pass draw once.

        Software GL (no GPU) takes 100-500 ms for a large cloud, so drawing on
        every slider step would stall the drag.
        """
        if self._render_pending:
            return
        self._render_pending = True
        from PySide6.QtCore import QTimer

        QTimer.singleShot(0, self._render_now)

    def _render_now(self) -> None:
        self._render_pending = False
        if not getattr(self.plotter, "_closed", False):
            self.plotter.render()
