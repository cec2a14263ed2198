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


MESH_SUFFIXES = (".ply", ".vtp", ".obj", ".stl")


def read_mesh(path):
    """A mesh file (``.ply``, ``.vtp``, ``.obj``, ``.stl``) as a pyvista PolyData; a file VTK cannot
    read, or one holding no triangles, raises FormatError naming it."""
    from pathlib import Path

    import pyvista as pv

    from volanim_core.errors import FormatError

    path = Path(path)
    if path.suffix.lower() not in MESH_SUFFIXES:
        raise ValueError(f"{path}: not a mesh file ({', '.join(MESH_SUFFIXES)})")
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such file")
    if path.stat().st_size == 0:
        raise FormatError(path, "is empty")
    check_mesh_claims(path)
    try:
        mesh = pv.read(path)
    except Exception as exc:  # VTK raises many types (and pyvista wraps its error output)
        raise FormatError(path, f"VTK could not read it as a mesh: {exc}") from exc
    if not isinstance(mesh, pv.PolyData) or mesh.n_points == 0 or mesh.n_cells == 0:
        raise FormatError(path, "holds no mesh (no points or no faces)")
    return mesh


#: A mesh element takes at least a byte in any of these formats; compressed .vtp data may inflate,
#: so its counts get this much room over the file's size (and must still fit in memory).
_VTP_INFLATION = 1024


def check_mesh_claims(path) -> None:
    """Refuse counts a mesh file's header claims but cannot hold, before VTK allocates for them
    (a PLY claiming 2^31 vertices made VTK abort the process)."""
    import re
    from pathlib import Path

    from volanim_core.errors import FormatError
    from volanim_core.limits import available_bytes, human_bytes

    path = Path(path)
    size = path.stat().st_size
    with open(path, "rb") as fh:
        head = fh.read(1 << 16)
    suffix = path.suffix.lower()
    claims: list[tuple[str, int, int]] = []  # (what, count, the most the file can hold)
    if suffix == ".ply":
        if not head.startswith(b"ply"):
            raise FormatError(path, "is not a PLY file (it must start with 'ply')")
        end = head.find(b"end_header")
        if end < 0:
            raise FormatError(path, "has no end_header in its first 64 KB")
        for m in re.finditer(rb"^element\s+(\S+)\s+(\d+)", head[:end], flags=re.M):
            claims.append((f"{m[1].decode('ascii', 'replace')} elements", int(m[2]), size))
    elif suffix == ".stl" and not head.lstrip().startswith(b"solid"):
        if size < 84:
            raise FormatError(path, f"is {size} bytes: too short for a binary STL (84 bytes of header)")
        count = int.from_bytes(head[80:84], "little")
        if 84 + 50 * count != size:
            raise FormatError(path, f"claims {count} triangles ({84 + 50 * count} bytes) but has {size} bytes")
    elif suffix == ".vtp":
        for m in re.finditer(rb'NumberOf(Points|Verts|Lines|Strips|Polys)="(\d+)"', head):
            claims.append((m[1].decode().lower(), int(m[2]), size * _VTP_INFLATION))
    free = available_bytes()
    for what, count, most in claims:
        if count > most:
            raise FormatError(path, f"claims {count} {what}, more than its {size} bytes can hold")
        if free is not None and 24 * count > free:
            raise FormatError(path, f"claims {count} {what} ({human_bytes(24 * count)}), more than the memory free")
