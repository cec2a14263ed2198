"""Geometry: index <-> physical maps, the grids tools derive, and the ``# geometry:`` header line."""

from __future__ import annotations

import numpy as np
import pytest
import SimpleITK as sitk

from volanim_core import io
from volanim_core.errors import FormatError
from volanim_core.geometry import IDENTITY, Geometry, axis_codes
from volanim_core.skeleton.points import Skeleton

TILTED = Geometry((0.7, 0.8, 2.5), (-40, -25, -900), (0, 1, 0, -1, 0, 0, 0, 0, 1))


def test_index_to_physical_is_simpleitks():
    image = sitk.Image(4, 5, 6, sitk.sitkUInt8)
    image.SetSpacing(TILTED.spacing)
    image.SetOrigin(TILTED.origin)
    image.SetDirection(TILTED.direction)
    idx = np.array([[0, 0, 0], [3, 4, 5], [1, 2, 3]])
    theirs = [image.TransformContinuousIndexToPhysicalPoint([float(v) for v in i]) for i in idx]
    assert np.allclose(TILTED.to_physical(idx), theirs)
    assert np.allclose(TILTED.to_index(theirs), idx)


def test_derived_grids_keep_every_voxel_in_place():
    idx = np.array([[2, 3, 4], [0, 0, 0], [5, 1, 2]])
    shifted = TILTED.shifted((2, 3, 4))
    assert np.allclose(shifted.to_physical(idx - [2, 3, 4]), TILTED.to_physical(idx))
    flipped = TILTED.flipped(1, 6)  # y reversed on a grid 6 voxels deep
    mirrored = idx.copy()
    mirrored[:, 1] = 5 - idx[:, 1]
    assert np.allclose(flipped.to_physical(mirrored), TILTED.to_physical(idx))
    m = TILTED.index_map(shifted)  # row-vector, like the bone matrices
    assert np.allclose(np.c_[idx, np.ones(3)] @ m, np.c_[idx - [2, 3, 4], np.ones(3)])


def test_affine_round_trip_and_axis_codes():
    assert np.allclose(Geometry.from_affine(TILTED.affine).affine, TILTED.affine)
    assert axis_codes(IDENTITY.matrix) == "LPS"
    assert axis_codes(np.diag([-1, -1, 1])) == "RAS"


@pytest.mark.parametrize("bad", [dict(spacing=(1, 0, 1)), dict(origin=(0, np.nan, 0)),
                                 dict(direction=(1, 0, 0, 0.5, 1, 0, 0, 0, 1)), dict(direction=(1, 0, 0))])
def test_a_bad_geometry_is_refused(bad):
    with pytest.raises(ValueError):
        Geometry(**bad)


# spec: docs/formats.md#physical-space
def test_the_header_line_round_trips_and_old_files_have_none(tmp_path):
    skel = Skeleton([[1, 2, 3]], [1.5], [0.7], "euclid", TILTED)
    io.write_mskel(tmp_path / "a.mskel", skel)
    text = (tmp_path / "a.mskel").read_text()
    assert "# geometry: spacing 0.7 0.8 2.5 origin -40 -25 -900 direction 0 1 0 -1 0 0 0 0 1" in text
    assert io.read_mskel(tmp_path / "a.mskel").geometry == TILTED
    io.write_mskel(tmp_path / "b.mskel", Skeleton([[1, 2, 3]], [1.5], [0.7]))
    assert "geometry" not in (tmp_path / "b.mskel").read_text()  # old readers see nothing new
    assert io.read_mskel(tmp_path / "b.mskel").geometry == IDENTITY


@pytest.mark.parametrize("value, why", [
    ("spacing 1_0 1 1", "'spacing' takes 3 numbers"),  # Python's float() takes "1_0"; our files do not
    ("spacing nan 1 1", "'spacing' takes 3 numbers"),
    ("spacing 1 1 1 origin 0 0", "'origin' takes 3 numbers"),
    ("spacing 1 1 1 spacing 1 1 1", "each once"),
    ("origin 0 0 0", "at least 'spacing'"),
    ("spacing 1 1 1 direction 1 1 0 0 1 0 0 0 1", "orthonormal"),
])
def test_a_bad_header_line_names_the_file_and_line(tmp_path, value, why):
    path = tmp_path / "bad.mskel"
    path.write_text(f"# volanim mskel 1\n# metric: euclid\n# geometry: {value}\n1 2 3 1.5 0.7\n")
    with pytest.raises(FormatError, match=f"bad.mskel:3: bad '# geometry:' header: .*{why}"):
        io.read_mskel(path)
