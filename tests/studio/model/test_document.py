"""The studio's document model and modes, without Qt."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core import io, samples
from volanim_core.errors import FormatError
from volanim_studio.model import Document
from volanim_studio.model.interaction import BonesMode, PickEvent, RootOrderMode
from volanim_studio.model.project import read_project


def point_near(doc, xyz):
    return int(np.argmin(((doc.skeleton.points - np.asarray(xyz)) ** 2).sum(1)))


def test_thinness_events_and_visible_count(doc):
    seen = []
    doc.events.thinness.connect(lambda value: seen.append(value))
    doc.thinness = 0.8
    assert seen == [0.8]
    assert doc.visible_count == int((doc.skeleton.thinness >= 0.8).sum())
    doc.thinness = 0.8  # unchanged: no event
    assert seen == [0.8]
    with pytest.raises(ValueError, match="finite"):
        doc.thinness = float("nan")


def test_bones_mode_builds_a_chain_and_undo_redo(doc):
    mode = BonesMode(doc)
    a, b, c = (point_near(doc, p) for p in [(108, 50, 226), (124, 50, 178), (139, 50, 133)])
    for p in (a, b, c):
        mode.press(PickEvent(point=p))
    assert len(doc.bones) == 2
    j = doc.bones.joints
    b0, b1 = doc.bones.bones
    assert b0.distal == b1.proximal  # A-B-C: the chain continues from B
    assert np.array_equal(j[b0.proximal], doc.skeleton.points[a])
    assert np.array_equal(j[b1.distal], doc.skeleton.points[c])
    assert all(n.startswith("L_") for n in j)  # x > mid-plane: named as left
    mode.key("Escape")
    mode.press(PickEvent(point=point_near(doc, (79, 50, 140))))
    mode.press(PickEvent(joint=b0.proximal))  # ends on an existing joint: reused, not duplicated
    assert len(doc.bones.joints) == 4 and len(doc.bones) == 3
    assert doc.undo.undo() is not None
    assert len(doc.bones) == 2
    assert doc.undo.redo() is not None
    assert len(doc.bones) == 3
    doc.select_bones([2])
    mode.key("Delete")
    assert len(doc.bones) == 2 and len(doc.bones.joints) == 3


def test_remove_toggle_and_errors(doc):
    mode = BonesMode(doc)
    mode.press(PickEvent(point=point_near(doc, (108, 50, 226))))
    mode.press(PickEvent(point=point_near(doc, (124, 50, 178))))
    mode.remove = True
    mode.press(PickEvent(bone=0))
    assert len(doc.bones) == 0 and not doc.bones.joints
    messages = []
    doc.events.message.connect(lambda text: messages.append(text))
    mode.remove = False
    mode.press(PickEvent())
    assert "No skeleton point" in messages[-1]


def test_root_order_mode(doc):
    s = samples.mannequin()
    doc.bone_edits.set_bones(s.bones)
    mode = RootOrderMode(doc)
    mode.enter()
    labels = [b.label for b in doc.bones.bones]
    mode.press(PickEvent(bone=labels.index("L_THIGH")))
    mode.press(PickEvent(bone=[b.label for b in doc.bones.bones].index("HEAD")))
    order = [b.label for b in doc.bones.bones]
    assert order[:2] == ["L_THIGH", "HEAD"]
    assert [x for x in order[2:]] == [x for x in labels if x not in ("L_THIGH", "HEAD")]
    doc.undo.undo()
    assert [b.label for b in doc.bones.bones][0] == "L_THIGH"


def test_rename_and_validation(doc):
    doc.bone_edits.add_bone((100, 50, 200), (110, 50, 180))
    j = list(doc.bones.joints)[0]
    doc.bone_edits.rename_joint(j, "L_SHOULDER")
    assert "L_SHOULDER" in doc.bones.joints and doc.bones.bones[0].proximal == "L_SHOULDER"
    with pytest.raises(ValueError, match="spaces"):
        doc.bone_edits.rename_joint("L_SHOULDER", "left shoulder")
    doc.bone_edits.rename_bone(0, "L_UPPERARM")
    assert doc.bones.bones[0].label == "L_UPPERARM"
    with pytest.raises(ValueError, match="already a bone"):
        doc.bone_edits.add_bone("L_SHOULDER", list(doc.bones.joints)[1])
    with pytest.raises(ValueError, match="permutation"):
        doc.bone_edits.set_root_order([0, 0])


def test_symmetrize_left_arm_into_right(doc):
    s = samples.mannequin()
    J = s.bones.joints
    mode = BonesMode(doc)
    for name in ("L_SHOULDER", "L_ELBOW", "L_WRIST"):
        mode.press(PickEvent(point=point_near(doc, J[name])))
    for old, new in zip(list(doc.bones.joints), ("L_SHOULDER", "L_ELBOW", "L_WRIST")):
        doc.bone_edits.rename_joint(old, new)
    doc.select_bones([0, 1])
    written = doc.bone_edits.symmetrize()
    assert set(written) == {"R_SHOULDER", "R_ELBOW", "R_WRIST"}
    assert len(doc.bones) == 4
    for name in ("SHOULDER", "ELBOW", "WRIST"):
        left, right = doc.bones.joints[f"L_{name}"], doc.bones.joints[f"R_{name}"]
        assert np.allclose([159 - left[0], left[1], left[2]], right)  # mirrored about x = 79.5
    doc.select_bones([0])
    doc.bone_edits.symmetrize()  # again: updates, does not duplicate
    assert len(doc.bones) == 4
    doc.undo.undo()
    doc.undo.undo()
    assert len(doc.bones) == 2


def test_project_round_trip(tmp_path, doc):
    io.write_volume(tmp_path / "m.VOL", doc.volume)
    seg = {"lo": 1, "hi": 255, "fill": True, "metric": "345", "min_thinness": 0.25, "spacing": [1.0, 1.0, 2.5],
           "series": None}
    doc.set_volume(doc.volume, doc.mask, path=tmp_path / "m.VOL", segmentation=seg)
    doc.bone_edits.add_bone((100, 50, 200), (110, 50, 180))
    doc.thinness = 0.7
    doc.settings.cube_size = 31
    doc.settings.preview_mode = "hotspot"
    cam = {"position": [1.0, 2.0, 3.0], "focal_point": [0.0, 0.0, 0.0], "view_up": [0.0, 0.0, 1.0]}
    doc.set_camera(cam)
    path = doc.save_project(tmp_path / "session.volanim")
    data = read_project(path)
    assert data["volume"] == str((tmp_path / "m.VOL").resolve())
    assert io.read_bones(data["bones"]) == doc.bones
    assert io.read_mskel(data["mskel"]) == doc.skeleton
    assert data["state"]["thinness"] == 0.7 and data["state"]["camera"] == cam
    assert data["segmentation"] == seg  # every segmentation parameter, so reopening segments the same way
    assert data["settings"]["cube_size"] == 31 and data["settings"]["preview_mode"] == "hotspot"
    (tmp_path / "bad.volanim").write_text("{nope")
    with pytest.raises(FormatError, match="bad.volanim:1: not a volanim project"):
        read_project(tmp_path / "bad.volanim")


def test_the_pose_is_saved_with_the_project_and_comes_back(tmp_path, doc):
    """Issue #37: pose L_UPPERARM to y -44, save, reopen: the angles were 0, 0, 0 (the pose was never saved)."""
    from volanim_studio.model.project import apply_project

    doc.bone_edits.set_bones(samples.mannequin_bones())
    arm, hip = doc.bones.index("L_UPPERARM"), doc.bones.index("L_THIGH")
    doc.pose.set_angles(arm, (0, -44, 0))
    doc.pose.set_angles(hip, (10, 0, 5))
    path = doc.save_project(tmp_path / "posed.volanim")
    fresh = Document()
    fresh.set_skeleton(doc.skeleton)
    assert apply_project(fresh, read_project(path), path) == []
    assert np.allclose(fresh.pose.angles_of(arm), (0, -44, 0)) and np.allclose(fresh.pose.angles_of(hip), (10, 0, 5))
    assert np.allclose(fresh.pose.matrices(), doc.pose.matrices())
    assert not fresh.undo.can_undo  # reopening is not an edit
    # a saved pose of a bone that no longer exists is dropped, and said
    data = read_project(path)
    data["state"]["pose"][0][("NOPE", "NADA")] = np.array([1.0, 2.0, 3.0])
    other = Document()
    other.set_skeleton(doc.skeleton)
    assert any("NOPE-NADA" in w for w in apply_project(other, data, path))


