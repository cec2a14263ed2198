"""#63 item 5: a clip is read as a biped, a quadruped or other, and drives only a rig of its own kind.

The report: a 3ds Max biped-named elephant (``Bip01_L_Thigh``, ``BN_Tail_01``) was mapped onto the
mannequin (HEAD <- a calf, R_THIGH <- the tail) with every plausibility check passing. No real
quadruped clip with a licence we can use is on hand, so the elephant (tests/written_clips.py) is written as such clips
are: 3ds Max's biped hierarchy (the thighs off the spine's first joint, the clavicles off the neck,
the front legs named as arms), a tail, Y up, trotting. The bipeds are the real clips of
tests/real_clips.py and ../shared's walk.bvh, also renamed into 3ds Max's biped scheme.
"""

from __future__ import annotations

import numpy as np
import pytest
from tests.paths import WALK

from real_clips import CLIPS, clip
from volanim_core.cli import main
from volanim_core.io.bvh_files import read_bvh
from volanim_core.motion.body import sample
from volanim_core.motion.kind import clip_kind
from volanim_core.motion.plausible import check_clip
from volanim_core.motion.retarget import Retarget
from volanim_core.samples import mannequin_bones
from written_clips import elephant_bvh


def test_the_elephant_is_a_quadruped_upright_or_on_its_side(tmp_path):
    for side in (False, True):
        elephant_bvh(tmp_path / "e.bvh", side=side)
        m = read_bvh(tmp_path / "e.bvh")
        kind = clip_kind(m, sample(m))
        assert kind.kind == "quadruped", kind


@pytest.mark.parametrize("name", ["walk", *sorted(CLIPS)])
def test_real_human_clips_are_bipeds(name):
    m = read_bvh(WALK if name == "walk" else clip(name))
    kind = clip_kind(m, sample(m))
    assert kind.kind == "biped", kind


def test_a_quadruped_clip_is_refused_for_the_mannequin_saying_why(tmp_path, capsys):
    """Before: mapped HEAD <- a calf, R_THIGH <- the tail, every check passing, frames written."""
    elephant_bvh(tmp_path / "elephant.bvh")
    bones = tmp_path / "m.bones"
    from volanim_core.io import write_bones

    write_bones(bones, mannequin_bones())
    assert main(["bvh2trans", str(tmp_path / "elephant.bvh"), "--bones", str(bones), "-o", str(tmp_path / "f")]) == 2
    out = capsys.readouterr()
    assert "# the clip's figure: quadruped: both pairs of limbs reach across the spine" in out.out
    assert "the clip's figure is a biped, as the rig: no (it is a quadruped: both pairs" in out.err
    assert not (tmp_path / "f").exists()
    r = Retarget.build(mannequin_bones(), read_bvh(tmp_path / "elephant.bvh"))
    got = {r.bones.bones[b].label: r.motion.names[k] for b, k in r.mapping.items()}
    assert "Tail" not in got.get("R_THIGH", "") and "Tail" not in got.get("L_THIGH", "")  # twins, not the tail
    assert main(["bvh2trans", str(tmp_path / "elephant.bvh"), "--bones", str(bones), "--no-check",
                 "-o", str(tmp_path / "f")]) == 0  # the user's call, said


BIP01 = {"Hips": "Pelvis", "Spine": "Spine", "Head": "Head", "Shoulder": "Clavicle", "Arm": "UpperArm",
         "ForeArm": "Forearm", "Hand": "Hand", "HandThumb1": "Finger0", "Hand_End": "Finger1", "UpLeg": "Thigh",
         "Leg": "Calf", "Foot": "Foot", "ToeBase": "Toe0"}


def _bip01(name: str, prefix: str, sep: str) -> str:
    for side, s in (("Left", "L"), ("Right", "R")):
        if name.startswith(side):
            return sep.join((prefix, s, BIP01[name[len(side):]]))
    return sep.join((prefix, BIP01[name]))


@pytest.mark.parametrize("prefix, sep", [("Bip01", " "), ("Bip001", "_")])
def test_the_real_walk_in_3ds_max_biped_names_maps_as_it_did(tmp_path, prefix, sep):
    """walk.bvh with every joint renamed as 3ds Max names it ("Bip01 L Thigh", names with spaces as
    Max writes and Blender reads them; "Bip001_L_Thigh") maps bone for bone as under its own names."""
    text = WALK.read_text()
    for old in sorted({t.split()[1] for t in text.splitlines() if t.split()[:1] in (["ROOT"], ["JOINT"])},
                      key=len, reverse=True):
        text = text.replace(f"T {old}\n", f"T {_bip01(old, prefix, sep)}\n")
    (tmp_path / "bip.bvh").write_text(text)
    bones = mannequin_bones()
    theirs = Retarget.build(bones, read_bvh(tmp_path / "bip.bvh"))
    ours = Retarget.build(bones, read_bvh(WALK))
    assert theirs.report["scheme"] == "3ds Max biped (Bip01)"
    named = {b: _bip01(ours.motion.names[k], prefix, sep) for b, k in ours.mapping.items()}
    assert {b: theirs.motion.names[k] for b, k in theirs.mapping.items()} == named
    assert all(how != "shape" for how in theirs.report["how"].values()), theirs.report["how"]
    checks, n = check_clip(theirs)
    assert all(c.ok for c in checks), [c.line(n) for c in checks]
    assert np.allclose(theirs.matrices(slice(0, 40, 10)), ours.matrices(slice(0, 40, 10)))


