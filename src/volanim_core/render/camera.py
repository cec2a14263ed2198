"""A camera that stays put for a whole sequence: named views, or one saved from the studio.

    named_view(name, bounds) --> Camera looking at the middle of ``bounds`` (the shared grid)
    Camera <--> a ``.camera`` text file (io.render_files)

Our figures stand z up and face -y (FORMATS.md's voxel axes), so *front*
looks from -y, *side* from +x (the figure's left), *top* from +z with the
figure facing the bottom of the picture, and *three-quarter* from the front
left, a little above.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

VIEWS = ("front", "side", "top", "three-quarter", "back")
_DIRECTIONS = {  # from the focal point to the camera, and the picture's up
    "front": ((0.0, -1.0, 0.0), (0.0, 0.0, 1.0)),
    "back": ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0)),
    "side": ((1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
    "top": ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0)),
    "three-quarter": ((0.6, -0.75, 0.3), (0.0, 0.0, 1.0)),
}


@dataclass(frozen=True)
class Camera:
    position: tuple[float, float, float]
    focal_point: tuple[float, float, float]
    view_up: tuple[float, float, float] = (0.0, 0.0, 1.0)
    view_angle: float = 30.0  # degrees, perspective
    parallel_scale: float | None = None  # set: a parallel projection, half the picture's height in voxels

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

    @classmethod
    def of(cls, vtk_camera) -> Camera:
        """The camera a ``vtkCamera`` has now (the studio's view)."""
        parallel = bool(vtk_camera.GetParallelProjection())
        return cls(tuple(vtk_camera.GetPosition()), tuple(vtk_camera.GetFocalPoint()), tuple(vtk_camera.GetViewUp()),
                   float(vtk_camera.GetViewAngle()), float(vtk_camera.GetParallelScale()) if parallel else None)


def named_view(name: str, lo, hi, aspect: float = 4 / 3, view_angle: float = 30.0) -> Camera:
    """A camera from direction ``name`` that frames the box ``lo..hi`` (voxel coordinates) whole
    in a picture of width/height ``aspect``, from far enough that the whole box fits."""
    if name not in _DIRECTIONS:
        raise ValueError(f"unknown view {name!r}; choose one of {', '.join(VIEWS)}")
    lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    centre = (lo + hi) / 2
    radius = max(float(np.linalg.norm(hi - lo)) / 2, 1.0)  # the box's bounding sphere
    direction, up = (np.asarray(v) for v in _DIRECTIONS[name])
    direction = direction / np.linalg.norm(direction)
    half = np.radians(view_angle) / 2
    fit = np.arctan(np.tan(half) * min(aspect, 1.0))  # the narrower of the two half-angles
    distance = radius / np.sin(fit)
    return Camera(tuple(centre + direction * distance), tuple(centre), tuple(up), float(view_angle))
