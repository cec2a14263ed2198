"""The BVH reader and forward kinematics on clips whose posed joints are known in closed form."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from paths import WALK  # WALK: the real clip, bundled with its MIT licence
from volanim_core.errors import FormatError
from volanim_core.io.bvh_files import read_bvh


def clip(order: str, frames: list[str], root_channels: str = "Xposition Yposition Zposition",
         child_channels: str | None = None, end: str = "0 5 0", frame_time: str = "0.04") -> str:
    """Root -> Arm (offset 0 10 0) -> Hand (offset 0 4 0) -> End Site."""
    rot = " ".join(f"{a}rotation" for a in order)
    child = child_channels or rot
    n_child = len(child.split())
    return (f"HIERARCHY\nROOT Root\n{{\n  OFFSET 0 0 0\n  CHANNELS {3 + len(order)} {root_channels} {rot}\n"
            f"  JOINT Arm\n  {{\n    OFFSET 0 10 0\n    CHANNELS {n_child} {child}\n"
            f"    JOINT Hand\n    {{\n      OFFSET 0 4 0\n      CHANNELS 3 {rot}\n"
            f"      End Site\n      {{\n        OFFSET {end}\n      }}\n    }}\n  }}\n}}\n"
            f"MOTION\nFrames: {len(frames)}\nFrame Time: {frame_time}\n" + "\n".join(frames) + "\n")


def write(tmp_path, text: str, name: str = "c.bvh") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


# spec: docs/formats.md#bvh
def test_rest_frame_places_joints_at_their_offsets(tmp_path):
    m = read_bvh(write(tmp_path, clip("ZXY", ["1 2 3 0 0 0 0 0 0 0 0 0"])))
    assert m.names == ["Root", "Arm", "Hand"] and m.parents.tolist() == [-1, 0, 1]
    assert m.fps == pytest.approx(25) and m.frames == 1 and list(m.end_sites) == [2]
    _, pos = m.forward_kinematics()
    assert np.allclose(pos[0], [[1, 2, 3], [1, 12, 3], [1, 16, 3]])


# spec: docs/formats.md#bvh
@pytest.mark.parametrize("order, expected_arm", [
    # intrinsic, listed order: R = R1 @ R2 @ R3 applied to the Hand's offset (0 4 0); Y is 0
    ("ZXY", [0, 0, 4]),   # Rx(90) (0 4 0) = (0 0 4); Rz(90) keeps z
    ("XZY", [-4, 0, 0]),  # Rz(90) (0 4 0) = (-4 0 0); Rx(90) keeps x
])
def test_channel_order_is_intrinsic_in_the_listed_order(tmp_path, order, expected_arm):
    angles = {"Z": "90", "X": "90", "Y": "0"}
    arm = " ".join(angles[a] for a in order)
    m = read_bvh(write(tmp_path, clip(order, [f"0 0 0 0 0 0 {arm} 0 0 0"])))
    _, pos = m.forward_kinematics()
    assert np.allclose(pos[0, 2] - pos[0, 1], expected_arm, atol=1e-9)


def test_three_axis_orders_agree_with_a_hand_built_matrix(tmp_path):
    from scipy.spatial.transform import Rotation

    a, b, c = 30.0, -50.0, 70.0
    for order in ("XYZ", "ZXY", "YZX", "ZYX"):
        m = read_bvh(write(tmp_path, clip(order, [f"0 0 0 {a} {b} {c} 0 0 0 0 0 0"])))
        rot, pos = m.forward_kinematics()
        axes = [np.eye(3)["XYZ".index(ax)] for ax in order]
        r = np.eye(3)
        for axis, angle in zip(axes, (a, b, c)):
            r = r @ Rotation.from_rotvec(np.radians(angle) * axis).as_matrix()
        assert np.allclose(rot[0, 0], r)
        assert np.allclose(pos[0, 1], r @ [0, 10, 0])


def test_six_channel_child_adds_its_translation_to_its_offset(tmp_path):
    text = clip("ZXY", ["0 0 0 90 0 0 1 2 3 0 0 0 0 0 0"],
                child_channels="Xposition Yposition Zposition Zrotation Xrotation Yrotation")
    m = read_bvh(write(tmp_path, text))
    _, pos = m.forward_kinematics()
    # the root's Rz(90) turns the Arm's local (0+1, 10+2, 0+3) into (-12, 1, 3)
    assert np.allclose(pos[0, 1], [-12, 1, 3])


def test_units_scale_positions_only(tmp_path):
    frames = ["5 6 7 10 20 30 40 50 60 0 0 0"]
    inch = read_bvh(write(tmp_path, clip("ZXY", frames), "inch.bvh"))
    cm_frames = ["12.7 15.24 17.78 10 20 30 40 50 60 0 0 0"]
    cm_text = clip("ZXY", cm_frames).replace("OFFSET 0 10 0", "OFFSET 0 25.4 0").replace("OFFSET 0 4 0",
                                                                                          "OFFSET 0 10.16 0")
    cm = read_bvh(write(tmp_path, cm_text, "cm.bvh"))
    r_in, p_in = inch.forward_kinematics(scale=2.54)
    r_cm, p_cm = cm.forward_kinematics()
    assert np.allclose(p_in, p_cm) and np.allclose(r_in, r_cm)


def test_bone_lengths_never_change_over_a_clip(tmp_path):
    rng = np.random.default_rng(5)
    frames = [" ".join(f"{v:.4f}" for v in np.r_[rng.normal(0, 5, 3), rng.uniform(-180, 180, 9)])
              for _ in range(50)]
    m = read_bvh(write(tmp_path, clip("YXZ", frames)))
    _, pos = m.forward_kinematics()
    assert np.allclose(np.linalg.norm(pos[:, 1] - pos[:, 0], axis=1), 10)
    assert np.allclose(np.linalg.norm(pos[:, 2] - pos[:, 1], axis=1), 4)


def test_the_real_walk_clip():
    m = read_bvh(WALK)
    assert m.frames == 1064 and len(m.names) == 23 and m.values.shape == (1064, 72)
    assert m.fps == pytest.approx(120, rel=1e-3)
    rot, pos = m.forward_kinematics(slice(0, 1064, 50))
    assert pos.shape == (22, 23, 3)
    assert np.allclose(rot @ np.swapaxes(rot, -1, -2), np.eye(3), atol=1e-9)
    spine, head = m.index("Spine"), m.index("Head")
    assert np.allclose(np.linalg.norm(pos[:, head] - pos[:, spine], axis=1), 13.8244, atol=1e-6)


# spec: docs/formats.md#bvh
@pytest.mark.parametrize("mutate, message", [
    (lambda t: t.replace("HIERARCHY", "HIERARCHX"), "starting with HIERARCHY"),
    (lambda t: t.replace("MOTION", "MOTON"), "no MOTION section"),
    (lambda t: t.replace("Frames: 1", "Frames: 2"), "'Frames: 2' but the file has 1 frame lines"),
    (lambda t: t.replace("Frames: 1", "Frames: 0"), "'Frames: 0' but the file has 1 frame lines"),
    (lambda t: t.replace("CHANNELS 3 Zrotation", "CHANNELS 4 Zrotation"), "must be 0, 3 or 6"),
    (lambda t: t.replace("Hand\n", "Arm\n"), "defined twice"),
    (lambda t: t.replace("OFFSET 0 4 0", "OFFSET 0 nan 0"), "expected a number for the OFFSET of Hand"),
    (lambda t: t.replace("OFFSET 0 4 0", "OFFSET 0 １ 0"), "expected a number"),
    (lambda t: t.replace("Frame Time: 0.04", "Frame Time: 0"), "must be positive"),
    (lambda t: t.rstrip("\n").rsplit("\n", 1)[0] + "\n1 2 3\n", "expected 12 channel values, got 3"),
    (lambda t: t.replace("0 0 0 0 0 0 0 0 0\n", "0 0 0 0 0 0 0 0 x\n"), "expected a number"),
    (lambda t: t.replace("      }\n    }\n  }\n}\n", "      }\n    }\n  }\n"), "unclosed"),
    (lambda t: t.replace("Yrotation\n  JOINT", "Yrotation\n  JUNK"), "expected JOINT"),
    (lambda t: t.replace("Zrotation Xrotation Yrotation\n      End", "Zrotation Xrotation Wrotation\n      End"),
     "unknown channel"),
])
def test_bad_files_are_format_errors_naming_file_and_line(tmp_path, mutate, message):
    path = write(tmp_path, mutate(clip("ZXY", ["0 0 0 0 0 0 0 0 0 0 0 0"])), "bad.bvh")
    with pytest.raises(FormatError, match=message) as info:
        read_bvh(path)
    assert str(path) in str(info.value)


def test_deep_hierarchies_do_not_recurse(tmp_path):
    n = 3000
    text = "HIERARCHY\nROOT J0\n{\nOFFSET 0 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n"
    for i in range(1, n):
        text += f"JOINT J{i}\n{{\nOFFSET 0 1 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n"
    text += "}\n" * n + f"MOTION\nFrames: 1\nFrame Time: 0.1\n{' '.join(['0'] * 3 * n)}\n"
    m = read_bvh(write(tmp_path, text))
    _, pos = m.forward_kinematics()
    assert np.allclose(pos[0, -1], [0, n - 1, 0])


def test_six_channel_child_holding_its_local_position_replaces_its_offset(tmp_path):
    """Blender writes a child's position channels as its whole local position (equal to its OFFSET
    while it does not move); adding them doubled such bones (#39, bvhtools' test3.bvh)."""
    text = clip("ZXY", ["0 0 0 0 0 0 0 10 0 0 0 0 0 0 0", "0 0 0 0 0 0 0 10.5 0 0 0 0 0 0 0"],
                child_channels="Xposition Yposition Zposition Zrotation Xrotation Yrotation")
    m = read_bvh(write(tmp_path, text))
    _, pos = m.forward_kinematics()
    assert np.allclose(pos[:, 1], [[0, 10, 0], [0, 10.5, 0]])  # not (0, 20, 0)


@pytest.mark.parametrize("axes", ["ZXY", "XYZ", "YZX", "ZYX", "XZY", "YXZ", "Z", "XY"])
def test_euler_rotations_are_scipys(axes):
    """The channels' rotations are written out (scipy 1.17's from_euler took 56 of the walk's 75 ms of forward
    kinematics); they are scipy's intrinsic rotations, angle for angle, whatever the order and range."""
    from scipy.spatial.transform import Rotation

    from volanim_core.io.bvh_files import euler_matrices

    angles = np.random.default_rng(3).uniform(-400, 400, (64, len(axes)))
    want = Rotation.from_euler(axes, angles, degrees=True).as_matrix()
    assert np.allclose(euler_matrices(axes, angles), want, rtol=0, atol=1e-12)
