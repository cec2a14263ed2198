"""Retargeting onto our bones: known answers for rest-equal clips, T-pose vs arms-down, elbow angles."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from paths import WALK
from small_rigs import arms_down, posed_joints
from volanim_core import io
from volanim_core.cli import main
from volanim_core.errors import FormatError
from volanim_core.io.bvh_files import read_bvh
from volanim_core.io.mapping_files import read_mapping
from volanim_core.motion.retarget import Retarget, axes_matrix, suggest_mapping
from volanim_core.rig.bones import Bone, BoneSkeleton
from volanim_core.samples import mannequin_bones

ASSETS = Path(__file__).resolve().parents[3] / "assets"
A = axes_matrix("y", "z")  # BVH (Y up, facing +Z) -> ours (z up, facing -y)


def arm_clip(tmp_path, frames: list[str]) -> Path:
    """Hips -> LeftArm (T-pose: +X) -> LeftForeArm -> End Site; 3 + 9 channels."""
    text = ("HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation "
            "Yrotation\nJOINT LeftArm\n{\nOFFSET 2 10 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n"
            "JOINT LeftForeArm\n{\nOFFSET 6 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n"
            "End Site\n{\nOFFSET 5 0 0\n}\n}\n}\n}\n"
            f"MOTION\nFrames: {len(frames)}\nFrame Time: 0.04\n" + "\n".join(frames) + "\n")
    p = tmp_path / "arm.bvh"
    p.write_text(text)
    return p


def test_axes_map_bvh_up_and_forward_onto_ours():
    assert np.allclose(A @ [0, 1, 0], [0, 0, 1]) and np.allclose(A @ [0, 0, 1], [0, -1, 0])
    assert np.allclose(A @ [1, 0, 0], [1, 0, 0])  # the figure's left stays left
    assert np.isclose(np.linalg.det(axes_matrix("z", "-y")), 1)
    with pytest.raises(ValueError, match="different axes"):
        axes_matrix("y", "-y")


def test_a_clip_whose_rest_is_ours_reproduces_world_rotations_and_positions(tmp_path):
    """Our skeleton is the clip's rest pose turned into our axes: rotations transfer exactly."""
    rng = np.random.default_rng(2)
    angles = rng.uniform(-80, 80, (2, 9))
    frames = ["0 0 0 0 0 0 0 0 0 0 0 0", " ".join(f"{v:.6f}" for v in np.r_[[1.5, -2, 3], angles[1]])]
    motion = read_bvh(arm_clip(tmp_path, frames))
    rest = motion.rest_positions() @ A.T
    joints = {"HIPS_J": rest[0], "SHOULDER": rest[1], "ELBOW": rest[2], "WRIST": rest[2] + A @ [5, 0, 0]}
    bones = BoneSkeleton(joints, [Bone("HIPS_J", "SHOULDER", "SPINE"), Bone("SHOULDER", "ELBOW", "UPPER"),
                                  Bone("ELBOW", "WRIST", "FORE")])
    r = Retarget.build(bones, motion, {"SPINE": "Hips", "UPPER": "LeftArm", "FORE": "LeftForeArm"})
    assert r.scale == pytest.approx(1.0) and np.allclose(r.rest_align, np.eye(3))
    world_rot, world_pos = motion.forward_kinematics()
    mats = r.matrices()
    for b, k in ((0, 0), (1, 1), (2, 2)):
        assert np.allclose(mats[1, b, :3, :3].T, A @ world_rot[1, k] @ A.T)
    posed = posed_joints(bones, mats[1])  # the root moved by the clip's displacement since frame 0
    assert np.allclose(posed["ELBOW"], A @ world_pos[1, 2] - A @ world_pos[0, 0] + rest[0])


def test_a_t_pose_clip_drives_an_arms_down_skeleton(tmp_path):
    # frame 0: the clip's T-pose; frame 1: arm hanging down (-90 about the clip's Z), elbow bent 60 forward
    frames = ["0 0 0 0 0 0 0 0 0 0 0 0", "0 0 0 0 0 0 -90 0 0 0 0 -60"]
    bones = arms_down()
    r = Retarget.build(bones, read_bvh(arm_clip(tmp_path, frames)))
    assert suggest_mapping(bones, r.motion) == {"L_UPPERARM": "LeftArm", "L_FOREARM": "LeftForeArm"}
    assert r.absorbed_degrees()["L_UPPERARM"] == pytest.approx(90)
    mats = r.matrices()
    t_pose, down = posed_joints(bones, mats[0]), posed_joints(bones, mats[1])
    # in the clip's T-pose our arm points sideways (+x, the figure's left) ...
    assert np.allclose((t_pose["L_ELBOW"] - t_pose["L_SHOULDER"]) / 6, [1, 0, 0], atol=1e-9)
    # ... and hanging down it is back at our rest, the forearm bent by the clip's 60 degrees
    assert np.allclose(down["L_ELBOW"], bones.joints["L_ELBOW"], atol=1e-9)
    upper, fore = down["L_ELBOW"] - down["L_SHOULDER"], down["L_WRIST"] - down["L_ELBOW"]
    cos = upper @ fore / np.linalg.norm(upper) / np.linalg.norm(fore)
    assert np.degrees(np.arccos(cos)) == pytest.approx(60)


