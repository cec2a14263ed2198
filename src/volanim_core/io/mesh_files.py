"""Triangle meshes out: ``.ply``, ``.vtp``, ``.obj``, ``.stl`` (through pyvista, atomically)."""

from __future__ import annotations

import numpy as np

MESH_SUFFIXES = (".ply", ".vtp", ".obj", ".stl")


def write_mesh(path, vertices: np.ndarray, faces: np.ndarray) -> None:
    """Write a mesh as ``.ply``, ``.vtp``, ``.obj`` or ``.stl`` (atomically)."""
    from pathlib import Path

    import pyvista as pv

    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in MESH_SUFFIXES:
        raise ValueError(f"cannot write a mesh as {suffix!r}: use .ply, .vtp, .obj or .stl")
    from volanim_core.io._atomic import atomic_vtk_save

    cells = np.hstack([np.full((len(faces), 1), 3), faces]).ravel()
    atomic_vtk_save(path, pv.PolyData(np.asarray(vertices, np.float32), cells))



def read_mesh(path):
    """A mesh file (``.ply``, ``.vtp``, ``.obj``, ``.stl``) as a pyvista PolyData; a file VTK cannot
    read, or one holding no triangles, raises FormatError naming it."""
    from pathlib import Path

    import pyvista as pv

    from volanim_core.errors import FormatError

    from .vtk_headers import check_mesh_claims

    path = Path(path)
    if path.suffix.lower() not in MESH_SUFFIXES:
        raise ValueError(f"{path}: not a mesh file ({', '.join(MESH_SUFFIXES)})")
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such file")
    if path.stat().st_size == 0:
        raise FormatError(path, "is empty")
    check_mesh_claims(path)  # VTK allocates whatever a header claims
    try:
        mesh = pv.read(path)
    except Exception as exc:  # VTK raises many types (and pyvista wraps its error output)
        raise FormatError(path, f"VTK could not read it as a mesh: {exc}") from exc
    if not isinstance(mesh, pv.PolyData) or mesh.n_points == 0 or mesh.n_cells == 0:
        raise FormatError(path, "holds no mesh (no points or no faces)")
    return mesh

