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
