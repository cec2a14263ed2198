"""Isosurface hull: coordinates in the volume's voxel frame, both engines agree."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core.io.mesh_files import write_mesh
from volanim_core.skeleton.hull import isosurface


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
