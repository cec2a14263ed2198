"""Inverting forward kinematics (a frame's matrices back onto the pose sliders)."""

from __future__ import annotations

import warnings

import numpy as np

from volanim_core.rig.pose import local_motion, pose_matrices
from volanim_core.samples import mannequin_bones


def test_local_motion_at_gimbal_lock_gives_angles_that_rebuild_the_pose():
    """A key at 90 degrees about y (an arm raised straight) used to raise scipy's gimbal-lock warning."""
    bones = mannequin_bones()
    m = pose_matrices(bones, {"L_UPPERARM": [10.0, -90.0, 20.0]})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        angles, shifts = local_motion(bones, m)
    assert np.allclose(pose_matrices(bones, angles, shifts), m, atol=1e-9)


def test_bend_across_bends_a_bone_along_y_where_0_45_0_only_twists_it():
    from volanim_core.rig.bones import Bone, BoneSkeleton
    from volanim_core.rig.pose import bend_across, pose_matrices, posed_joints

    bones = BoneSkeleton({"A": np.array([0.0, 0, 0]), "B": np.array([0.0, 10, 0])}, [Bone("A", "B", "AB")])
    twisted = posed_joints(bones, pose_matrices(bones, {"AB": (0.0, 45.0, 0.0)}))["B"]
    bent = posed_joints(bones, pose_matrices(bones, {"AB": bend_across(bones, "AB", 45.0)}))["B"]
    assert np.allclose(twisted[:3], [0, 10, 0])  # about its own length: the tip stays
    assert np.isclose(np.linalg.norm(bent[:3]), 10) and np.isclose(bent[1], 10 * np.cos(np.radians(45)))
