"""The picture oracle: what a camera must see of a volume, computed with NumPy alone (no VTK).

    filled voxels --exposed faces, sampled--> world points --look-at + projection (ours)--> pixels
        --> silhouette (H, W) and the share of the body outside the picture
    rendered picture --differs from the background--> foreground (H, W)
    compare(foreground, silhouette) --> IoU, IoU off the silhouette's 1-pixel rim, stray and missing pixels

A volume drawn by VTK's surface style is the 0.5 isosurface of its filled voxels
(point data at voxel centres), which runs through the faces of the voxels' cubes;
a ray cast reaches the same faces. So the silhouette is that of the union of the
voxels' cubes, and the union's projection is the projection of its exposed faces
(any line of sight through the body enters it through one). Each exposed face is
sampled finely enough that neighbouring samples land less than half a pixel apart.

The camera is read the way VTK documents it -- ``view_angle`` the full vertical
angle, ``parallel_scale`` half the picture's height, view-up made orthogonal to
the line of sight -- and implemented here independently of ``vtkCamera``.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

FACES = [(axis, side) for axis in range(3) for side in (-1, 1)]


def view_frame(camera):
    """``(eye, right, up, forward)`` unit vectors of a camera (anything with position, focal_point, view_up)."""
    eye = np.asarray(camera.position, np.float64)
    forward = np.asarray(camera.focal_point, np.float64) - eye
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, np.asarray(camera.view_up, np.float64))
    right /= np.linalg.norm(right)
    return eye, right, np.cross(right, forward), forward


def to_pixels(world: np.ndarray, camera, size) -> tuple[np.ndarray, np.ndarray]:
    """``(N, 2)`` picture coordinates (column, row from the top; pixel k spans k..k+1) and whether each
    point is in front of the camera."""
    w, h = size
    eye, right, up, forward = view_frame(camera)
    rel = np.asarray(world, np.float64) - eye
    x, y, z = rel @ right, rel @ up, rel @ forward
    if getattr(camera, "parallel_scale", None):
        half_h = np.full(len(rel), float(camera.parallel_scale))
    else:
        half_h = np.tan(np.radians(camera.view_angle) / 2) * np.maximum(z, 1e-9)
    ndc_x, ndc_y = x / (half_h * w / h), y / half_h
    return np.stack([(ndc_x + 1) / 2 * w, (1 - ndc_y) / 2 * h], axis=1), z > 0


def _pixels_per_world(world: np.ndarray, camera, size) -> float:
    """The largest size on the picture, in pixels, of one world unit at any of ``world``'s points."""
    _, h = size
    eye, _, _, forward = view_frame(camera)
    if getattr(camera, "parallel_scale", None):
        return h / (2 * float(camera.parallel_scale))
    z = (np.asarray(world, np.float64) - eye) @ forward
    nearest = max(float(z[z > 0].min()) if np.any(z > 0) else 1.0, 1e-6)
    return h / (2 * np.tan(np.radians(camera.view_angle) / 2) * nearest)


def silhouette(mask: np.ndarray, origin, spacing, camera, size, chunk: int = 2_000_000):
    """What of ``mask`` (``[x, y, z]`` bool; voxel i at ``origin + i * spacing`` in the camera's world) the
    camera sees: ``(H, W)`` bool, and the share of the body's face samples that fall outside the picture."""
    w, h = size
    origin, spacing = np.asarray(origin, np.float64), np.asarray(spacing, np.float64) * np.ones(3)
    out = np.zeros((h, w), bool)
    m = np.pad(np.asarray(mask, bool), 1)
    exposed = []
    for axis, side in FACES:  # filled voxels whose neighbour on this side is empty
        nb = np.roll(m, -side, axis=axis)
        faces = np.argwhere(m & ~nb) - 1
        if len(faces):
            exposed.append((axis, side, faces))
    if not exposed:
        return out, 0.0
    centres = np.concatenate([f for _, _, f in exposed]) * spacing + origin
    step_px = float(np.max(spacing)) * _pixels_per_world(centres, camera, size)
    n = int(np.clip(np.ceil(step_px / 0.5) + 1, 2, 64))  # samples per face edge: < half a pixel apart
    grid = np.linspace(-0.5, 0.5, n)
    total = outside = 0
    for axis, side, faces in exposed:
        a, b = (k for k in range(3) if k != axis)
        offsets = np.zeros((n * n, 3))
        offsets[:, axis] = 0.5 * side
        offsets[:, a] = np.repeat(grid, n)
        offsets[:, b] = np.tile(grid, n)
        per = max(1, chunk // len(offsets))
        for s in range(0, len(faces), per):
            pts = ((faces[s:s + per, None, :] + offsets[None]) * spacing + origin).reshape(-1, 3)
            xy, ahead = to_pixels(pts, camera, size)
            col, row = np.floor(xy[:, 0]).astype(np.int64), np.floor(xy[:, 1]).astype(np.int64)
            inside = ahead & (col >= 0) & (col < w) & (row >= 0) & (row < h)
            out[row[inside], col[inside]] = True
            total += len(pts)
            outside += int(np.count_nonzero(~inside))
    return out, outside / max(total, 1)


def foreground(image: np.ndarray, background=(0, 0, 0), tolerance: int = 12) -> np.ndarray:
    """``(H, W)`` bool: the pixels of an RGB picture that differ from the background by more than ``tolerance``."""
    diff = np.abs(np.asarray(image, np.int16)[..., :3] - np.asarray(background, np.int16)[None, None, :3])
    return diff.max(axis=2) > tolerance


def compare(fg: np.ndarray, sil: np.ndarray, rim: int = 1) -> dict:
    """How well a picture's foreground matches the silhouette.

    ``iou``: plain; ``iou_rim``: leaving out the pixels within ``rim`` of the silhouette's edge (where
    anti-aliasing and the samples' half pixel decide); ``stray``: the share of the foreground further
    than 2 pixels from the silhouette (a picture of nothing there); ``missing``: the share of the
    silhouette's core not drawn."""
    fg, sil = np.asarray(fg, bool), np.asarray(sil, bool)
    edge = ndimage.binary_dilation(sil, iterations=rim) & ~ndimage.binary_erosion(sil, iterations=rim)
    keep = ~edge
    inter, union = np.count_nonzero(fg & sil), np.count_nonzero(fg | sil)
    inter_r, union_r = np.count_nonzero(fg & sil & keep), np.count_nonzero((fg | sil) & keep)
    near = ndimage.binary_dilation(sil, iterations=2)
    core = sil & keep
    return {
        "iou": inter / union if union else 1.0,
        "iou_rim": inter_r / union_r if union_r else 1.0,
        "stray": np.count_nonzero(fg & ~near) / max(np.count_nonzero(fg), 1),
        "missing": np.count_nonzero(core & ~fg) / max(np.count_nonzero(core), 1),
        "silhouette_px": int(np.count_nonzero(sil)),
        "foreground_px": int(np.count_nonzero(fg)),
    }


def mask_region(fg: np.ndarray, boxes) -> np.ndarray:
    """``fg`` with rectangles ``(row0, row1, col0, col1)`` (text, a colour bar, the axes widget) cleared."""
    out = fg.copy()
    for r0, r1, c0, c1 in boxes:
        out[r0:r1, c0:c1] = False
    return out
