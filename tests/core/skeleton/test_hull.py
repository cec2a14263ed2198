"""Isosurface hull: coordinates in the volume's voxel frame, both engines agree."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core.io.mesh_files import write_mesh
from volanim_core.skeleton.hull import display_hull, isosurface


@pytest.fixture
def cube():
    m = np.zeros((20, 18, 16), bool)
    m[5:12, 4:10, 3:8] = True
    return m


@pytest.mark.parametrize("engine", ["vtk", "skimage"])
def test_surface_in_voxel_frame(cube, engine):
    v, f = isosurface(cube, engine=engine)
    assert np.allclose(v.min(0), [4.5, 3.5, 2.5]) and np.allclose(v.max(0), [11.5, 9.5, 7.5])
    assert f.shape[1] == 3 and f.max() < len(v)


def test_border_touching_object_is_closed():
    import pyvista as pv

    m = np.ones((6, 6, 6), bool)
    v, f = isosurface(m)
    mesh = pv.PolyData(v, np.hstack([np.full((len(f), 1), 3), f]).ravel())
    assert mesh.is_manifold and np.allclose(v.min(0), -0.5)


def test_errors_and_writer(tmp_path, cube):
    with pytest.raises(ValueError, match="empty"):
        isosurface(np.zeros((3, 3, 3)))
    with pytest.raises(ValueError, match="engine"):
        isosurface(cube, engine="gpu")
    v, f = isosurface(cube, step=2)
    write_mesh(tmp_path / "c.obj", v, f)
    assert (tmp_path / "c.obj").stat().st_size > 0
    with pytest.raises(ValueError, match=".ply"):
        write_mesh(tmp_path / "c.xyz", v, f)


def test_display_hull_is_the_hull_until_it_is_too_large():
    """The studio draws a coarser surface in the same place once the full one has too many triangles."""
    import pyvista as pv

    g = np.indices((60, 50, 40)) - np.array([30, 25, 20])[:, None, None, None]
    ball = (g**2).sum(0) < 17.3**2
    ball[:, :, :3] = True  # touches the border: still closed
    full = isosurface(ball)
    same = display_hull(ball, max_faces=len(full[1]))
    assert np.array_equal(same[0], full[0]) and np.array_equal(same[1], full[1])
    v, f = display_hull(ball, max_faces=len(full[1]) // 5)
    assert 0 < len(f) <= len(full[1]) // 5
    mesh = pv.PolyData(v, np.hstack([np.full((len(f), 1), 3), f]).ravel())
    assert mesh.is_manifold
    r = np.linalg.norm(v - [30, 25, 20], axis=1)
    inner = v[:, 2] > 6  # the ball's part away from the slab
    assert np.abs(r[inner] - 17.3).max() < 1.5  # same place, within the block size
    assert np.allclose(v.min(0), full[0].min(0), atol=1.5) and np.allclose(v.max(0), full[0].max(0), atol=1.5)


def test_display_hulls_give_a_level_of_detail_only_for_a_heavy_hull():
    from volanim_core.skeleton import hull

    g = np.indices((60, 50, 40)) - np.array([30, 25, 20])[:, None, None, None]
    ball = (g**2).sum(0) < 17.3**2
    (v, f), lod = hull.display_hulls(ball)
    assert len(f) < hull.LOD_FACES and lod is None  # ~14 k triangles: light enough to drag with
    big = np.kron(ball, np.ones((2, 2, 2), bool))  # 4x the triangles
    (v, f), lod = hull.display_hulls(big)
    assert len(f) == len(isosurface(big)[1]) > hull.LOD_FACES
    assert lod is not None and 0 < len(lod[1]) <= hull.LOD_FACES
    assert np.allclose(lod[0].min(0), v.min(0), atol=3.0) and np.allclose(lod[0].max(0), v.max(0), atol=3.0)


def test_vertex_normals_are_vtk_s_and_point_out_of_the_body():
    """The hull's normals (made off the GUI thread) against VTK's vtkPolyDataNormals, what smooth shading
    made when the actor was added; and outward on a ball (the faces' winding)."""
    import pyvista as pv

    from volanim_core.skeleton.hull import vertex_normals

    r = np.linalg.norm(np.indices((31, 31, 31)) - 15.0, axis=0)
    v, f = isosurface(r <= 11)
    n = vertex_normals(v, f)
    assert n.dtype == np.float32 and n.shape == v.shape
    assert np.allclose(np.linalg.norm(n, axis=1), 1, atol=1e-5)
    theirs = pv.PolyData.from_regular_faces(v, f).compute_normals(
        cell_normals=False, split_vertices=False, consistent_normals=False, auto_orient_normals=False)
    dot = (np.asarray(theirs.point_data["Normals"]) * n).sum(axis=1)
    assert np.percentile(dot, 1) > 0.99 and dot.min() > 0.9
    radial = (v - 15.0) / np.linalg.norm(v - 15.0, axis=1, keepdims=True)
    assert (radial * n).sum(axis=1).min() > 0.5  # out of the ball (a voxel corner's normal leans)


def test_a_vertex_no_face_uses_has_no_normal():
    from volanim_core.skeleton.hull import vertex_normals

    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 5, 5]], np.float32)
    n = vertex_normals(v, np.array([[0, 1, 2]]))
    assert np.allclose(n[:3], [0, 0, 1]) and np.allclose(n[3], 0)
