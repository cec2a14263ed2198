"""One slice of a volume as a picture: the thesis's View.tcl, for ``volanim view --slices`` and the studio.

    volume[x, y, z] (grey, or [x, y, z, 3] colour) --axis, index--> the plane
        --window lo..hi (grey) --> uint8 --rows flipped--> picture (H, W, 3), row 0 at the top

Every slice is seen the way the named views see the body, so a slice matches
a render: a z slice from above (x to the right, y up), a y slice from the
front (x right, z up), an x slice from the side (y right, z up). One picture
pixel is one voxel; :func:`pixel_aspect` says how tall a pixel is against its
width, for voxels that are not cubes.
"""

from __future__ import annotations

import numpy as np

AXES = "xyz"


def parse_slice_axis(text: str) -> int:
    """``x``, ``y`` or ``z`` -> 0, 1, 2 (the axis a slice is across)."""
    t = str(text).strip().lower()
    if t not in ("x", "y", "z"):  # not `in AXES`: "xy" is a substring of "xyz"
        raise ValueError(f"a slice is across x, y or z, got {text!r}")
    return AXES.index(t)


def default_window(volume: np.ndarray) -> tuple[float, float]:
    """The grey range a volume's slices share: its smallest and largest finite values (0..1 when flat),
    fixed for every slice so a brighter slice looks brighter."""
    finite = volume[np.isfinite(volume)] if volume.dtype.kind == "f" else volume
    if finite.size == 0:
        return 0.0, 1.0
    lo, hi = float(finite.min()), float(finite.max())
    return (lo, hi) if hi > lo else (lo, lo + 1.0)


def describe(volume: np.ndarray, grey: tuple[float, float] | None) -> str:
    """``228x142x120 voxels, grey -1000..900`` (or ``, RGB``): what a slice viewer shows, in a line."""
    shape = "x".join(str(v) for v in volume.shape[:3])
    return f"{shape} voxels" + (f", grey {grey[0]:g}..{grey[1]:g}" if grey is not None else ", RGB")


def slice_picture(volume: np.ndarray, axis: int, index: int, window: tuple[float, float] | None = None
                  ) -> np.ndarray:
    """``(H, W, 3)`` uint8: slice ``index`` across ``axis`` (0, 1, 2 = x, y, z), row 0 at the top.
    Grey values map ``window`` (default :func:`default_window`) onto black..white; colour is shown as it is."""
    n = volume.shape[axis]
    if not 0 <= index < n:
        raise ValueError(f"slice {index} is outside the volume: {AXES[axis]} runs 0..{n - 1}")
    plane = np.take(volume, index, axis=axis)  # (u, v[, 3]): the two other axes, in order
    if volume.ndim == 3:
        lo, hi = window if window is not None else default_window(volume)
        if not hi > lo:
            raise ValueError(f"a grey window needs LO < HI, got {lo:g}..{hi:g}")
        scaled = (np.nan_to_num(plane.astype(np.float64), nan=lo) - lo) / (hi - lo)
        grey = np.round(np.clip(scaled, 0.0, 1.0) * 255).astype(np.uint8)
        plane = np.repeat(grey[..., None], 3, axis=2)
    # u to the right, v up: columns are u, rows v from the top down
    return np.ascontiguousarray(plane.transpose(1, 0, 2)[::-1]).astype(np.uint8, copy=False)


def pixel_aspect(spacing, axis: int) -> float:
    """How tall a slice's pixel is for its width (the voxel's v spacing over its u spacing)."""
    u, v = [a for a in range(3) if a != axis]
    return float(spacing[v]) / float(spacing[u])


def voxel_at(shape, axis: int, index: int, column: int, row: int) -> tuple[int, int, int]:
    """The ``(x, y, z)`` voxel under a picture's pixel (column, row from the top) of slice ``index``."""
    u, v = [a for a in range(3) if a != axis]
    at = [0, 0, 0]
    at[axis], at[u], at[v] = index, column, shape[v] - 1 - row
    return tuple(at)


def tinted(picture: np.ndarray, labels: np.ndarray, axis: int, index: int, table: np.ndarray,
           share: float = 0.55) -> np.ndarray:
    """``picture`` (:func:`slice_picture` of the same slice) with each voxel of label l > 0 in ``labels`` (the
    volume's shape, ``[x, y, z]``) blended ``share`` of the way to ``table[l]`` (``(L, 3)`` uint8): which bone owns
    each voxel, over the scan's own grey (the studio's *Show ownership on slices*)."""
    plane = np.take(labels, index, axis=axis).T[::-1]  # as slice_picture lays the slice out
    out = picture.astype(np.float32)
    on = plane > 0
    out[on] = (1.0 - share) * out[on] + share * table[plane[on]].astype(np.float32)
    return np.round(out).astype(np.uint8)
