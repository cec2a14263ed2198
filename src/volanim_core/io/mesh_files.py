"""Triangle meshes out: ``.ply``, ``.vtp``, ``.obj``, ``.stl`` (through pyvista, atomically)."""

from __future__ import annotations

import numpy as np


def write_mesh(path, vertices: np.ndarray, faces: np.ndarray) -> None:
    """Write a mesh as ``.ply``, ``.vtp``, ``.obj`` or ``.stl`` (atomically)."""
    from pathlib import Path

    import pyvista as pv

    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".ply", ".vtp", ".obj", ".stl"):
        raise ValueError(f"cannot write a mesh as {suffix!r}: use .ply, .vtp, .obj or .stl")
    from volanim_core.io._atomic import atomic_vtk_save

    cells = np.hstack([np.full((len(faces), 1), 3), faces]).ravel()
    atomic_vtk_save(path, pv.PolyData(np.asarray(vertices, np.float32), cells))
