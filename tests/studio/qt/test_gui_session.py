"""The studio keeps everything the user did, through real widgets (issue #37)."""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import Qt

from paths import ASSETS
from volanim_studio.model.interaction import Mode

from ..conftest import JOB_TIMEOUT_MS, new_window, open_project, rig_and_pose, save_project


def _close(w) -> None:
    w.doc.undo.mark_clean()
    w.close()
    assert not w.busy


def test_the_whole_session_comes_back_on_reopen(qtbot, window, tmp_path):
    """Bones, attachments, the pose, the keys and the frame, the thinness, display settings, the mode, the
    selected bone and the camera: all in the project, all back in a new window."""
    w = rig_and_pose(qtbot, window)
    doc = w.doc
    arm = doc.bones.index("L_UPPERARM")
    w.bone_panel.tree.topLevelItem(arm).setSelected(True)  # select the bone by its row
    assert doc.selected_bones == (arm,)
    w.display_panel.thinness_slider.setValue(w.display_panel._step_of(0.8))
    doc.settings.colour_by = "dt"
    doc.settings.preview_mode = "mottled"
    doc.settings.names_visible = False
    qtbot.keyClick(w, Qt.Key_S)  # a key at frame 0 (rest)
    doc.settings.current_frame = 12
    slider = w.pose_panel.sliders[1]
    slider.setSliderDown(True)
    for v in range(0, -45, -4):
        slider.setValue(v)
    slider.setSliderDown(False)
    qtbot.keyClick(w, Qt.Key_S)  # a key at frame 12
    qtbot.waitUntil(lambda: not w.busy, timeout=JOB_TIMEOUT_MS)
    doc.settings.current_frame = 6  # between the keys: the pose shows the frame
    doc.pose.set_angles(doc.bones.index("R_THIGH"), (15, 0, 0), merge=False)  # and an edit on top of it
    qtbot.keyClick(w, Qt.Key_3, Qt.ControlModifier)  # View > Side
    camera = w.scene.camera()
    angles = {i: doc.pose.angles_of(i) for i in range(len(doc.bones))}
    path = save_project(qtbot, w, path=tmp_path / "day.volanim")
    assert path is not None and not w.isWindowModified()

    other = new_window(qtbot)
    try:
        assert open_project(qtbot, other, path)
        d = other.doc
        assert other.mode == Mode.POSE and other.mode_actions[Mode.POSE].isChecked()
        assert d.selected_bones == (arm,) and "L_UPPERARM" in other.pose_panel.bone_label.text()
        assert d.thinness == doc.thinness and other.display_panel.thinness_slider.value() == \
            w.display_panel.thinness_slider.value()
        assert (d.settings.colour_by, d.settings.preview_mode, d.settings.names_visible) == ("dt", "mottled", False)
        assert sorted(d.timeline.keys) == [0, 12] and d.settings.current_frame == 6
        assert all(np.allclose(d.pose.angles_of(i), a) for i, a in angles.items())  # the pose, not the frame's
        assert np.allclose(d.pose.angles_of(d.bones.index("R_THIGH")), (15, 0, 0))
        assert np.array_equal(d.attachments.bone, doc.attachments.bone)
        for key in ("position", "focal_point", "view_up"):
            assert np.allclose(other.scene.camera()[key], camera[key], atol=1e-6), key
        assert not d.undo.can_undo and not other.isWindowModified()
    finally:
        _close(other)


def test_opening_bones_or_connections_from_the_menu_is_not_undone_by_ctrl_z(qtbot, window):
    """Issue #37: loading any file is not an edit (Open bones was still an undo step)."""
    window.doc.bone_edits.add_bone((80, 50, 140), (80, 50, 200))  # an edit before the load
    assert window.files.open_bones(ASSETS / "mannequin.bones")
    assert window.files.open_connect(ASSETS / "mannequin.0.50.connect")
    attached = int((window.doc.attachments.bone >= 0).sum())
    assert not window.undo_action.isEnabled() and window.isWindowModified()  # not saved anywhere yet
    window.activateWindow()
    qtbot.keyClick(window, Qt.Key_Z, Qt.ControlModifier)
    assert len(window.doc.bones) == 18 and int((window.doc.attachments.bone >= 0).sum()) == attached


def test_a_slider_drag_is_one_undo_step_and_each_arrow_key_is_another(qtbot, window):
    w = rig_and_pose(qtbot, window)
    arm = w.doc.bones.index("L_UPPERARM")
    w.doc.select_bones([arm])
    slider = w.pose_panel.sliders[2]
    slider.setSliderDown(True)  # press ...
    for v in range(0, 31, 3):
        slider.setValue(v)
    slider.setSliderDown(False)  # ... to release
    qtbot.waitUntil(lambda: not w.busy, timeout=JOB_TIMEOUT_MS)
    slider.setFocus()
    qtbot.keyClick(slider, Qt.Key_Up)  # the keyboard moves a slider one step a press (Right steps frames)
    qtbot.keyClick(slider, Qt.Key_Up)
    qtbot.waitUntil(lambda: not w.busy, timeout=JOB_TIMEOUT_MS)
    assert np.isclose(w.doc.pose.angles_of(arm)[2], 32)
    w.undo()
    assert np.isclose(w.doc.pose.angles_of(arm)[2], 31)
    w.undo()
    assert np.isclose(w.doc.pose.angles_of(arm)[2], 30)
    w.undo()  # the whole drag
    assert w.doc.pose.is_rest and not w.doc.undo.can_undo


def test_ctrl_f2_names_an_arm_from_the_neck_as_the_readme_says(qtbot, window):
    """Issue #37: SHOULDER, ELBOW, WRIST, FINGERS on the chain from the neck renamed NECK to SHOULDER
    and left the fingertip unnamed."""
    from volanim_core import samples
    from volanim_core.rig.bones import BoneSkeleton

    man = samples.mannequin_bones()
    anon = {n: (n if n in ("PELVIS", "NECK", "HEAD") else f"J{k}") for k, n in enumerate(man.joints)}
    window.doc.bone_edits.set_bones(BoneSkeleton({anon[n]: p for n, p in man.joints.items()},
                                                 [type(b)(anon[b.proximal], anon[b.distal], "") for b in man.bones]))
    window.doc.select_bones([next(i for i, b in enumerate(window.doc.bones.bones) if b.distal == anon["L_FINGERS"])])
    window.activateWindow()
    qtbot.keyClick(window, Qt.Key_F2, Qt.ControlModifier)
    box = window.naming.box
    assert "(type 5 to rename NECK too)" in box.labelText()
    box.setTextValue("SHOULDER, ELBOW, WRIST, FINGERS")
    box.accept()
    joints = window.doc.bones.joints
    assert {"NECK", "L_SHOULDER", "L_ELBOW", "L_WRIST", "L_FINGERS"} <= set(joints)
    assert np.allclose(joints["L_FINGERS"], man.joints["L_FINGERS"])
    assert window.doc.undo.undo_label.startswith("Name chain")
