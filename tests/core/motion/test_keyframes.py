"""Keyframes: slerp between pose keys, ease in/out, held ends, bone lengths kept, JSON round trip."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from small_rigs import arms_down, posed_joints
from volanim_core.motion.keyframes import interpolate
from volanim_core.rig.key_pose import KeyPose
from volanim_core.rig.pose import pose_matrices
from volanim_core.samples import mannequin_bones

ARM = ("L_SHOULDER", "L_ELBOW")


def local_angle(mats: np.ndarray, bones, child: int) -> np.ndarray:
    """Per frame, the angle (degrees) of a bone's rotation relative to its parent."""
    parent = bones.parents()[child]
    rel = mats[:, child, :3, :3] @ np.linalg.inv(mats[:, parent, :3, :3])
    return np.degrees(Rotation.from_matrix(np.swapaxes(rel, 1, 2)).magnitude())


def test_slerp_turns_at_constant_speed_between_two_keys():
    bones = arms_down()
    keys = {0: KeyPose(), 10: KeyPose({ARM: np.array([0.0, 90.0, 0.0])})}
    mats = interpolate(bones, keys, range(11))
    assert np.allclose(local_angle(mats, bones, 1), np.arange(11) * 9.0)
    # the frame halfway is the 45-degree pose the sliders would make
    assert np.allclose(mats[5], pose_matrices(bones, {1: [0.0, 45.0, 0.0]}))


def test_slerp_takes_the_short_way_round():
    bones = arms_down()
    keys = {0: KeyPose({ARM: np.array([0.0, 0.0, 170.0])}), 2: KeyPose({ARM: np.array([0.0, 0.0, -170.0])})}
    mats = interpolate(bones, keys, [1])
    assert np.allclose(local_angle(mats, bones, 1), 180.0)  # through 180, not back through 0


def test_ease_starts_and_ends_slowly_and_keeps_the_midpoint():
    bones = arms_down()
    keys = {0: KeyPose(), 10: KeyPose({ARM: np.array([90.0, 0.0, 0.0])})}
    plain = local_angle(interpolate(bones, keys, range(11)), bones, 1)
    eased = local_angle(interpolate(bones, keys, range(11), ease=True), bones, 1)
    assert eased[1] < plain[1] / 2 and eased[9] > 90 - (90 - plain[9]) / 2
    assert np.isclose(eased[5], 45.0) and np.isclose(eased[10], 90.0)
    assert np.allclose(eased[1], 90 * (0.1 ** 2 * (3 - 0.2)))


def test_frames_outside_the_keys_hold_the_first_and_last_pose():
    bones = arms_down()
    keys = {5: KeyPose({ARM: np.array([30.0, 0.0, 0.0])}), 9: KeyPose({ARM: np.array([60.0, 0.0, 0.0])})}
    angle = local_angle(interpolate(bones, keys, [0, 5, 7, 9, 20]), bones, 1)
    assert np.allclose(angle, [30, 30, 45, 60, 60])
    one = {3: KeyPose({ARM: np.array([0.0, 20.0, 0.0])})}
    assert np.allclose(local_angle(interpolate(bones, one, [0, 3, 50]), bones, 1), 20)


def test_shifts_interpolate_linearly_and_children_follow():
    bones = arms_down()
    keys = {0: KeyPose(), 4: KeyPose(shifts={("PELVIS", "L_SHOULDER"): np.array([8.0, 0.0, 0.0])})}
    mats = interpolate(bones, keys, [1])
    assert np.allclose(mats[0, :, 3, :3], [2.0, 0.0, 0.0])


def test_bone_lengths_never_change_on_the_mannequin():
    bones = mannequin_bones()
    rng = np.random.default_rng(3)
    keys = {f: KeyPose({(b.proximal, b.distal): rng.uniform(-120, 120, 3) for b in bones.bones})
            for f in (0, 7, 30)}
    mats = interpolate(bones, keys, np.arange(0, 31), ease=True)
    rest = {(b.proximal, b.distal): np.linalg.norm(bones.joints[b.distal] - bones.joints[b.proximal])
            for b in bones.bones}
    for m in mats:
        j = posed_joints(bones, m)  # also asserts no joint is torn between parent and child
        for (p, d), length in rest.items():
            assert np.isclose(np.linalg.norm(j[d] - j[p]), length)


def test_no_keys_is_the_rest_pose():
    mats = interpolate(arms_down(), {}, range(3))
    assert mats.shape == (3, 3, 4, 4) and np.allclose(mats, np.eye(4))


def test_json_round_trip_and_bad_rows_name_the_key():
    key = KeyPose({ARM: np.array([1.0, 2.0, 3.0])}, {ARM: np.array([0.0, 0.5, 0.0])})
    back = KeyPose.from_json(key.to_json(), "key 4")
    assert np.allclose(back.angles[ARM], [1, 2, 3]) and np.allclose(back.shifts[ARM], [0, 0.5, 0])
    for bad in ([["A", "B", 1, 2]], [["A", "B", 1, 2, 3, 0, 0, float("nan")]], "x", [["A", "B", True, 0, 0, 0, 0, 0]],
                [["A", "B", 0, 0, 0, 0, 0, 0], ["A", "B", 1, 0, 0, 0, 0, 0]]):
        with pytest.raises(ValueError, match="key 4"):
            KeyPose.from_json(bad, "key 4")