def test_the_elbow_angle_follows_the_clip_frame_by_frame(tmp_path):
    rng = np.random.default_rng(9)
    frames = [" ".join(f"{v:.5f}" for v in np.r_[0, 0, 0, rng.uniform(-60, 60, 9)]) for _ in range(30)]
    motion = read_bvh(arm_clip(tmp_path, frames))
    bones = arms_down()
    mats = Retarget.build(bones, motion).matrices()
    _, pos = motion.forward_kinematics()
    end = pos[:, 2] + np.einsum("fab,b->fa", motion.forward_kinematics()[0][:, 2], [5, 0, 0])
    for f in range(30):
        p = posed_joints(bones, mats[f])
        ours = _angle(p["L_ELBOW"] - p["L_SHOULDER"], p["L_WRIST"] - p["L_ELBOW"])
        clip = _angle(pos[f, 2] - pos[f, 1], end[f] - pos[f, 2])
        assert ours == pytest.approx(clip, abs=1e-6)
        assert np.linalg.norm(p["L_WRIST"] - p["L_ELBOW"]) == pytest.approx(5)  # bone lengths are ours


def _angle(a, b) -> float:
    return float(np.degrees(np.arccos(np.clip(a @ b / np.linalg.norm(a) / np.linalg.norm(b), -1, 1))))


def test_walk_drives_the_mannequin_keeping_bone_lengths():
    bones = io.read_bones(ASSETS / "mannequin.bones")
    r = Retarget.build(bones, read_bvh(WALK))
    assert len(r.mapping) == 18  # every mannequin bone finds its joint by name
    mats = r.matrices(slice(0, None, 7))
    seg = bones.segments()
    for f in range(len(mats)):
        prox = np.einsum("bj,bjk->bk", seg[:, 0], mats[f, :, :3, :3]) + mats[f, :, 3, :3]
        dist = np.einsum("bj,bjk->bk", seg[:, 1], mats[f, :, :3, :3]) + mats[f, :, 3, :3]
        assert np.allclose(np.linalg.norm(dist - prox, axis=1), np.linalg.norm(seg[:, 1] - seg[:, 0], axis=1))
        rot = mats[f, :, :3, :3]
        assert np.allclose(rot @ np.swapaxes(rot, 1, 2), np.eye(3), atol=1e-9)
        posed_joints(bones, mats[f])  # no joint torn apart


def test_unmapped_bones_follow_their_parent_rigidly():
    bones = io.read_bones(ASSETS / "mannequin.bones")
    motion = read_bvh(WALK)
    mats = Retarget.build(bones, motion, {"SPINE": "Spine"}).matrices(slice(100, 101))
    head, spine = bones.index("HEAD"), bones.index("SPINE")
    assert np.allclose(mats[0, head], mats[0, spine])


# spec: docs/formats.md#bvh
def test_mapping_files(tmp_path):
    (tmp_path / "m.txt").write_text("# ours theirs\nL_UPPERARM LeftArm\nL_FOREARM LeftForeArm\n")
    assert read_mapping(tmp_path / "m.txt") == {"L_UPPERARM": "LeftArm", "L_FOREARM": "LeftForeArm"}
    (tmp_path / "bad.txt").write_text("L_UPPERARM LeftArm\nL_UPPERARM RightArm\n")
    with pytest.raises(FormatError, match="bad.txt:2: bone 'L_UPPERARM' is mapped twice"):
        read_mapping(tmp_path / "bad.txt")


