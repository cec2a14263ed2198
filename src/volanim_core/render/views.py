"""A camera that stays put for a whole sequence: named views, or one saved from the studio.

    named_view(name, bounds) --> Camera looking at the middle of ``bounds`` (every frame's body)
    follow_cameras(name, boxes) --> a Camera per frame, centred on its body (``--camera follow``)
    (Camera, the data type, is volanim_core.camera's: io reads camera files without the renderer)

Our figures stand z up and face -y (docs/formats.md's voxel axes), so *front*
looks from -y, *side* from +x (the figure's left), *top* from +z with the
figure facing the bottom of the picture, and *three-quarter* from the front
left, a little above.
"""

from __future__ import annotations

import numpy as np

from volanim_core.camera import Camera

__all__ = ["VIEWS", "Camera", "follow_cameras", "named_view", "natural_axes", "union_box"]

VIEWS = ("front", "side", "top", "three-quarter", "back")
_DIRECTIONS = {  # from the focal point to the camera, and the picture's up
    "front": ((0.0, -1.0, 0.0), (0.0, 0.0, 1.0)),
    "back": ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0)),
    "side": ((1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
    "top": ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0)),
    "three-quarter": ((0.6, -0.75, 0.3), (0.0, 0.0, 1.0)),
}


def natural_axes(lo, hi, clearly: float = 1.15) -> np.ndarray:
    """A rotation (columns: where x, y, z of the view table go) that stands an object up by its shape.

    The figures of the thesis stand z up and face -y, and so do the views above. A scan lying
    flat (the frog: 500 x 470 x 204 mm) seen that way shows its edge. Here the line of sight
    is the clearly (by ``clearly``) shortest extent and up the longer of the other two (the
    frog's x, head to legs); with
    no clearly shortest extent, up is the clearly longest; otherwise the axes stay as they are.
    """
    e = np.asarray(hi, np.float64) - np.asarray(lo, np.float64)
    order = [int(a) for a in np.argsort(e, kind="stable")]  # shortest ... longest
    if e[order[1]] > clearly * e[order[0]]:
        front = order[0]
        a, b = (x for x in range(3) if x != front)
        up = a if e[a] > e[b] else b if e[b] > e[a] else (2 if 2 in (a, b) else b)
    elif e[order[2]] > clearly * e[order[1]]:
        up = order[2]
        front = 1 if up != 1 else 0
    else:
        return np.eye(3)
    right = 3 - up - front
    axes = np.zeros((3, 3))
    axes[right, 0], axes[front, 1], axes[up, 2] = 1.0, 1.0, 1.0
    if np.linalg.det(axes) < 0:
        axes[right, 0] = -1.0  # a rotation, not a mirror: pictures are never flipped
    return axes


def named_view(name: str, lo, hi, aspect: float = 4 / 3, view_angle: float = 30.0, margin: float = 0.05,
               axes=None, faces: float = 0.5) -> Camera:
    """A camera from direction ``name`` at the distance where the box ``lo..hi`` just fits a picture of
    width/height ``aspect`` (plus ``margin`` around it): every corner of the box, seen in perspective,
    is inside the picture. ``axes`` (e.g. :func:`natural_axes`) turns the view table. ``lo..hi`` are
    voxel centres, widened by ``faces`` to the voxels' faces (0: a box already to the faces, in world
    units)."""
    if name not in _DIRECTIONS:
        raise ValueError(f"unknown view {name!r}; choose one of {', '.join(VIEWS)}")
    lo, hi = np.asarray(lo, np.float64) - faces, np.asarray(hi, np.float64) + faces
    centre = (lo + hi) / 2
    direction, up = (np.asarray(v, np.float64) for v in _DIRECTIONS[name])
    if axes is not None:
        direction, up = np.asarray(axes) @ direction, np.asarray(axes) @ up
    direction = direction / np.linalg.norm(direction)
    up = up - np.dot(up, direction) * direction
    up /= np.linalg.norm(up)
    right = np.cross(direction, up)
    tan_v = np.tan(np.radians(view_angle) / 2) / (1 + margin)
    tan_h = tan_v * aspect
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]) - centre
    toward = corners @ direction  # how much nearer the camera each corner is than the centre
    distance = max(1.0, float(np.max(np.maximum(np.abs(corners @ up) / tan_v, np.abs(corners @ right) / tan_h)
                                     + toward)))
    return Camera(tuple(centre + direction * distance), tuple(centre), tuple(up), float(view_angle))


def follow_cameras(name: str, boxes, aspect: float = 4 / 3, view_angle: float = 30.0, axes=None,
                   smooth: int = 9, base: Camera | None = None) -> list[Camera]:
    """One camera per frame from direction ``name`` that keeps the body in the middle (``--camera follow``).

    ``boxes``: per frame the body's world box ``(lo, hi)`` to the voxels' faces, or None (an empty frame:
    it keeps its neighbours' camera). The centres are smoothed by a moving average over ``smooth``
    frames (no jitter from a swinging arm; fewer in a clip under 16 x ``smooth`` frames); every
    camera stands at the one distance at which the largest box, around its smoothed centre, fits
    the picture -- so no frame leaves it. With ``base`` (the studio's view), each camera is ``base`` moved
    to the smoothed centre instead: the user's direction, distance and zoom.
    """
    known = [k for k, b in enumerate(boxes) if b is not None]
    if not known:
        raise ValueError("every frame is empty: there is no body to follow")
    centres = np.array([(np.asarray(b[0], np.float64) + np.asarray(b[1], np.float64)) / 2 for b in boxes
                        if b is not None])
    index = np.arange(len(boxes))
    track = np.stack([np.interp(index, known, centres[:, a]) for a in range(3)], axis=1)  # gaps: held / blended
    half_window = min(max(int(smooth), 1) // 2, len(boxes) // 16)  # a short clip is not smoothed flat
    padded = np.concatenate([track[:1].repeat(half_window, 0), track, track[-1:].repeat(half_window, 0)])
    kernel = np.ones(2 * half_window + 1) / (2 * half_window + 1)
    smoothed = np.stack([np.convolve(padded[:, a], kernel, mode="valid") for a in range(3)], axis=1)
    if base is not None:
        focal = np.asarray(base.focal_point, np.float64)
        return [Camera(tuple(np.asarray(base.position) + c - focal), tuple(c), base.view_up, base.view_angle,
                       base.parallel_scale) for c in smoothed]
    reach = np.zeros(3)
    for k in known:  # the box around each frame's smoothed centre that holds its body
        lo, hi = (np.asarray(v, np.float64) for v in boxes[k])
        reach = np.maximum(reach, np.maximum(hi - smoothed[k], smoothed[k] - lo))
    return [named_view(name, c - reach, c + reach, aspect=aspect, view_angle=view_angle, axes=axes, faces=0.0)
            for c in smoothed]


def union_box(boxes, lo, hi) -> tuple[tuple, tuple]:
    """The box holding every known, non-empty box of ``boxes`` (``(lo, hi)`` each); ``lo..hi`` (the grid)
    when there is none: a camera then frames the grid rather than nothing."""
    known = [b for b in boxes if b is not None]
    if not known:
        return tuple(lo), tuple(hi)
    return (tuple(int(v) for v in np.min([b[0] for b in known], 0)),
            tuple(int(v) for v in np.max([b[1] for b in known], 0)))
