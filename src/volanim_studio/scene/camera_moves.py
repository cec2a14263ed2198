"""Camera moves and camera state of a pyvista plotter (plain lists, saved in projects)."""

from __future__ import annotations

import numpy as np

from volanim_core.render.scene import reset_clipping, visible_bounds

FOLLOW_SECONDS = 0.25  # a playing camera's easing, in the clip's time: no jitter from a swinging arm


def composite_matrix(renderer) -> tuple[np.ndarray, tuple[float, float, float, float]]:
    """The renderer's world -> clip matrix and its viewport ``(x0, y0, width, height)`` in pixels."""
    width, height = renderer.GetSize()
    x0, y0 = renderer.GetOrigin()
    m = renderer.GetActiveCamera().GetCompositeProjectionTransformMatrix(width / max(height, 1), -1, 1)
    return np.array([[m.GetElement(i, j) for j in range(4)] for i in range(4)]), (x0, y0, width, height)


def preset_view(renderer, name: str = "front", box=None, shape=None) -> bool:
    """Look from a named direction (``volanim_core.render.views.VIEWS``) at the world box ``box``
    (``(lo, hi)``; default: everything drawn), the object stood up by the shape of the box ``shape``
    (default ``box``; ``natural_axes``: the frog lies flat, the mannequin stands).

    Returns False when nothing is visible (the camera is left alone)."""
    from volanim_core.render.views import named_view, natural_axes

    if box is None:
        b = visible_bounds(renderer)  # the x-ray layer's posed bones too
        if b is None:
            return False
        box = (np.array(b[0::2]), np.array(b[1::2]))
    lo, hi = (np.asarray(v, np.float64) for v in box)
    w, h = renderer.GetSize()
    cam = named_view(name, lo, hi, aspect=w / h if w and h else 4 / 3, view_angle=30.0,
                     axes=natural_axes(*(box if shape is None else shape)), faces=0.0)
    cam.apply(renderer.GetActiveCamera())
    reset_clipping(renderer)
    return True


def frame(renderer, lo=None, hi=None) -> bool:
    """Keep the direction, move so that the box ``lo..hi`` (world; default everything shown) fills the view."""
    if lo is None:
        b = visible_bounds(renderer)
        if b is None:
            return False
    else:
        pad = 0.15 * max(float(np.max(np.asarray(hi) - np.asarray(lo))), 10.0)  # a point or a joint: some room
        b = [v for lo_, hi_ in zip(lo, hi) for v in (lo_ - pad, hi_ + pad)]
    renderer.ResetCamera(*b)
    reset_clipping(renderer)  # ResetCamera fits the planes to b alone: a framed joint must not cut the body
    return True


def move_closer_to(renderer, target) -> None:
    """Centre the view on ``target`` (world) and halve the distance to it."""
    cam = renderer.GetActiveCamera()
    pos, focal = np.array(cam.GetPosition()), np.array(cam.GetFocalPoint())
    cam.SetFocalPoint(*target)
    cam.SetPosition(*(np.asarray(target, np.float64) + 0.5 * (pos - focal)))
    reset_clipping(renderer)


def follow(renderer, target, blend: float = 1.0) -> None:
    """Move the camera by the way from its focal point to ``blend`` of the way to ``target`` (world): its
    direction, distance and zoom stay the user's. ``blend`` < 1 eases a playing camera (no jitter from a
    swinging arm); 1 lands on the body (a step, a jump)."""
    cam = renderer.GetActiveCamera()
    focal = np.array(cam.GetFocalPoint())
    shift = float(blend) * (np.asarray(target, np.float64) - focal)
    cam.SetFocalPoint(*(focal + shift))
    cam.SetPosition(*(np.array(cam.GetPosition()) + shift))
    reset_clipping(renderer)


def follow_blend(seconds: float, ease: float = FOLLOW_SECONDS) -> float:
    """The share of the way to the body a playing camera moves after ``seconds`` of the clip: eased in
    time, not by a share per picture. A share per picture (0.35) let the camera fall behind by the way the
    body went between pictures, so on a loaded machine (fewer pictures) a walk was drawn at the view's
    edge. Eased in time, it trails a body at speed v by at most v * ``ease`` at any picture rate."""
    return float(1.0 - np.exp(-max(float(seconds), 0.0) / ease))


def camera_state(renderer) -> dict:
    cam = renderer.GetActiveCamera()
    return {"position": list(cam.GetPosition()), "focal_point": list(cam.GetFocalPoint()),
            "view_up": list(cam.GetViewUp())}


def set_camera_state(renderer, data: dict) -> None:
    cam = renderer.GetActiveCamera()
    cam.SetPosition(*data["position"])
    cam.SetFocalPoint(*data["focal_point"])
    cam.SetViewUp(*data["view_up"])
    reset_clipping(renderer)


def view_distances(renderer, world: np.ndarray) -> np.ndarray:
    """Distance of each world point along the viewing direction (for depth-slab lasso modes)."""
    cam = renderer.GetActiveCamera()
    pos, focal = np.array(cam.GetPosition()), np.array(cam.GetFocalPoint())
    direction = (focal - pos) / max(np.linalg.norm(focal - pos), 1e-12)
    return (np.asarray(world, np.float64) - pos) @ direction
