"""The hull: an isosurface of the mask, in the volume's voxel frame.

    mask --crop to tight bounds, pad 1--> box --marching cubes--> (vertices, faces)
         --shift by the box origin--> voxel coordinates [x, y, z]

Two engines, same contract:

* ``engine="vtk"`` (default): VTK's flying edges through pyvista. Measured on
  the frog (``benchmarks/bench_skeleton.py``) it is ~5x faster than
  scikit-image at step 1, so it is what the studio and CLI use.
* ``engine="skimage"``: scikit-image's ``marching_cubes`` (Lewiner), pure
  NumPy/Cython and VTK-free, used when VTK is unavailable and for ``step > 1``
  (a coarser, faster preview mesh).

The one-voxel zero pad closes the surface where the object touches the
volume's border, which is right because outside counts as background.

:func:`display_hull` is the hull the studio draws: the same surface, made
from the mask averaged over f^3 blocks when the full one has too many
triangles for software OpenGL to draw translucent at interactive rates.
"""

from __future__ import annotations

import numpy as np

from volanim_core.volume import Bounds, crop, tight_bounds


def _padded_box(mask) -> tuple[np.ndarray, np.ndarray]:
    mask = np.asarray(mask)
    if mask.ndim != 3:
        raise ValueError(f"mask must be 3-D, got shape {mask.shape}")
    m = mask != 0
    b = tight_bounds(m)
    if b is None:
        raise ValueError("the mask is empty: there is no surface")
    lo = np.array(b.lo) - 1
    box = crop(m.view(np.uint8), Bounds(tuple(lo), tuple(np.array(b.hi) + 1)))
    return box, lo


def isosurface(mask, *, step: int = 1, engine: str = "vtk") -> tuple[np.ndarray, np.ndarray]:
    """Triangle mesh of the boundary of ``mask`` (level 0.5 between 0 and 1).

    Parameters
    ----------
    mask : (X, Y, Z) ndarray, non-zero = object
    step : int
        Sampling step (skimage only); 1 is full resolution.
    engine : {'vtk', 'skimage'}

    Returns
    -------
    vertices : (V, 3) float32 ndarray, voxel coordinates ``x, y, z``
    faces : (F, 3) int64 ndarray of vertex indices
    """
    if step < 1:
        raise ValueError(f"step must be >= 1, got {step}")
    if engine not in ("vtk", "skimage"):
        raise ValueError(f"engine must be 'vtk' or 'skimage', got {engine!r}")
    box, lo = _padded_box(mask)
    if engine == "skimage" or step > 1:
        from skimage.measure import marching_cubes

        verts, faces, _, _ = marching_cubes(box, 0.5, step_size=step, allow_degenerate=False)
        return (verts + lo).astype(np.float32), faces.astype(np.int64)
    from volanim_core.isosurface import flying_edges

    return flying_edges(box, origin=lo)


#: Triangles the studio draws for the translucent hull: llvmpipe spends ~140 ms a frame on the
#: frog's full 1.5 M and ~50 ms on 250 k (bench_studio.py); the hull is context, not data.
DISPLAY_FACES = 250_000
#: ... and while the thinness slider is held, with the points' level of detail: the frog's hull
#: at 107 k triangles costs ~30 ms of a 1200x800 frame, at 19 k ~8 ms.
LOD_FACES = 30_000


def display_hull(mask, max_faces: int = DISPLAY_FACES, surface=None) -> tuple[np.ndarray, np.ndarray]:
    """The hull to draw: :func:`isosurface`, or -- when that has more than ``max_faces``
    triangles -- the 0.5 isosurface of the mask averaged over ``f^3`` blocks, with the
    smallest ``f`` that fits (triangles fall as ``1/f^2``). Same voxel frame; the
    surface stays where the object's boundary is, only coarser. ``surface``: the mask's
    :func:`isosurface`, when the caller has it already."""
    verts, faces = isosurface(mask) if surface is None else surface
    f = max(2, int(np.ceil(np.sqrt(len(faces) / max_faces))))
    while len(faces) > max_faces:
        verts, faces = _block_isosurface(mask, f)
        f += 1
    return verts, faces


def vertex_normals(vertices, faces) -> np.ndarray:
    """Each vertex's unit normal (float32, (V, 3)): the mean of its triangles' unit normals (as VTK's
    vtkPolyDataNormals makes them), oriented by the faces' winding (zero for a vertex no face uses). Made
    with the hull, off the GUI thread: VTK's smooth shading made them as the actor was added (70 ms of
    mannequin-large's open)."""
    v = np.asarray(vertices, np.float64)
    f = np.asarray(faces, np.intp)
    a = v[f[:, 0]]
    n = np.cross(v[f[:, 1]] - a, v[f[:, 2]] - a)
    area = np.linalg.norm(n, axis=1, keepdims=True)
    n /= np.where(area > 0, area, 1.0)  # each face counts once, whatever its size
    flat = f.ravel()
    out = np.empty((len(v), 3), np.float64)
    for k in range(3):
        out[:, k] = np.bincount(flat, weights=np.repeat(n[:, k], 3), minlength=len(v))
    length = np.linalg.norm(out, axis=1, keepdims=True)
    return (out / np.where(length > 0, length, 1.0)).astype(np.float32)


def display_hulls(mask) -> tuple[tuple[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray] | None]:
    """The studio's hull (:func:`display_hull`) and its level of detail for frames drawn while a
    slider is held (at most ``LOD_FACES`` triangles; None when the hull has no more), from one
    isosurface of the mask."""
    surface = isosurface(mask)
    hull = display_hull(mask, DISPLAY_FACES, surface)
    lod = display_hull(mask, LOD_FACES, surface) if len(hull[1]) > LOD_FACES else None
    return hull, lod


def _block_isosurface(mask, f: int) -> tuple[np.ndarray, np.ndarray]:
    from volanim_core.isosurface import flying_edges

    box, lo = _padded_box(mask)
    # pad to whole blocks, with a block of background all round so the coarse surface is closed
    pad = [(f, f + (-n) % f) for n in box.shape]
    box = np.pad(box, pad)
    nx, ny, nz = (n // f for n in box.shape)
    mean = box.reshape(nx, f, ny, f, nz, f).mean(axis=(1, 3, 5), dtype=np.float32)
    origin = lo - f + (f - 1) / 2.0  # block b's centre is voxel lo - f + b f + (f - 1) / 2
    return flying_edges(mean, origin=origin, spacing=float(f))
