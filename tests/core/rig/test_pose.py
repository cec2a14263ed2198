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


def _old_studio_rule(bones, m):  # what rig.pose.posed_joints did before #68: the bone that ends at a joint
    out = {}
    for i, b in enumerate(bones.bones):
        for name in (b.proximal, b.distal):
            if name == b.distal or name not in out:
                out[name] = np.append(bones.joints[name], 1.0) @ m[i]
    return {k: v[:3] for k, v in out.items()}


def test_one_rule_places_a_joint_wherever_it_is_asked_for():
    """The studio (posed_joints) and trans2positions (joint_positions over frames) place every joint alike;
    with nothing shifted both old rules agree with it, and a shifted bone takes its own start along."""
    from volanim_core.rig.pose import joint_positions, posed_joints

    bones = mannequin_bones()
    bent = pose_matrices(bones, {"L_FOREARM": (0, 0, 70), "R_THIGH": (40, 0, 0), "HEAD": (0, 30, 0)})
    by_name = posed_joints(bones, bent)
    frames = joint_positions(bones, np.stack([np.tile(np.eye(4), (len(bones), 1, 1)), bent]))
    assert frames.shape == (2, len(bones.joints), 3)
    assert np.allclose(frames[0], [bones.joints[n] for n in bones.joints])
    assert np.allclose(frames[1], [by_name[n] for n in bones.joints])
    old = _old_studio_rule(bones, bent)
    assert max(np.abs(old[n] - by_name[n]).max() for n in bones.joints) < 1e-9
    hand = bones.bones[[b.label for b in bones.bones].index("L_HAND")]
    shifted = pose_matrices(bones, translations={"L_HAND": (0, 0, 5)})
    moved = posed_joints(bones, shifted)
    assert np.allclose(moved[hand.proximal], np.asarray(bones.joints[hand.proximal]) + (0, 0, 5))  # the hand's start
    assert not np.allclose(_old_studio_rule(bones, shifted)[hand.proximal], moved[hand.proximal])  # (the old rule
    # left it at the forearm's end, so the studio drew the hand from where it was not)
