"""The timeline model (no Qt): keys with undo, frames driving the pose, clips, and projects keeping it all."""

from __future__ import annotations

import json

import numpy as np
import pytest

from paths import FOX, HUESITOS, WALK  # WALK: the real clip, bundled with its MIT licence
from volanim_core import samples
from volanim_core.errors import FormatError
from volanim_core.io.frame_files import write_frames
from volanim_core.rig.key_pose import KeyPose
from volanim_studio.model import Document
from volanim_studio.model.project import apply_project, read_project


@pytest.fixture
def doc():
    d = Document()
    d.bone_edits.set_bones(samples.mannequin_bones())
    d.undo.clear()
    return d


def arm(doc):
    return doc.bones.index("L_UPPERARM")


def test_keys_are_undoable_and_frames_between_them_interpolate(doc):
    tl, st = doc.timeline, doc.settings
    tl.set_key(0)
    st.current_frame = 20
    doc.pose.set_angles(arm(doc), (0, -80, 0))
    tl.set_key()
    assert sorted(tl.keys) == [0, 20] and doc.undo.undo_label == "Set key at frame 20"
    tl.set_options(ease=False)
    st.current_frame = 10
    assert np.allclose(doc.pose.angles_of(arm(doc)), (0, -40, 0))  # halfway, shown on the sliders
    edits = doc.undo.edits
    st.current_frame = 5
    assert doc.undo.edits == edits  # scrubbing is not an edit
    doc.undo.undo()  # the key at 20 goes: frame 5 shows the only key left (rest)
    assert sorted(tl.keys) == [0] and doc.pose.is_rest
    doc.undo.redo()
    assert np.allclose(doc.pose.angles_of(arm(doc)), (0, -20, 0))
    tl.delete_key(0)
    assert sorted(tl.keys) == [20] and np.allclose(doc.pose.angles_of(arm(doc)), (0, -80, 0))
    with pytest.raises(ValueError, match="no key at frame 3"):
        tl.delete_key(3)


def test_stepping_wraps_and_the_length_covers_every_key(doc):
    tl = doc.timeline
    tl.set_key(60)
    assert tl.frame_count == 61
    tl.set_options(length=100)
    assert tl.frame_count == 100 and tl.step(-1) == 99 and tl.step(2) == 1
    with pytest.raises(ValueError, match="length"):
        tl.set_options(length=0)


def test_a_bvh_clip_drives_the_pose_and_keys_wait_for_it_to_unload(doc):
    tl = doc.timeline
    r = tl.load_bvh(WALK)
    assert tl.frame_count == 1064 and tl.frame_rate == pytest.approx(r.motion.fps) and (r.up, r.forward) == ("y", "z")
    doc.settings.current_frame = 500
    assert np.allclose(doc.pose.matrices(), tl.matrices([500])[0], atol=1e-6)
    with pytest.raises(ValueError, match="unload it"):
        tl.set_key()
    # editing the bones retargets the clip onto the new skeleton (FK keeps our new bone length)
    wrist = doc.bones.joints["L_WRIST"].copy()
    doc.bone_edits.move_joint("L_WRIST", wrist + [0, 0, -5])
    assert tl.clip is not None and tl.matrices([500]).shape == (1, 18, 4, 4)
    tl.unload()
    assert tl.clip is None and tl.frame_count == 48
    tl.set_key()


def test_a_trans_folder_becomes_the_clip_in_frame_order(doc, tmp_path):
    mats = np.stack([doc.pose.matrices()] * 3)
    mats[:, :, 3, 0] += np.array([0.0, 5.0, 10.0])[:, None]
    write_frames(tmp_path / "f", "walk", doc.bones, mats, [8, 10, 12])
    clip = doc.timeline.load_trans(tmp_path / "f")
    assert clip.frames == [8, 10, 12] and doc.timeline.frame_number(2) == 12
    doc.settings.current_frame = 2
    assert np.allclose(doc.pose.matrices(), mats[2], atol=1e-5)
    doc.bone_edits.move_joint("L_WRIST", doc.bones.joints["L_WRIST"] + [0, 0, -5])
    assert doc.timeline.clip is None  # its frames were made for the old bones


def test_a_project_keeps_keys_options_and_the_clip(doc, tmp_path):
    tl = doc.timeline
    doc.pose.set_angles(arm(doc), (0, -30, 0))
    tl.set_key(12)
    tl.set_options(ease=False, length=90, fps=30)
    doc.write_project(tmp_path / "anim.volanim")
    other = Document()
    apply_project(other, read_project(tmp_path / "anim.volanim"), tmp_path / "anim.volanim")
    t2 = other.timeline
    assert sorted(t2.keys) == [12] and (t2.ease, t2.length, t2.fps) == (False, 90, 30.0)
    assert np.allclose(t2.keys[12].angles[("L_SHOULDER", "L_ELBOW")], (0, -30, 0))

    tl.load_bvh(WALK)
    doc.write_project(tmp_path / "walk.volanim")
    other = Document()
    apply_project(other, read_project(tmp_path / "walk.volanim"), tmp_path / "walk.volanim")
    assert other.timeline.clip is not None and other.timeline.frame_count == 1064


