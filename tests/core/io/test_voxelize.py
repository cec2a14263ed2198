"""Meshes into volumes (#35): a closed surface filled, with its geometry, against the shape it is."""

from __future__ import annotations

import numpy as np
import pytest
import pyvista as pv
from pyvista import examples

from volanim_core import io
from volanim_core.cli import main
from volanim_core.errors import FormatError
from volanim_core.io.mesh_files import voxelize


def test_a_sphere_fills_the_voxels_whose_centres_are_inside():
    """Against the ball itself: each voxel centre's distance from the centre, independently of VTK."""
    R, centre = 10.0, np.array([3.0, -2.0, 5.0])
    mesh = pv.Sphere(radius=R, center=centre, theta_resolution=180, phi_resolution=180)
    vol, g = voxelize(mesh, spacing=0.5)
    assert g.spacing == (0.5, 0.5, 0.5)
    d = np.linalg.norm(g.to_physical(np.argwhere(np.ones(vol.shape, bool))) - centre, axis=1).reshape(vol.shape)
    clear = np.abs(d - R) > 0.05  # the tessellated sphere is within 0.01 of R; leave the boundary shell
    assert np.array_equal(vol[clear] > 0, d[clear] < R)
    assert (vol[:2] == 0).all() and (vol[-2:] == 0).all()  # padding all round


def test_an_open_mesh_and_a_flat_one_are_refused():
    with pytest.raises(ValueError, match=r"no volume: its \d+ points are flat along z"):
        voxelize(pv.Plane())  # checked before its open edges (#89)
    with pytest.raises(ValueError, match=r"not closed \(\d+ open edges, one from \("):
        voxelize(pv.Sphere().remove_cells([0]))  # names where one of them is
    with pytest.raises(ValueError, match="no faces"):
        voxelize(pv.PolyData(np.random.default_rng(0).random((5, 3))))


def test_the_ant_from_pyvistas_wheel_voxelizes_and_skeletonizes(tmp_path, capsys):
    assert main(["voxelize", examples.antfile, str(tmp_path / "ant.nrrd"), "--size", "96"]) == 0
    scan = io.read_scan(tmp_path / "ant.nrrd")
    assert max(scan.data.shape) == 96 and scan.geometry.is_isotropic and scan.data.max() == 255
    lo = np.asarray(pv.read(examples.antfile).bounds).reshape(3, 2)[:, 0]
    assert np.allclose(scan.geometry.origin, lo - 2 * scan.geometry.spacing[0])  # placed where the mesh is
    assert main(["skeletonize", str(tmp_path / "ant.nrrd"), "-o", str(tmp_path / "ant.mskel")]) == 0
    assert io.read_mskel(tmp_path / "ant.mskel").geometry == scan.geometry


def test_a_mesh_given_as_a_volume_says_how_to_fill_it(tmp_path):
    with pytest.raises(FormatError, match="volanim voxelize ant.ply ant.nrrd"):
        io.read_scan(examples.antfile)


def test_the_studio_opens_a_mesh_filled():
    from volanim_studio import tasks

    loaded = tasks.load_volume_file(examples.antfile)
    assert loaded["volume"].max() == 255 and max(loaded["volume"].shape) == 128
    assert loaded["geometry"].is_isotropic
