"""Flesh one voxel thin stays in one piece when its bone turns (reconstruct/_owned_kernels.splat_turned, #86):
a limb held on by voxel corners (the ant's leg tip, which came off at 90 degrees) and a sheet of one bone's flesh
lying on another's (the rabbit's, which came off at 45 degrees), each turned every which way."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage
from scipy.spatial.transform import Rotation

from volanim_core.reconstruct.owned import reconstruct_owned
from volanim_core.rig.connectivity import BoneSegment
from volanim_core.rig.ownership import Ownership

TURNS = Rotation.random(60, random_state=86).as_matrix()  # fixed: the same turns on every run


def _turned(own: Ownership, joint, rotation) -> np.ndarray:
    """The body (bone mode) with bone 1 turned by ``rotation`` about ``joint``, bone 0 still."""
    m = np.stack([np.eye(4), np.eye(4)])
    m[1, :3, :3] = rotation
    m[1, 3, :3] = joint - joint @ rotation
    return np.asarray(reconstruct_owned(own, m, mode="bone", padding=3).volume)


def _pieces(voxels: np.ndarray) -> int:
    return ndimage.label(voxels, np.ones((3, 3, 3), bool))[1]


def test_a_limb_held_on_by_its_corners_stays_one_piece_at_every_turn():
    """A leg one voxel thin along a cube's diagonal: each voxel touches the next by a corner only. Pushed to
    where they land, two such voxels can land two apart on an axis; their midpoint pushed too keeps them
    touching."""
    labels = np.zeros((24, 24, 24), np.uint8)
    labels[2:8, 2:8, 2:8] = 1  # the trunk
    for i in range(14):
        labels[8 + i, 8 + i, 8 + i] = 2  # the leg, from the trunk's corner
    joint = np.array([7.5, 7.5, 7.5])
    own = Ownership(labels, (0, 0, 0), [BoneSegment((2, 2, 2), tuple(joint)),
                                        BoneSegment(tuple(joint), (21.0, 21.0, 21.0))], np.zeros(2))
    broken = [k for k, r in enumerate(TURNS) if _pieces(_turned(own, joint, r) == 2) != 1]
    assert broken == []


@pytest.mark.slow
@pytest.mark.parametrize("body, leaf, angle", [("rabbit", "INF3_2", 45), ("ant", "R_ANT2_5", 90)])
def test_the_leaves_that_tore_a_voxel_off_bend_whole(tmp_path, body, leaf, angle):
    """Real bodies, as bench_autorig_bodies rigs them (voxelized at 160, autorig, pieces, owned): trimesh's rabbit
    bent 45 degrees at INF3_2 tore off one voxel of a fin of its flesh lying on INF3_1's, thick as body but one
    voxel thin as its own bone's (not pushed forward, since only body-thin voxels were); pyvista's ant bent 90
    degrees at R_ANT2_5 tore off its leg's tip, held on by a voxel corner."""
    from volanim_core import samples
    from volanim_core.io.mesh_files import read_mesh, voxelize
    from volanim_core.reconstruct.checks import report
    from volanim_core.rig.attach import connect
    from volanim_core.rig.autorig import autorig
    from volanim_core.rig.connectivity import Trans
    from volanim_core.rig.curve_skeleton import balls
    from volanim_core.rig.ownership import ownership
    from volanim_core.rig.pose import bend_across, pose_matrices, root_bones
    from volanim_core.skeleton.skeletonize import skeletonize

    samples.write_sample(body, tmp_path)
    mask = voxelize(read_mesh(tmp_path / f"{body}.ply"), size=160)[0] > 0
    skel = skeletonize(mask)
    bones = autorig(skel).bones
    conn = connect(skel, bones, method="pieces", mask=balls(skel))[0]
    owned = conn.with_ownership(ownership(mask, conn))
    m = pose_matrices(bones, {leaf: bend_across(bones, leaf, angle)})
    rep = report(owned, Trans(root_bones(bones), m), bones=bones)
    assert rep.healthy and not rep.specks, rep.verdict  # not even a speck let go (reconstruct/torn.py)