def test_one_animation_of_a_gltf_file_is_the_clip_and_the_project_keeps_which(doc, tmp_path):
    doc.timeline.load_bvh(FOX, animation="Walk")  # Khronos' Fox: Survey, Walk, Run
    assert (doc.timeline.clip.animation, doc.timeline.frame_count, doc.timeline.frame_rate) == ("Walk", 18, 24.0)
    doc.write_project(tmp_path / "fox.volanim")
    other = Document()
    apply_project(other, read_project(tmp_path / "fox.volanim"), tmp_path / "fox.volanim")
    assert other.timeline.clip.animation == "Walk" and other.timeline.frame_count == 18
    assert np.allclose(other.timeline.matrices([9]), doc.timeline.matrices([9]))


def test_an_fbx_clip_drives_the_bones_its_map_names_and_leaves_the_others_at_rest(doc):
    arms = {"SPINE": "Bone.001", "L_UPPERARM": "Bone.004", "L_FOREARM": "Bone.005", "L_HAND": "Bone.006",
            "R_UPPERARM": "Bone.003", "R_FOREARM": "Bone.007", "R_HAND": "Bone.008"}
    doc.timeline.load_bvh(HUESITOS, mapping=arms)  # assimp's huesitos.fbx: a trunk forking into two arms
    tl = doc.timeline
    assert (tl.clip.animation, tl.frame_count, tl.frame_rate) == ("Armature|Action", 40, 25.0)
    m = tl.matrices([20])[0]
    arm_turn = m[arm(doc), :3, :3] @ np.linalg.inv(m[doc.bones.index("SPINE"), :3, :3])
    assert not np.allclose(arm_turn, np.eye(3), atol=1e-2)  # the arm swings against the spine
    assert not np.allclose(m[doc.bones.index("SPINE")], np.eye(4), atol=1e-2)  # the trunk leans the spine
    for leg in ("L_THIGH", "R_THIGH", "L_SHIN"):  # what the map leaves out stays at rest
        assert np.allclose(m[doc.bones.index(leg)], np.eye(4))


def test_a_missing_clip_is_a_warning_and_a_bad_timeline_names_the_project(doc, tmp_path):
    clip = tmp_path / "gone.bvh"
    clip.write_bytes(WALK.read_bytes())
    doc.timeline.load_bvh(clip)
    doc.write_project(tmp_path / "p.volanim")
    clip.unlink()
    other = Document()
    warnings = apply_project(other, read_project(tmp_path / "p.volanim"), tmp_path / "p.volanim")
    assert any("clip was not loaded" in w and "gone.bvh" in w for w in warnings)

    data = json.loads((tmp_path / "p.volanim").read_text())
    for bad in ({"keys": {"x": []}}, {"keys": {"3": [["A", "B", 1, 2, 3]]}}, {"fps": 0}, {"ease": "yes"},
                {"clip": {"kind": "avi", "path": "x"}}):
        data["timeline"] = bad
        (tmp_path / "bad.volanim").write_text(json.dumps(data))
        with pytest.raises(FormatError, match="bad.volanim"):
            read_project(tmp_path / "bad.volanim")
    assert KeyPose.from_json([], "k").angles == {}


def test_exported_keys_make_the_timeline_frames_on_the_command_line(doc, tmp_path):
    from volanim_core import io
    from volanim_core.cli import main

    tl, st = doc.timeline, doc.settings
    tl.set_key(0)
    st.current_frame = 9
    doc.pose.set_angles(arm(doc), (10, -70, 5))
    doc.pose.set_angles(doc.bones.index("SPINE"), (0, 0, 12))
    tl.set_key()
    st.current_frame = 15
    tl.set_key()  # a hold
    tl.set_options(ease=True, length=20, fps=30)
    assert tl.export_keys(tmp_path / "a.keys") == 3
    io.write_bones(tmp_path / "m.bones", doc.bones)
    assert main(["keys", str(tmp_path / "a.keys"), "--bones", str(tmp_path / "m.bones"), "-o",
                 str(tmp_path / "out")]) == 0
    files = sorted((tmp_path / "out").glob("*.trans"))
    assert len(files) == 20  # the timeline's length, at its own rate
    written = np.stack([io.read_trans(f).matrices for f in files])
    assert np.allclose(written, tl.matrices(), atol=1e-6)
    # and back into a fresh timeline: the same keys and options, one undo step
    other = Document()
    other.bone_edits.set_bones(samples.mannequin_bones())
    other.undo.clear()
    assert other.timeline.import_keys(tmp_path / "a.keys") == 3
    assert (other.timeline.ease, other.timeline.length, other.timeline.fps) == (True, 20, 30.0)
    assert np.allclose(other.timeline.matrices(), tl.matrices(), atol=1e-9)
    other.undo.undo()
    assert not other.timeline.keys