def test_bvh2trans_and_trans2tskel_command_line(tmp_path, capsys):
    out = tmp_path / "walk"
    assert main(["bvh2trans", str(WALK), "--bones", str(ASSETS / "mannequin.bones"), "--frames", "0:300:100",
                 "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "L_UPPERARM LeftArm" in text and "rest poses differ by" in text and "wrote 3 frames" in text
    frames = sorted(out.glob("walk.*.trans"))
    assert [f.name for f in frames] == ["walk.0000.trans", "walk.0100.trans", "walk.0200.trans"]
    assert main(["trans2tskel", str(ASSETS / "mannequin.0.50.connect"), *map(str, frames), "-o", str(out)]) == 0
    assert len(list(out.glob("*.tskel"))) == 3
    (tmp_path / "m.txt").write_text("L_UPPERARM NoSuchJoint\n")
    assert main(["bvh2trans", str(WALK), "--bones", str(ASSETS / "mannequin.bones"), "--map",
                 str(tmp_path / "m.txt"), "-o", str(out)]) == 2
    assert "m.txt: BVH joint 'NoSuchJoint' is not in the clip" in capsys.readouterr().err


def figure_clip(tmp_path, up: str, forward: str) -> Path:
    """A small figure (spine, pelvis, left leg and foot, a T-pose left arm) written in the axes ``up``/``forward``."""
    to_clip = axes_matrix(up, forward).T  # ours -> the clip's axes

    def off(x, y, z):
        return " ".join(f"{v:g}" for v in to_clip @ np.array([x, y, z], float))

    joint = "CHANNELS 3 Zrotation Xrotation Yrotation"
    text = (f"HIERARCHY\nROOT Hips\n{{\nOFFSET {off(0, 0, 10)}\nCHANNELS 6 Xposition Yposition Zposition "
            f"Zrotation Xrotation Yrotation\n"
            f"JOINT Spine\n{{\nOFFSET {off(0, 0, 1)}\n{joint}\nEnd Site\n{{\nOFFSET {off(0, 0, 5)}\n}}\n}}\n"
            f"JOINT LeftUpLeg\n{{\nOFFSET {off(2, 0, 0)}\n{joint}\nJOINT LeftLeg\n{{\nOFFSET {off(0, 0, -5)}\n{joint}\n"
            f"JOINT LeftFoot\n{{\nOFFSET {off(0, 0, -5)}\n{joint}\n"
            f"End Site\n{{\nOFFSET {off(0, -2, 0)}\n}}\n}}\n}}\n}}\n"
            f"JOINT LeftArm\n{{\nOFFSET {off(2, 0, 5)}\n{joint}\nEnd Site\n{{\nOFFSET {off(6, 0, 0)}\n}}\n}}\n}}\n"
            "MOTION\nFrames: 1\nFrame Time: 0.04\n" + " ".join(["0"] * 21) + "\n")
    p = tmp_path / f"figure_{up}_{forward}.bvh"
    p.write_text(text)
    return p


def figure_bones() -> BoneSkeleton:
    joints = {"ROOT": (0, 0, 10), "CHEST": (0, 0, 16), "L_HIP": (2, 0, 10), "L_KNEE": (2, 0, 5), "L_ANKLE": (2, 0, 0),
              "L_TOE": (2, -2, 0), "L_SHOULDER": (2, 0, 15), "L_ELBOW": (2, 0, 10)}
    return BoneSkeleton(joints, [Bone("ROOT", "CHEST", "SPINE"), Bone("ROOT", "L_HIP", "L_PELVIS"),
                                 Bone("L_HIP", "L_KNEE", "L_THIGH"), Bone("L_KNEE", "L_ANKLE", "L_SHIN"),
                                 Bone("L_ANKLE", "L_TOE", "L_FOOT"), Bone("L_SHOULDER", "L_ELBOW", "L_UPPERARM")])


@pytest.mark.parametrize("up, forward", [("y", "z"), ("z", "-y"), ("z", "x"), ("-x", "y"), ("y", "-x")])
def test_up_and_forward_axes_are_detected_despite_a_t_pose_arm(tmp_path, up, forward):
    bones = figure_bones()
    r = Retarget.build(bones, read_bvh(figure_clip(tmp_path, up, forward)))
    assert (r.up, r.forward) == (up, forward)
    assert np.allclose(r.axes, axes_matrix(up, forward))
    # the legs and spine agree with ours at rest; only the T-pose arm needed aligning
    absorbed = r.absorbed_degrees()
    assert absorbed["L_UPPERARM"] == pytest.approx(90) and absorbed["L_THIGH"] == pytest.approx(0, abs=1e-6)


def test_given_axes_are_kept_and_the_walk_is_detected_y_up(tmp_path):
    bones = figure_bones()
    r = Retarget.build(bones, read_bvh(figure_clip(tmp_path, "z", "-y")), up="z")
    assert (r.up, r.forward) == ("z", "-y")
    walk = Retarget.build(mannequin_bones(), read_bvh(WALK))
    assert (walk.up, walk.forward) == ("y", "z")
