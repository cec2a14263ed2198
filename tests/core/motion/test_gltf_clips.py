"""glTF clips (#88) through the commands that take BVH: a real VRM humanoid animation (pixiv's, MIT) onto the
mannequin, named by its VRM bone names, its arm turned as the file turns it; Khronos' Fox walking Spot the
cow (a real animal clip onto a scanned quadruped)."""

from __future__ import annotations

import numpy as np

from paths import ASSETS, FOX, GLTF
from volanim_core.cli import main
from volanim_core.io import read_bones, read_trans
from volanim_core.io.clip_files import read_clip


def _turn(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.degrees(np.arccos(np.clip(a @ b / np.linalg.norm(a) / np.linalg.norm(b), -1, 1))))


def test_a_vrm_animation_drives_the_mannequins_arm_as_far_as_the_file_turns_it(tmp_path, capsys):
    out = tmp_path / "vrma"
    assert main(["bvh2trans", str(GLTF / "test.vrma"), "--bones", str(ASSETS / "mannequin.bones"),
                 "--frames", "0:16:15", "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "naming scheme: VRM / Unity humanoid" in text and "R_UPPERARM rightUpperArm  # name and shape" in text
    assert "wrote 2 frames (30.0 fps in the clip" in text
    clip = read_clip(GLTF / "test.vrma")
    _, pos = clip.forward_kinematics()
    arm, elbow = clip.index("rightUpperArm"), clip.index("rightLowerArm")
    theirs = _turn(pos[0, elbow] - pos[0, arm], pos[15, elbow] - pos[15, arm])  # the file's arm, 0 -> 0.5 s
    bones = read_bones(ASSETS / "mannequin.bones")
    b = bones.index("R_UPPERARM")
    seg = bones.bones[b]

    def direction(path):
        m = read_trans(path).matrices[b]
        ends = np.c_[np.array([bones.joints[seg.proximal], bones.joints[seg.distal]]), np.ones(2)] @ m
        return ends[1, :3] - ends[0, :3]

    ours = _turn(direction(out / "test.0000.trans"), direction(out / "test.0015.trans"))
    assert theirs > 60 and abs(ours - theirs) < 1.0, (ours, theirs)


def test_sequence_takes_a_gltf_clip_and_its_animation_by_name(tmp_path, capsys):
    assert main(["sequence", str(ASSETS / "mannequin.0.50.connect"), str(FOX), "--animation", "Trot",
                 "--bones", str(ASSETS / "mannequin.bones"), "-o", str(tmp_path / "s.zarr")]) == 2
    assert "has no animation 'Trot'; it has Survey, Walk, Run" in capsys.readouterr().err
    assert main(["sequence", str(ASSETS / "mannequin.0.50.connect"), str(GLTF / "test.vrma"), "--frames", "0:31:15",
                 "--bones", str(ASSETS / "mannequin.bones"), "--workers", "1", "-o", str(tmp_path / "v.zarr")]) == 0
    assert "3 frames" in capsys.readouterr().out
