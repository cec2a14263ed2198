"""A camera as plain data: where it stands, what it looks at, which way is up, how wide it sees.

    Camera <--> a ``.camera`` text file (io.render_files)
    Camera --apply--> a ``vtkCamera``; a ``vtkCamera`` --Camera.of--> Camera (duck-typed: no VTK import)

Here, below ``render/``, so that ``io`` reads and writes camera files without importing the renderer
(the ``core-layers`` contract, pyproject.toml); the named views and the follow camera are in ``render/views.py``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Camera:
    position: tuple[float, float, float]
    focal_point: tuple[float, float, float]
    view_up: tuple[float, float, float] = (0.0, 0.0, 1.0)
    view_angle: float = 30.0  # degrees, perspective
    parallel_scale: float | None = None  # set: a parallel projection, half the picture's height in voxels

    def __post_init__(self):  # a camera at NaN is no camera (the rest: check(), naming a file's line)
        if not all(np.all(np.isfinite(np.asarray(v, np.float64)))
                   for v in (self.position, self.focal_point, self.view_up, self.view_angle)):
            raise ValueError("camera: every number must be finite")

    def check(self, where: str = "camera") -> None:
        """Refuse a camera that cannot make a picture (ValueError naming the fault)."""
        pos, focal, up = (np.asarray(v, np.float64) for v in (self.position, self.focal_point, self.view_up))
        if not all(np.all(np.isfinite(v)) for v in (pos, focal, up)):
            raise ValueError(f"{where}: every number must be finite")
        look = focal - pos
        if np.linalg.norm(look) == 0:
            raise ValueError(f"{where}: the position and the focal point are the same point")
        if np.linalg.norm(np.cross(look, up)) <= 1e-9 * np.linalg.norm(look) * np.linalg.norm(up):
            raise ValueError(f"{where}: view_up must not be zero or point along the line of sight")
        if not 0 < self.view_angle < 180:
            raise ValueError(f"{where}: view_angle must be between 0 and 180 degrees, got {self.view_angle:g}")
        if self.parallel_scale is not None and not self.parallel_scale > 0:
            raise ValueError(f"{where}: parallel_scale must be above 0, got {self.parallel_scale:g}")

    def apply(self, vtk_camera) -> None:
        """Set a ``vtkCamera`` (e.g. ``plotter.camera``) to this camera."""
        vtk_camera.SetPosition(*self.position)
        vtk_camera.SetFocalPoint(*self.focal_point)
        vtk_camera.SetViewUp(*self.view_up)
        vtk_camera.SetViewAngle(self.view_angle)
        vtk_camera.SetParallelProjection(self.parallel_scale is not None)
        if self.parallel_scale is not None:
            vtk_camera.SetParallelScale(self.parallel_scale)
        vtk_camera.OrthogonalizeViewUp()

    def scaled(self, factor) -> Camera:
        """This camera with world coordinates multiplied by ``factor`` per axis (e.g. ``1 / spacing``:
        a view of a volume with anisotropic voxels, in voxel coordinates as camera files are)."""
        f = np.asarray(factor, np.float64) * np.ones(3)
        up = np.asarray(self.view_up, np.float64)
        up = up / np.linalg.norm(up)
        stretched = up * f  # the picture's height is measured along view_up: it stretches as up does
        scale = None if self.parallel_scale is None else self.parallel_scale * float(np.linalg.norm(stretched))
        return Camera(tuple(np.asarray(self.position) * f), tuple(np.asarray(self.focal_point) * f),
                      tuple(stretched / np.linalg.norm(stretched)), self.view_angle, scale)

    @classmethod
    def of(cls, vtk_camera) -> Camera:
        """The camera a ``vtkCamera`` has now (the studio's view: ``renderer.GetActiveCamera()``; not pyvista's
        ``plotter.camera``, whose first read resets a camera pyvista did not place to its own default view)."""
        parallel = bool(vtk_camera.GetParallelProjection())
        return cls(tuple(vtk_camera.GetPosition()), tuple(vtk_camera.GetFocalPoint()), tuple(vtk_camera.GetViewUp()),
                   float(vtk_camera.GetViewAngle()), float(vtk_camera.GetParallelScale()) if parallel else None)
