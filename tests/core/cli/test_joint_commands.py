"""``--joints smooth`` from the command line (#42): the mannequin's hip flexed 90 degrees breaks with rigid
joints and not with smooth ones, in ``report``, ``scan``, ``connect2tskel`` + ``reconstruct`` and ``sequence``."""

from __future__ import annotations

import json

import numpy as np
import pytest

from runnable import volanim
from volanim_core import io, samples
from volanim_core.reconstruct.engine import reconstruct
from volanim_core.rig.connectivity import Trans
from volanim_core.rig.pose import pose_matrices, root_bones
from volanim_core.rig.skinning import Joints


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    d = tmp_path_factory.mktemp("joints")
    s = samples.mannequin()
    io.write_connect(d / "m.connect", samples.part_connectivity(s))  # every point on the part it lies in
    io.write_bones(d / "m.bones", s.bones)
    for name, angle in (("hip90", -90), ("hip30", -30)):
        mats = pose_matrices(s.bones, {"L_THIGH": (angle, 0, 0)})
        io.write_trans(d / f"{name}.trans", Trans(root_bones(s.bones), mats))
    return d


def test_report_rigid_finds_the_hips_breakage_and_smooth_joints_close_it(made):
    rigid = volanim("report", made / "m.connect", made / "hip90.trans", "--bones", made / "m.bones", "--json")
    assert rigid.returncode == 1, rigid.stderr  # broken: a stump at the hip, cracks
    r = json.loads(rigid.stdout)
    assert r["stumps"] and r["stumps"][0]["near"] == "L_HIP" and r["cracks"] > 10
    smooth = volanim("report", made / "m.connect", made / "hip90.trans", "--bones", made / "m.bones", "--json",
                     "--joints", "smooth")
    assert smooth.returncode == 0, smooth.stdout + smooth.stderr
    s = json.loads(smooth.stdout)
    assert s["healthy"] and s["cracks"] == 0 and not s["stumps"] and len(s["components"]) == 1
    assert abs(s["loss_percent"]) < 3.0


def test_scan_with_smooth_joints(made):
    frames = [made / "hip30.trans", made / "hip90.trans"]
    rigid = volanim("scan", made / "m.connect", *frames, "--json")
    assert rigid.returncode == 1
    assert [v["frame"] for v in json.loads(rigid.stdout) if v["broken"]] == [90]  # numbered by the names
    smooth = volanim("scan", made / "m.connect", *frames, "--json", "--joints", "smooth", "--blend", "1")
    assert smooth.returncode == 0, smooth.stdout + smooth.stderr
    assert all(v["cracks"] == 0 and v["stump"] == 0 for v in json.loads(smooth.stdout))


# spec: docs/formats.md#joints
def test_connect2tskel_records_smooth_joints_and_reconstruct_follows_them(made):
    out = volanim("connect2tskel", made / "m.connect", made / "hip90.trans", "--joints", "smooth", "--blend", "1.5",
                  "-o", made / "hip.tskel")
    assert out.returncode == 0, out.stderr
    text = (made / "hip.tskel").read_text()
    assert "\n# joints: smooth 1.5\n" in text
    t = io.read_tskel(made / "hip.tskel")
    assert t.joints == Joints("smooth", 1.5)
    assert volanim("reconstruct", made / "hip.tskel", "--mode", "bone", "-o", made / "hip.vti").returncode == 0
    assert volanim("reconstruct", made / "hip.tskel", "--mode", "bone", "--joints", "rigid",
                   "-o", made / "hip-rigid.vti").returncode == 0
    smooth, rigid = (io.read_volume(made / n) for n in ("hip.vti", "hip-rigid.vti"))
    conn = io.read_connect(made / "m.connect")
    expect = reconstruct(conn.with_joints(Joints("smooth", 1.5)).posed(t.matrices), mode="bone").volume
    np.testing.assert_array_equal(smooth, expect)
    assert (rigid > 0).sum() < (smooth > 0).sum()  # the rigid hip's crack is empty voxels


# spec: docs/formats.md#joints
def test_a_file_without_the_line_is_rigid_and_rigid_files_stay_as_they_were(made):
    out = volanim("connect2tskel", made / "m.connect", made / "hip30.trans", "-o", made / "plain.tskel")
    assert out.returncode == 0 and "rigid joints" in out.stdout
    assert "# joints" not in (made / "plain.tskel").read_text()
    assert io.read_tskel(made / "plain.tskel").joints == Joints()


@pytest.mark.parametrize("args, words", [
    (("--joints", "rigid", "--blend", "2"), "means nothing with --joints rigid"),
    (("--blend", "wide"), "--blend must be a number"),
    (("--blend", "-1"), "must be a positive number"),
])
def test_bad_joint_options_are_refused(made, args, words):
    out = volanim("report", made / "m.connect", made / "hip30.trans", *args)
    assert out.returncode == 2 and words in out.stderr


def test_a_bad_joints_line_names_the_file_and_line(made, tmp_path):
    text = (made / "m.connect").read_text().replace("# metric: euclid", "# metric: euclid\n# joints: springy")
    (tmp_path / "bad.connect").write_text(text)
    out = volanim("report", tmp_path / "bad.connect", made / "hip30.trans")
    assert out.returncode == 2
    assert "bad.connect:5:" in out.stderr and "'rigid' or 'smooth'" in out.stderr
