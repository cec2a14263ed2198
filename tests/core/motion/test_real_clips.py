"""Real clips of five naming styles (#39): each lands upright, mapped limb to limb and to scale.

The clips are other projects' files (tests/real_clips.py). What is asserted is read off the clip
itself, independently of the retarget: which way its own figure's head, feet and left hand are
(its forward kinematics), its leg length in its own units, and the naming scheme it uses.
"""

from __future__ import annotations

import numpy as np
import pytest

from real_clips import clip
from small_rigs import posed_joints
from volanim_core.io.bvh_files import read_bvh
from volanim_core.motion.plausible import check_clip
from volanim_core.motion.retarget import Retarget
from volanim_core.samples import mannequin_bones

# clip -> (scheme, units, what the clip names its parts: L_UPPERARM, L_CLAVICLE, L_THIGH, L_SHIN)
EXPECTED = {
    "lafan_test": ("Mixamo / CMU / LAFAN", "centimetres", ("LeftArm", "LeftShoulder", "LeftUpLeg", "LeftLeg")),
    "lafan_test2": ("Mixamo / CMU / LAFAN", "centimetres", ("LeftArm", "LeftShoulder", "LeftUpLeg", "LeftLeg")),
    "blender": ("Blender .L/.R", "metres", ("upper_arm.L", "shoulder.L", "thigh.L", "shin.L")),
    "mocapbank": ("Biovision / MocapBank", "centimetres", ("LeftShoulder", "LeftCollar", "LeftHip", "LeftKnee")),
    "mixamo": ("Mixamo / CMU / LAFAN", "centimetres",
               ("mixamorig:LeftArm", "mixamorig:LeftShoulder", "mixamorig:LeftUpLeg", "mixamorig:LeftLeg")),
}
# the clip's own joints for our PELVIS, HEAD-end, L_WRIST-ish and L_ANKLE, to compare directions with
OWN = {"lafan_test": ("Hips", "Head", "LeftForeArm", "LeftFoot"),
       "lafan_test2": ("Hips", "Head", "LeftForeArm", "LeftFoot"),
       "blender": ("pelvis", "face", "forearm.L", "foot.L"),
       "mocapbank": ("Hips", "Head", "LeftElbow", "LeftAnkle"),
       "mixamo": ("mixamorig:Hips", "mixamorig:Head", "mixamorig:LeftForeArm", "mixamorig:LeftFoot")}


@pytest.fixture(scope="module")
def bones():
    return mannequin_bones()


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_a_real_clip_is_mapped_limb_to_limb_in_its_own_scheme(bones, name):
    scheme, units, (upper, clavicle, thigh, shin) = EXPECTED[name]
    r = Retarget.build(bones, read_bvh(clip(name)))
    got = {bones.bones[b].label: r.motion.names[k] for b, k in r.mapping.items()}
    assert r.report["scheme"] == scheme
    assert (got["L_UPPERARM"], got["L_CLAVICLE"], got["L_THIGH"], got["L_SHIN"]) == (upper, clavicle, thigh, shin)
    assert got["R_THIGH"] == thigh.replace("Left", "Right").replace(".L", ".R")
    assert r.report["units"] == units


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_a_real_clip_lands_upright_to_scale_and_faces_as_its_own_figure(bones, name):
    motion = read_bvh(clip(name))
    r = Retarget.build(bones, motion)
    checks, n = check_clip(r)
    assert n > 1 and all(c.ok for c in checks), [c.line(n) for c in checks]
    assert (r.up, r.forward) == ("y", "z")  # every one of these is Y-up facing +Z in its calibration pose
    frames = np.unique(np.linspace(0, motion.frames - 1, 24).round().astype(int))
    mats = r.matrices(frames)
    _, own = motion.forward_kinematics(frames)
    pelvis, head, arm, foot = (motion.index(j) for j in OWN[name])
    lengths = {b: np.linalg.norm(bones.joints[x.distal] - bones.joints[x.proximal]) for b, x in enumerate(bones.bones)}
    agree = []
    for f in range(len(frames)):
        posed = posed_joints(bones, mats[f])  # also asserts no joint is torn apart
        for b, x in enumerate(bones.bones):  # bone lengths are ours, in every frame
            assert np.linalg.norm(posed[x.distal] - posed[x.proximal]) == pytest.approx(lengths[b], rel=1e-6)
        for ours, theirs in (("HEAD", head), ("L_ELBOW", arm), ("L_ANKLE", foot)):
            a = posed[ours] - posed["PELVIS"]
            b = r.axes @ (own[f, theirs] - own[f, pelvis])
            agree.append(a @ b / np.linalg.norm(a) / np.linalg.norm(b))
    # our head, left elbow and left ankle lie where the clip's own do, seen from the pelvis
    assert np.median(agree) > 0.9 and np.mean(np.array(agree) > 0.5) > 0.9, np.round(agree, 2)
    # to scale: the root's travel is the clip's, times our leg over its leg
    travel = np.linalg.norm(posed_joints(bones, mats[-1])["PELVIS"] - posed_joints(bones, mats[0])["PELVIS"])
    assert travel == pytest.approx(np.linalg.norm(own[-1, 0] - own[0, 0]) * r.scale, rel=1e-6, abs=1e-6)


