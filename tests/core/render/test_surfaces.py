"""The label surface (studio live preview, render surface style) is coloured by the filled voxels only."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core.render.surfaces import label_surface, voxel_faces


def test_every_surface_point_takes_the_colour_of_the_filled_voxel_it_bounds():
    x, y, z = np.ogrid[:40, :40, :40]
    vol = np.where((x - 20) ** 2 + (y - 20) ** 2 + (z - 20) ** 2 <= 15**2, 1, 0).astype(np.uint8)
    vol[21:] *= 2  # the +x half is label 2
    table = np.array([[9, 9, 9], [255, 0, 0], [0, 0, 255]], np.uint8)
    surf = label_surface(vol, (100, 0, -5), (1, 1, 1), table)
    rgb = np.asarray(surf.point_data["rgb"])
    px = np.asarray(surf.points)[:, 0] - 100
    assert surf.n_points > 1000
    assert not np.any(np.all(rgb == table[0], axis=1))  # never the empty voxel's colour (half were, before)
    assert np.all(rgb[px < 20] == table[1]) and np.all(rgb[px > 21] == table[2])


def boundary_faces(vol: np.ndarray) -> dict:
    """Each face between a filled voxel and an empty one (or the grid's edge), found with NumPy alone:
    ``{(centre of the face in voxel units, doubled to stay whole) : (outward axis, sign, label)}``."""
    padded = np.pad(vol, 1)
    faces = {}
    for axis in range(3):
        for sign in (-1, 1):
            neighbour = np.roll(padded, -sign, axis=axis)[1:-1, 1:-1, 1:-1]
            for v in np.argwhere((vol != 0) & (neighbour == 0)):
                centre = 2 * v
                centre[axis] += sign
                faces[tuple(centre)] = (axis, sign, int(vol[tuple(v)]))
    return faces


def test_voxel_faces_are_the_faces_between_filled_and_empty_voxels_outward_and_coloured_by_their_voxel():
    rng = np.random.default_rng(5)
    vol = (rng.random((9, 7, 6)) < 0.45) * rng.integers(1, 4, (9, 7, 6))
    vol = np.ascontiguousarray(vol.astype(np.uint8).T).T  # an [x, y, z] view of a [z, y, x] array, as pictures are
    table = np.array([[9, 9, 9], [255, 0, 0], [0, 255, 0], [0, 0, 255]], np.uint8)
    origin, spacing = np.array([100.0, 0.0, -5.0]), np.array([0.5, 1.0, 2.0])
    mesh = voxel_faces(vol, origin, spacing, table)
    want = boundary_faces(vol)
    assert mesh.n_cells == len(want) > 100
    corners = np.asarray(mesh.points).reshape(-1, 4, 3)  # 4 corners a face, in world units
    rgb = np.asarray(mesh.point_data["rgb"]).reshape(-1, 4, 3)
    assert np.array_equal(np.asarray(mesh.regular_faces), np.arange(4 * mesh.n_cells).reshape(-1, 4))
    got = {}
    for c, colour in zip(corners, rgb):
        voxels = (c - origin) / spacing  # back in voxel units: a unit square at a half-voxel boundary
        centre = voxels.mean(0)
        normal = np.cross(voxels[1] - voxels[0], voxels[2] - voxels[0])
        axis = int(np.argmax(np.abs(normal)))
        sign = int(np.sign(normal[axis]))
        assert np.allclose(np.abs(normal), np.eye(3)[axis])  # a unit square across one axis
        filled = np.rint(centre - 0.5 * sign * np.eye(3)[axis]).astype(int)  # the voxel behind the face
        assert (colour == colour[0]).all()
        got[tuple(np.rint(2 * centre).astype(int))] = (axis, sign, int(vol[tuple(filled)]))
        assert np.array_equal(colour[0], table[vol[tuple(filled)]])
    assert got == want  # every face, facing out of its filled voxel


def test_voxel_faces_of_any_memory_order_of_labels_and_of_nothing():
    x, y, z = np.ogrid[:20, :16, :12]
    ball = ((x - 10) ** 2 + (y - 8) ** 2 + (z - 6) ** 2 <= 25).astype(np.uint16) * 300  # past the table: its last row
    table = np.array([[0, 0, 0], [1, 2, 3]], np.uint8)
    a = voxel_faces(np.ascontiguousarray(ball), (0, 0, 0), (1, 1, 1), table)
    b = voxel_faces(np.asfortranarray(ball), (0, 0, 0), (1, 1, 1), table)
    assert a.n_cells == b.n_cells == len(boundary_faces(ball))
    assert (np.asarray(a.point_data["rgb"]) == [1, 2, 3]).all()
    assert voxel_faces(ball > 0, (0, 0, 0), (1, 1, 1)).n_cells == a.n_cells  # no table: no colours
    assert voxel_faces(np.zeros((4, 4, 4), np.uint8), (0, 0, 0), (1, 1, 1), table).n_cells == 0
    with pytest.raises(ValueError, match="label volume"):
        voxel_faces(ball.astype(np.float32), (0, 0, 0), (1, 1, 1), table)


def test_voxel_faces_keep_a_transfer_function_s_opacity():
    """Review of #85: the live picture's faces took only RGB of the user's RGBA table, so a bone made faint by the
    transfer function was drawn solid while dragged (flying edges had kept the alpha)."""
    vol = np.zeros((6, 6, 6), np.uint8)
    vol[1:3, 1:5, 1:5], vol[3:5, 1:5, 1:5] = 1, 2
    table = np.array([[0, 0, 0, 0], [200, 10, 10, 255], [10, 10, 200, 26]], np.uint8)  # label 2 at 0.1
    mesh = voxel_faces(vol, (0, 0, 0), (1, 1, 1), table)
    rgba = np.asarray(mesh.point_data["rgb"])
    assert rgba.shape[1] == 4 and set(map(tuple, rgba.tolist())) == {tuple(table[1]), tuple(table[2])}
