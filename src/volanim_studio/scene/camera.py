"""Camera moves and camera state of a pyvista plotter (plain lists, saved in projects)."""

from __future__ import annotations

import numpy as np


def composite_matrix(renderer) -> tuple[np.ndarray, tuple[float, float, float, float]]:
    """The renderer's world -> clip matrix and its viewport ``(x0, y0, width, height)`` in pixels."""
    width, height = renderer.GetSize()
    x0, y0 = renderer.GetOrigin()
    m = renderer.GetActiveCamera().GetCompositeProjectionTransformMatrix(width / max(height, 1), -1, 1)
    return np.array([[m.GetElement(i, j) for j in range(4)] for i in range(4)]), (x0, y0, width, height)


def front_view(renderer) -> bool:
    """Look along +y (from the front of a figure facing -y), z up, everything in view.

    Returns False when nothing is visible (the camera is left alone)."""
    b = renderer.ComputeVisiblePropBounds()
    if b[0] > b[1]:
        return False
    c = [(b[0] + b[1]) / 2, (b[2] + b[3]) / 2, (b[4] + b[5]) / 2]
    cam = renderer.GetActiveCamera()
    cam.SetFocalPoint(*c)
    cam.SetPosition(c[0], c[1] - 3 * max(b[1] - b[0], b[5] - b[4], 1.0), c[2])
    cam.SetViewUp(0, 0, 1)
    renderer.ResetCamera()
    return True


def move_closer_to(renderer, target) -> None:
    """Centre the view on ``target`` (world) and halve the distance to it."""
    cam = renderer.GetActiveCamera()
    pos, focal = np.array(cam.GetPosition()), np.array(cam.GetFocalPoint())
    cam.SetFocalPoint(*target)
    cam.SetPosition(*(np.asarray(target, np.float64) + 0.5 * (pos - focal)))
    renderer.ResetCameraClippingRange()


def camera_state(renderer) -> dict:
    cam = renderer.GetActiveCamera()
    return {"position": list(cam.GetPosition()), "focal_point": list(cam.GetFocalPoint()),
            "view_up": list(cam.GetViewUp())}


def set_camera_state(renderer, data: dict) -> None:
    cam = renderer.GetActiveCamera()
    cam.SetPosition(*data["position"])
    cam.SetFocalPoint(*data["focal_point"])
    cam.SetViewUp(*data["view_up"])
    renderer.ResetCameraClippingRange()


def view_distances(renderer, world: np.ndarray) -> np.ndarray:
    """Distance of each world point along the viewing direction (for depth-slab lasso modes)."""
    cam = renderer.GetActiveCamera()
    pos, focal = np.array(cam.GetPosition()), np.array(cam.GetFocalPoint())
    direction = (focal - pos) / max(np.linalg.norm(focal - pos), 1e-12)
    return (np.asarray(world, np.float64) - pos) @ direction