def test_sequence_refuses_the_quadruped_clip_too(tmp_path, capsys):
    """`volanim sequence` ran a .bvh with no check at all: the elephant would have been rendered as a person."""
    from tests.paths import ASSETS

    elephant_bvh(tmp_path / "elephant.bvh")
    argv = ["sequence", str(ASSETS / "mannequin.0.50.connect"), str(tmp_path / "elephant.bvh"), "--bones",
            str(ASSETS / "mannequin.bones"), "--frames", "0:4:2", "-o", str(tmp_path / "e.zarr")]
    assert main(argv) == 2
    assert "it is a quadruped" in capsys.readouterr().err and not (tmp_path / "e.zarr").exists()


ARM = ("Spine", "LeftShoulder", "LeftArm", "LeftForeArm", "LeftHand")  # a chest and one arm of the real walk


def arm_bvh(path) -> None:
    """One arm of the real walk as a capture of its own (hand and arm captures are common): the chest the
    root, moving as the walk's hips moved, the shoulder, arm, forearm and hand turning as they turned."""
    m = read_bvh(WALK)
    starts = np.cumsum([0] + [len(c) for c in m.channels])
    joints = [m.names.index(n) for n in ARM]
    lines, cols = ["HIERARCHY"], []
    for depth, j in enumerate(joints):
        pad = "\t" * depth
        lines += [f"{pad}{'ROOT' if depth == 0 else 'JOINT'} {m.names[j]}", pad + "{",
                  f"{pad}\tOFFSET " + " ".join(f"{v:.4f}" for v in (m.offsets[j] if depth else np.zeros(3)))]
        rot = [k for k, c in enumerate(m.channels[j]) if c.endswith("rotation")]
        names = [m.channels[j][k].capitalize() for k in rot]
        lines.append(f"{pad}\tCHANNELS {len(rot) + 3 * (depth == 0)} "
                     + ("Xposition Yposition Zposition " if depth == 0 else "") + " ".join(names))
        cols.append((depth == 0, [starts[j] + k for k in rot]))
    pad = "\t" * len(joints)
    lines += [pad + "End Site", pad + "{", pad + "\tOFFSET 5.0 0.0 0.0", pad + "}"]
    lines += ["\t" * d + "}" for d in reversed(range(len(joints)))]
    lines += ["MOTION", f"Frames: {m.frames}", f"Frame Time: {m.frame_time:.6f}"]
    for row in m.values:
        values = []
        for root, c in cols:
            values += (list(row[:3]) if root else []) + list(row[c])  # the hips' Xposition Yposition Zposition
        lines.append(" ".join(f"{v:.4f}" for v in values))
    path.write_text("\n".join(lines) + "\n")


def test_a_one_arm_clip_with_map_drives_the_mapped_arm_and_leaves_the_rest_at_rest(tmp_path, capsys):
    """#86 item 3: the arm clip with an explicit --map was refused ("other: no pair of twin limbs"), and the
    refusal told the user to give --map. The map is the user's word: only its chains are checked."""
    from volanim_core.io import write_bones
    from volanim_core.io.frame_files import read_frames

    arm_bvh(tmp_path / "arm.bvh")
    write_bones(tmp_path / "m.bones", mannequin_bones())
    (tmp_path / "arm.map").write_text("L_CLAVICLE LeftShoulder\nL_UPPERARM LeftArm\nL_FOREARM LeftForeArm\n"
                                      "L_HAND LeftHand\n")
    assert main(["bvh2trans", str(tmp_path / "arm.bvh"), "--bones", str(tmp_path / "m.bones"),
                 "--map", str(tmp_path / "arm.map"), "-o", str(tmp_path / "f")]) == 0
    bones = mannequin_bones()
    mats, paths = read_frames(tmp_path / "f", bones)
    assert len(paths) == read_bvh(WALK).frames
    r = mats[:, :, :3, :3]
    assert np.allclose(r @ np.swapaxes(r, -1, -2), np.eye(3), atol=1e-5)  # rigid
    moved = {b.label for k, b in enumerate(bones.bones) if not np.allclose(mats[:, k], np.eye(4), atol=1e-6)}
    assert moved == {"L_CLAVICLE", "L_UPPERARM", "L_FOREARM", "L_HAND"}, moved  # the rest stays at rest


def test_a_one_arm_clip_without_map_is_refused_showing_a_map_that_would_work(tmp_path, capsys):
    from volanim_core.io import write_bones

    arm_bvh(tmp_path / "arm.bvh")
    write_bones(tmp_path / "m.bones", mannequin_bones())
    assert main(["bvh2trans", str(tmp_path / "arm.bvh"), "--bones", str(tmp_path / "m.bones"),
                 "-o", str(tmp_path / "f")]) == 2
    err = capsys.readouterr().err
    assert "it is other" in err and "part of a body" in err
    assert "L_UPPERARM LeftArm" in err and "--map" in err  # a map file that would work, shown
    assert not (tmp_path / "f").exists()
