"""Triangle meshes out: ``.ply``, ``.vtp``, ``.obj``, ``.stl`` (through pyvista, atomically)."""

from __future__ import annotations

import numpy as np

MESH_SUFFIXES = (".ply", ".vtp", ".obj", ".stl")
#: what read_mesh also reads: a glTF file's surface at rest (io/gltf_meshes.py); written as none of them
READ_MESH_SUFFIXES = MESH_SUFFIXES + (".glb", ".gltf")


def write_mesh(path, vertices: np.ndarray, faces: np.ndarray) -> None:
    """Write a mesh as ``.ply``, ``.vtp``, ``.obj`` or ``.stl`` (atomically)."""
    from pathlib import Path

    import pyvista as pv

    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in MESH_SUFFIXES:
        raise ValueError(f"cannot write a mesh as {suffix!r}: use .ply, .vtp, .obj or .stl")
    from volanim_core.io.atomic import atomic_vtk_save

    cells = np.hstack([np.full((len(faces), 1), 3), faces]).ravel()
    atomic_vtk_save(path, pv.PolyData(np.asarray(vertices, np.float32), cells))



def read_mesh(path):
    """A mesh file (``.ply``, ``.vtp``, ``.obj``, ``.stl``; or a glTF file's surface at rest, ``.glb``,
    ``.gltf``) as a pyvista PolyData; a file VTK cannot read, or one holding no triangles, raises FormatError
    naming it."""
    from pathlib import Path

    import pyvista as pv

    from volanim_core.errors import FormatError

    from .vtk_headers import check_mesh_claims

    path = Path(path)
    if path.suffix.lower() not in READ_MESH_SUFFIXES:
        raise ValueError(f"{path}: not a mesh file ({', '.join(READ_MESH_SUFFIXES)})")
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such file")
    if path.stat().st_size == 0:
        raise FormatError(path, "is empty")
    if path.suffix.lower() not in MESH_SUFFIXES:
        from .gltf_meshes import read_gltf_mesh

        vertices, faces = read_gltf_mesh(path)  # our reader: each accessor checked against its buffer
        # glTF splits a vertex wherever its normal or texture coordinate changes: merged, the surface closes
        return pv.PolyData(vertices, np.c_[np.full(len(faces), 3), faces].ravel()).clean(tolerance=1e-9)
    check_mesh_claims(path)  # VTK allocates whatever a header claims
    from .mesh_checks import check_ply, read_obj

    if path.suffix.lower() == ".obj":
        return read_obj(path)  # read here: VTK's reader crashed on indices a face does not have
    if path.suffix.lower() == ".ply":
        check_ply(path)  # every count and index, before VTK reads it
    try:
        mesh = pv.read(path)
    except Exception as exc:  # VTK raises many types (and pyvista wraps its error output)
        raise FormatError(path, f"VTK could not read it as a mesh: {exc}") from exc
    if not isinstance(mesh, pv.PolyData) or mesh.n_points == 0 or mesh.n_cells == 0:
        raise FormatError(path, "holds no mesh (no points or no faces)")
    from volanim_core.limits import MAX_MEASURE

    points = np.asarray(mesh.points)
    bad = ~(np.isfinite(points) & (np.abs(points) <= MAX_MEASURE)).all(axis=1)
    if bad.any():  # an infinite vertex overflowed the voxel grid; a NaN one voxelized to nothing
        k = int(np.argmax(bad))
        raise FormatError(path, f"vertex {k} is at {points[k].tolist()}: vertices must be finite numbers within "
                                f"{MAX_MEASURE:g}")
    return mesh



def _point(p) -> str:
    return "(" + ", ".join(f"{v:g}" for v in p) + ")"


def voxelize(mesh, *, spacing: float | None = None, size: int | None = None, padding: int = 2, value: int = 255):
    """A closed surface mesh as a binary volume with its geometry: ``(vol[x, y, z] uint8, Geometry)``.

    ``spacing``: the voxel size in the mesh's units; or ``size``: voxels along the mesh's longest side
    (default 128). ``padding`` empty voxels surround the body, so its skeleton's radii stay true at the
    edges. Through VTK's stencil (pyvista ``voxelize_binary_mask``): a voxel is inside when its centre is.
    A mesh with holes (open edges) has no inside and is refused.
    """
    import pyvista as pv

    from volanim_core.geometry import Geometry
    from volanim_core.limits import check_allocation

    surface = mesh.extract_surface().triangulate() if not isinstance(mesh, pv.PolyData) else mesh.triangulate()
    if surface.n_cells == 0:
        raise ValueError("the mesh has no faces: there is no surface to fill")
    lo, hi = np.asarray(surface.bounds, np.float64).reshape(3, 2).T
    extent = hi - lo
    if not (extent > 0).all():  # checked before the open edges: a mesh of one point "had 3 open edges"
        flat = "all at one point" if not extent.any() else "flat along " + " and ".join(
            a for a, e in zip("xyz", extent) if not e > 0)
        raise ValueError(f"the mesh has no volume: its {surface.n_points} points are {flat} "
                         f"(bounds {lo.tolist()} to {hi.tolist()}); there is no inside to fill")
    if surface.n_open_edges:
        rim = surface.extract_feature_edges(boundary_edges=True, feature_edges=False, manifold_edges=False,
                                            non_manifold_edges=False)
        edge = rim.points[rim.lines[1:3]]  # the first line cell: [2, a, b, ...]
        raise ValueError(f"the mesh is not closed ({surface.n_open_edges} open edges, one from "
                         f"{_point(edge[0])} to {_point(edge[1])}): it has no inside to fill; close its holes "
                         "first (e.g. pymeshfix, or Blender's 3D-Print toolbox)")
    if spacing is None:
        cells = max((size or 128) - 1 - 2 * padding, 1)
        spacing = float(extent.max()) / cells
    if not spacing > 0:
        raise ValueError(f"the voxel size must be above 0, got {spacing!r}")
    dims = np.ceil(extent / spacing).astype(int) + 1 + 2 * padding
    check_allocation(dims, 1, "the voxelized grid", "choose a larger --spacing or a smaller --size")
    origin = lo - padding * spacing
    reference = pv.ImageData(dimensions=tuple(int(n) for n in dims), spacing=(spacing,) * 3, origin=tuple(origin))
    image = surface.voxelize_binary_mask(reference_volume=reference, foreground_value=value)
    vol = np.asarray(image.point_data["mask"]).reshape(tuple(dims), order="F").astype(np.uint8)
    return np.asfortranarray(vol), Geometry((spacing,) * 3, tuple(origin))