def test_lafan_lies_along_x_at_rest_and_is_measured_at_a_standing_frame(bones):
    motion = read_bvh(clip("lafan_test"))
    rest = motion.rest_positions()
    assert np.ptp(rest[:, 0]) > np.ptp(rest[:, 1])  # the OFFSET pose: not standing up y
    r = Retarget.build(bones, motion)
    assert r.reference is not None and "frame" in r.report["axes"]
    # our thigh + shin over the clip's, both read off the files here (the issue: 32.8 before)
    ours = sum(np.linalg.norm(np.subtract(bones.joints[a], bones.joints[b]))
               for a, b in (("L_HIP", "L_KNEE"), ("L_KNEE", "L_ANKLE")))
    theirs = sum(np.linalg.norm(motion.offsets[motion.index(j)]) for j in ("LeftLeg", "LeftFoot"))
    assert r.scale == pytest.approx(ours / theirs, rel=0.02)  # the mean of both legs: within 2 % of the left
    assert abs(r.scale - 32.8) > 30


def test_a_wrong_up_axis_is_refused_with_the_suspect_named(tmp_path, bones, capsys):
    from volanim_core.cli import main

    out = tmp_path / "frames"
    assert main(["bvh2trans", str(clip("lafan_test")), "--bones", str(_bones_file(tmp_path, bones)),
                 "--frames", "0:50:25", "--up", "x", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "head above pelvis in only" in err and "suspect the up axis" in err and not out.exists()
    assert main(["bvh2trans", str(clip("lafan_test")), "--bones", str(_bones_file(tmp_path, bones)),
                 "--frames", "0:50:25", "--up", "x", "--no-check", "-o", str(out)]) == 0
    assert len(list(out.glob("*.trans"))) == 2


def _bones_file(tmp_path, bones):
    from volanim_core import io

    path = tmp_path / "m.bones"
    io.write_bones(path, bones)
    return path


@pytest.mark.parametrize("name", ["mocapbank", "lafan_test2", "blender"])
def test_a_clip_whose_names_mean_nothing_is_mapped_by_shape_alone(tmp_path, bones, name):
    """Every joint renamed J0, J1, ...: the hierarchy, the lengths and the motion still place the limbs."""
    import re

    text = clip(name).read_text()
    named = read_bvh(clip(name))
    for k, joint in enumerate(named.names):
        text = re.sub(rf"(ROOT|JOINT)\s+{re.escape(joint)}\s*\n", rf"\1 J{k}\n", text, count=1)
    (tmp_path / "anon.bvh").write_text(text)
    anon = read_bvh(tmp_path / "anon.bvh")
    assert anon.names == [f"J{k}" for k in range(len(named.names))]
    by_name = Retarget.build(bones, named)
    by_shape = Retarget.build(bones, anon)
    assert by_shape.report["scheme"] == "none"
    assert set(by_shape.report["how"].values()) <= {"shape", "the root"}
    # limbs to the same limbs as the names say (the head may sit a joint apart: Neck vs Head)
    for label in ("L_UPPERARM", "L_FOREARM", "R_UPPERARM", "R_FOREARM", "L_THIGH", "L_SHIN", "R_THIGH", "R_SHIN"):
        b = bones.index(label)
        assert by_shape.mapping[b] == by_name.mapping[b], label
    checks, n = check_clip(by_shape)
    assert all(c.ok for c in checks), [c.line(n) for c in checks]
