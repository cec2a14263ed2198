"""The selection overlays of the scene: the connect cube and the lasso outline.

Each overlay owns its actor and is handed the :class:`~volanim_studio.scene.view.SceneView`
for coordinates, the plotter and coalesced rendering. In lasso mode a left drag
draws an outline in display pixels (VTK's camera style is swapped out) and the
closed polygon goes to ``on_lasso``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pyvista as pv

from .projection import CLICK_SLOP


class CubeOverlay:
    """The wireframe connect cube, following ``doc.events.cube`` and ``settings.cube_size``."""

    def __init__(self, view):
        self.view = view
        self.actor = None
        view.doc.events.cube.connect(self._on_cube_changed)
        view.settings.events.cube_size.connect(self._on_cube_changed)

    def _on_cube_changed(self, **_) -> None:
        view = self.view
        view.plotter.remove_actor("cube", render=False)
        self.actor = None
        if view.doc.cube_centre is not None:
            c = view.world(view.doc.cube_centre)
            half = view.settings.cube_size * view.spacing / 2
            box = pv.Box(bounds=(c[0] - half[0], c[0] + half[0], c[1] - half[1], c[1] + half[1],
                                 c[2] - half[2], c[2] + half[2]))
            self.actor = view.plotter.add_mesh(box, style="wireframe", color="#00ffff", line_width=2,
                                               name="cube", render=False, reset_camera=False, pickable=False)
        view.apply_stage()
        view.render()


class LassoOverlay:
    """A left drag draws a closed outline; on release ``on_lasso(polygon, ctrl)`` gets it."""

    def __init__(self, view):
        self.view = view
        self.enabled = False
        self.on_lasso: Callable[[np.ndarray, bool], None] | None = None
        self.points: list | None = None  # display points of the outline being drawn
        self._actor = None
        self._trackball = None
        raw = view.plotter.iren.interactor  # raw VTK observers: they run before the camera style
        raw.AddObserver("LeftButtonPressEvent", self._press, 10.0)
        raw.AddObserver("MouseMoveEvent", self._move, 10.0)
        raw.AddObserver("LeftButtonReleaseEvent", self._release, 10.0)

    def set_enabled(self, on: bool) -> None:
        """In lasso mode a left drag draws an outline; the camera keeps the wheel only."""
        import vtk

        iren = self.view.plotter.iren.interactor
        if on and not self.enabled:
            self._trackball = iren.GetInteractorStyle()
            iren.SetInteractorStyle(vtk.vtkInteractorStyleUser())
        elif not on and self.enabled and self._trackball is not None:
            iren.SetInteractorStyle(self._trackball)
        self.enabled = bool(on)

    def _press(self, obj, event) -> None:
        if self.enabled:
            self.points = [self.view.event_position()]

    def _move(self, obj, event) -> None:
        if self.enabled and self.points is not None:
            self.points.append(self.view.event_position())
            self.draw()

    def _release(self, obj, event) -> None:
        if not self.enabled or self.points is None:
            return
        polygon = np.asarray(self.points + [self.view.event_position()], np.float64)
        self.points = None
        self.draw()
        if np.ptp(polygon, axis=0).max() <= CLICK_SLOP:  # a click, not an outline: it chooses the working bone
            self.view.click_at(*polygon[-1])
            return
        ctrl = bool(self.view.plotter.iren.interactor.GetControlKey())
        if self.on_lasso is not None and len(polygon) >= 3:
            self.on_lasso(polygon, ctrl)

    def draw(self) -> None:
        """Draw the outline so far (2-D, in display pixels), or remove it."""
        import vtk

        ren = self.view.plotter.renderer
        if self._actor is not None:
            ren.RemoveViewProp(self._actor)
            self._actor = None
        pts_xy = self.points
        if pts_xy and len(pts_xy) > 1:
            pts = vtk.vtkPoints()
            for x, y in pts_xy:
                pts.InsertNextPoint(x, y, 0)
            line = vtk.vtkPolyLine()
            ids = line.GetPointIds()
            ids.SetNumberOfIds(len(pts_xy) + 1)
            for i in range(len(pts_xy)):
                ids.SetId(i, i)
            ids.SetId(len(pts_xy), 0)
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
            self._actor = actor
        self.view.render()
