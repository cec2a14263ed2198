"""Pieces torn off, and the specks a pose lets go where the rest pose's own lie (#86: Bob's leaves at 320
voxels, smooth joints, called BROKEN for specks of 4 and 5 voxels 2 and 3 voxels off its body)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from volanim_core.reconstruct.breakage import breakage_report
from volanim_core.reconstruct.checks import report_json
from volanim_core.reconstruct.torn import homes, torn_off
from volanim_core.rig.connectivity import BoneSegment, Connectivity, Trans
from volanim_core.rig.tskel_tools import connect_to_tskel

CENTRE = np.array([30.0, 20, 20])
SPECK = CENTRE + (4, 6, 0)  # a one-voxel sphere touching the 6-voxel ball by one voxel's corner at rest
JOINTS = {"P": np.array([20.0, 20, 20]), "Q": np.array([40.0, 20, 20])}
BONES = [BoneSegment(JOINTS["P"], JOINTS["Q"], "A"), BoneSegment(JOINTS["Q"], [50, 20, 20], "B")]


def turned(degrees: float, about: np.ndarray) -> np.ndarray:
    """A turn about z through ``about``, in the row-vector convention of .trans matrices."""
    m = np.eye(4)
    m[:3, :3] = Rotation.from_euler("z", degrees, degrees=True).as_matrix()
    m[:3, 3] = about - m[:3, :3] @ about
    return m.T


def report(speck_bone: int, matrices: list[np.ndarray]):
    conn = Connectivity(BONES, np.array([CENTRE, SPECK]), np.array([6.0, 1.0]), None, np.array([0, speck_bone]))
    trans = Trans(BONES, np.array(matrices))
    posed = {n: p @ matrices[0][:3, :3] + matrices[0][3, :3] for n, p in JOINTS.items()}
    return breakage_report(connect_to_tskel(conn, trans), JOINTS, posed)


def test_a_speck_moved_by_the_same_matrix_as_its_flesh_can_part_from_it_by_one_voxel():
    """Both spheres move by one matrix, so nothing tears; but their centres land on other fractions of a voxel,
    and the speck, which touched the ball by a corner at rest, now lies one empty voxel off it."""
    rest = report(0, [np.eye(4), np.eye(4)])
    assert len(rest.components) == 1  # one piece at rest: the speck touches the ball
    r = report(0, [turned(21, CENTRE), turned(21, CENTRE)])
    assert len(r.components) == 2 and r.components[1] == 2  # parted on the grid
    assert r.healthy and r.pieces == [] and r.verdict == "healthy: one piece, no stump"
    assert [n for n, _, _ in r.specks] == [2]
    assert any("1 speck(s) of at most 8 voxels let go within 3 voxels of the body" in line for line in r.lines())
    assert report_json(r)["specks"][0]["voxels"] == 2 and report_json(r)["pieces"] == []


def shifted(y: float) -> np.ndarray:
    m = np.eye(4)
    m[3, 1] = y
    return m


@pytest.mark.parametrize("y", [4, 6, 12])
def test_a_speck_carried_off_by_another_bone_is_still_a_piece_torn_off(y):
    """The same speck given to bone B, which moves it away from the ball: three empty voxels or more between
    them, farther than the rest pose's specks lie, so the pose tore it off, however small."""
    r = report(1, [np.eye(4), shifted(y)])
    assert not r.healthy and r.specks == [] and [n for n, _, _ in r.pieces] == [r.components[1]]
    assert r.verdict.startswith("BROKEN: the pose tore off 1 piece")


def test_a_rest_piece_s_home_is_where_most_of_it_lands():
    rest_piece = np.array([1, 1, 1, 2, 2, 3])
    posed_piece = np.array([4, 4, 5, 6, 0, 0])  # piece 1 splits 2:1; 2 lands in 6 once; 3 lands nowhere
    assert homes(rest_piece, posed_piece, 6).tolist() == [0, 4, 6, 0]
    assert torn_off(homes(rest_piece, posed_piece, 6), 6).tolist() == [1, 2, 3, 5]
