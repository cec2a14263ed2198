"""The selection overlays of the scene: the connect cube and the lasso outline.

A mixin of :class:`~volanim_studio.scene.view.SceneView`: in lasso mode a left
drag draws an outline in display pixels (VTK's camera style is swapped out)
and hands the closed polygon to ``on_lasso``.
"""

from __future__ import annotations

import numpy as np
import pyvista as pv


class SceneSelectionMixin:
    # ---------------------------------------------------------------- cube
    def _on_cube_changed(self, **_) -> None:
        self.plotter.remove_actor("cube", render=False)
        self._cube_actor = None
        if self.doc.cube_centre is not None:
            c = self.world(self.doc.cube_centre)
            size = self.settings.cube_size * self.spacing
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