def test_load_connections_sets_bones_in_root_order(tmp_path, doc):
    s = samples.mannequin()
    doc.bone_edits.set_bones(s.bones)
    doc.attachments.assign([0, 1], doc.bones.index("L_THIGH"))
    (tmp_path / "a.connections").write_text("L_HIP L_KNEE\nPELVIS NECK\n")
    doc.bone_edits.load_connections(tmp_path / "a.connections")
    assert [b.label for b in doc.bones.bones] == ["L_THIGH", "SPINE"]
    assert doc.bone_of_point(0) == "L_THIGH"  # attachments follow their bone
    (tmp_path / "b.connections").write_text("L_HIP L_WING\n")
    with pytest.raises(ValueError, match="not loaded: L_WING"):
        doc.bone_edits.load_connections(tmp_path / "b.connections")
    assert len(doc.bones) == 2  # a refused file changes nothing
    assert not doc.undo.can_undo and doc.modified  # a load is not an edit to undo, and not saved yet (issue #37)


def test_loading_a_file_is_not_an_edit_but_a_failed_load_keeps_the_history(tmp_path, doc):
    """Every file put into the session starts the history after it (issue #37: Ctrl+Z undid the
    opening); a file refused leaves the edits before it undoable."""
    from volanim_core import io

    s = samples.mannequin()
    io.write_bones(tmp_path / "m.bones", s.bones)
    doc.bone_edits.load_bones(tmp_path / "m.bones")
    assert len(doc.bones) == 18 and not doc.undo.can_undo and doc.modified
    doc.attachments.assign([0, 1], doc.bones.index("L_THIGH"))
    io.write_connect(tmp_path / "m.connect", doc.attachments.to_connectivity())
    doc.pose.set_angles(doc.bones.index("L_THIGH"), [10, 0, 0])
    doc.pose.save_trans(tmp_path / "m.trans")
    assert doc.undo.can_undo
    (tmp_path / "bad.bones").write_text("not bones\n")
    with pytest.raises(ValueError):
        doc.bone_edits.load_bones(tmp_path / "bad.bones")
    assert doc.undo.undo_label == "Pose L_THIGH"  # the refused file took no history
    for load in (lambda: doc.attachments.load(tmp_path / "m.connect"), lambda: doc.bone_edits.load_bones(
            tmp_path / "m.bones"), lambda: doc.pose.load_trans(tmp_path / "m.trans")):
        doc.pose.set_angles(doc.bones.index("L_THIGH"), [20, 0, 0], merge=False)
        load()
        assert not doc.undo.can_undo, load
    assert doc.bone_of_point(0) == "L_THIGH" and np.isclose(doc.pose.angles_of(doc.bones.index("L_THIGH"))[0], 10)


