"""Meshes nobody here wrote: the PLY files pyvista's wheel ships, read through volanim's checks and
compared with VTK's own reader; the same surfaces written as OBJ by VTK, read by volanim's OBJ reader (#38)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import pyvista as pv

from volanim_core.io.mesh_files import read_mesh

SHIPPED = sorted((Path(pv.__file__).parent / "examples").glob("*.ply"))


def test_pyvista_ships_the_meshes():
    assert {p.name for p in SHIPPED} >= {"ant.ply", "airplane.ply", "nut.ply", "sphere.ply"}


@pytest.mark.parametrize("path", SHIPPED, ids=[p.name for p in SHIPPED])
def test_a_shipped_ply_reads_as_vtk_reads_it_and_its_obj_as_vtk_reads_that(path, tmp_path):
    vtk = pv.read(path)
    ours = read_mesh(path)
    assert (ours.n_points, ours.n_cells) == (vtk.n_points, vtk.n_cells)
    assert np.allclose(ours.points, vtk.points) and np.array_equal(ours.faces, vtk.faces)
    obj = tmp_path / (path.stem + ".obj")
    vtk.triangulate().save(obj)  # VTK's OBJ writer
    assert np.allclose(read_mesh(obj).points, pv.read(obj).points)
    assert np.array_equal(read_mesh(obj).faces, pv.read(obj).faces)