def test_version_1_projects_read_with_their_defaults(tmp_path):
    path = tmp_path / "old.volanim"
    path.write_text('{"format": "volanim project", "version": 1, "threshold": [20, 200], "thinness": 0.5}')
    seg = read_project(path)["segmentation"]
    assert seg == {"lo": 20, "hi": 200, "fill": False, "metric": "euclid", "min_thinness": 0.5, "spacing": None,
                   "series": None}


@pytest.mark.parametrize("content, message", [
    ('{"format": "volanim project", "volume": 7}', '"volume" must be a file name'),
    ('{"format": "volanim project", "volume": ["a"]}', '"volume" must be a file name'),
    ('{"format": "volanim project", "thinness": "x"}', '"thinness" must be a finite number'),
    ('{"format": "volanim project", "settings": []}', '"settings" must be an object'),
    ("[" * 100000 + "]" * 100000, "nested too deeply|not a volanim project"),
    ('{"format": "volanim project", "demo": 3}', '"demo" must be a sample name'),
    ('{"format": "volanim project", "threshold": [1, 2, 3]}', '"threshold" must be a list'),
    ('{"format": "volanim project", "threshold": 5}', '"threshold" must be a list'),
    ('{"format": "volanim project", "segmentation": {"lo": "x"}}', '"lo" must be a number'),
    ('{"format": "volanim project", "segmentation": {"fill": "yes"}}', '"fill" must be true or false'),
    ('{"format": "volanim project", "segmentation": {"metric": "manhattan"}}', '"metric" must be'),
    ('{"format": "volanim project", "pose": []}', '"pose" must be an object'),
    ('{"format": "volanim project", "pose": {"angles": [["A", "B", 1, 2]]}}', r'"pose" "angles": expected'),
    ('{"format": "volanim project", "pose": {"angles": [["A", "B", 1, 2, "x"]]}}', r'"pose" "angles": expected'),
])
def test_bad_project_fields_are_format_errors_naming_the_file(tmp_path, content, message):
    path = tmp_path / "bad.volanim"
    path.write_text(content)
    with pytest.raises(FormatError, match=message) as info:
        read_project(path)
    assert str(path) in str(info.value)


def test_a_project_that_is_a_device_is_refused_not_read_forever(tmp_path):
    """#38 review: the manifest reader took a size of 0 for /dev/zero and read until memory ran out."""
    link = tmp_path / "zero.volanim"
    link.symlink_to("/dev/zero")
    with pytest.raises(FormatError, match="zero.volanim: is not a regular file"):
        read_project(link)


def test_an_undo_group_is_one_step_undone_in_reverse():
    """UndoStack.group (QUndoStack's macro): the lasso's points and their flesh are one Ctrl+Z (#84)."""
    from volanim_studio.model.undo import Command, UndoStack

    log, stack = [], UndoStack()
    with stack.group("both"):
        stack.push(Command("a", lambda: log.append("a"), lambda: log.append("-a")))
        stack.push(Command("b", lambda: log.append("b"), lambda: log.append("-b")))
    assert log == ["a", "b"] and stack.undo_label == "both" and stack.edits == 1
    assert stack.undo() == "both" and log[2:] == ["-b", "-a"] and not stack.can_undo
    assert stack.redo() == "both" and log[4:] == ["a", "b"]
    with stack.group("nothing"):
        pass
    assert stack.undo_label == "both"  # an empty group leaves no step
