"""One document per project in the real window: the modified marker, "Save changes?" on close and
before opening another volume, and nothing lost either way (issue #18)."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QMessageBox

from paths import ASSETS
from volanim_core import io
from volanim_studio.model import autosave
from volanim_studio.model.interaction import Mode
from volanim_studio.model.project import read_project

from ..conftest import JOB_TIMEOUT_MS, open_project, save_project

pytestmark = pytest.mark.gui


def _answer(qtbot, window, button) -> None:
    """Click ``button`` of the window's "Save changes?" box (which must be showing)."""
    qtbot.waitUntil(lambda: window.session.save_box is not None and window.session.save_box.isVisible(), timeout=5000)
    window.session.save_box.button(button).click()


def _rename_a_joint(window) -> None:
    assert window.files.open_bones(ASSETS / "mannequin.bones")
    window.doc.undo.mark_clean()  # as if the bones came with the project
    window.doc.bone_edits.rename_joint("L_ELBOW", "L_KNUCKLE")


def test_an_edit_marks_the_window_modified_and_undo_back_to_the_saved_state_clears_it(qtbot, window, tmp_path):
    assert window.files.open_bones(ASSETS / "mannequin.bones")
    path = save_project(qtbot, window, path=tmp_path / "man.volanim")
    assert not window.isWindowModified() and window.windowTitle() == "volanim studio — man.volanim[*]"
    window.doc.bone_edits.rename_joint("L_ELBOW", "L_KNUCKLE")
    assert window.isWindowModified()
    window.undo()
    assert not window.isWindowModified()
    window.redo()
    assert window.isWindowModified()
    assert path.exists()


def test_closing_with_unsaved_edits_asks_and_cancel_keeps_the_window(qtbot, window):
    _rename_a_joint(window)
    window.close()
    _answer(qtbot, window, QMessageBox.Cancel)
    assert window.isVisible() and "L_KNUCKLE" in window.doc.bones.joints


def test_discarded_edits_are_set_aside_for_a_week_not_deleted(qtbot, window, recovery_dir):
    """Rename a joint, Ctrl+Q: the clean exit deleted the autosave and the rename was gone."""
    _rename_a_joint(window)
    window.close()
    _answer(qtbot, window, QMessageBox.Discard)
    qtbot.waitUntil(lambda: not window.isVisible(), timeout=5000)
    kept = list(recovery_dir.glob("*-discarded/recovery.volanim"))
    assert len(kept) == 1 and (kept[0].parent / autosave.DECLINED).exists()
    assert "L_KNUCKLE" in io.read_bones(read_project(kept[0])["bones"]).joints
    assert autosave.find_recoveries(recovery_dir) == []  # kept, but not offered as a crash
    assert not window.session.autosaver.folder.exists()  # the session's own folder went as before


def test_save_from_the_close_prompt_saves_then_closes(qtbot, window, tmp_path):
    assert window.files.open_bones(ASSETS / "mannequin.bones")
    path = save_project(qtbot, window, path=tmp_path / "man.volanim")
    window.doc.bone_edits.rename_joint("L_ELBOW", "L_KNUCKLE")
    window.close()
    _answer(qtbot, window, QMessageBox.Save)
    qtbot.waitUntil(lambda: not window.isVisible(), timeout=5000)
    assert "L_KNUCKLE" in io.read_bones(read_project(path)["bones"]).joints


def test_a_new_volume_is_a_new_document_and_the_old_project_is_untouched(qtbot, window, tmp_path):
    """Open man.volanim, open another volume, save: the mannequin's bones floated over the new volume,
    the title kept man.volanim and Ctrl+S overwrote man.volanim with the new volume."""
    assert window.files.open_bones(ASSETS / "mannequin.bones")
    window.doc.attachments.auto(scope="all")
    save_project(qtbot, window, path=tmp_path / "man.volanim")
    before = {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file() and "recovery" not in p.parts}
    vol = np.zeros((40, 30, 30), np.uint8)
    vol[5:35, 5:25, 5:25] = 200
    io.write_volume(tmp_path / "box.VOL", vol)
    assert not window.doc.modified
    window.files.open_volume(tmp_path / "box.VOL", params={"lo": 1, "hi": None, "fill": True})
    qtbot.waitUntil(lambda: not window.busy, timeout=JOB_TIMEOUT_MS)
    doc = window.doc
    assert len(doc.bones) == 0 and doc.project_path is None and not doc.undo.can_undo
    assert (doc.attachments.bone == -1).all() and doc.pose.is_rest
    assert window.windowTitle() == "volanim studio — untitled[*]" and not window.isWindowModified()
    box = save_project(qtbot, window, path=tmp_path / "box.volanim")  # Ctrl+S asks where: no path is known
    assert {p: p.read_bytes() for p in before} == before  # man.volanim and its files untouched
    assert window.windowTitle() == "volanim studio — box.volanim[*]"
    assert read_project(box).get("bones") is None  # (a project without bones was saved with an empty,
    assert open_project(qtbot, window, box)  # unreadable .bones file and could not be reopened)
    assert window.last_error is None and len(window.doc.bones) == 0 and window.doc.skeleton is not None


def test_opening_another_volume_with_unsaved_edits_asks_first(qtbot, window):
    _rename_a_joint(window)
    asked = []
    window.session.when_saved_or_discarded(lambda: asked.append("went on"), "opening another volume")
    _answer(qtbot, window, QMessageBox.Cancel)
    assert asked == [] and "L_KNUCKLE" in window.doc.bones.joints
    window.session.when_saved_or_discarded(lambda: asked.append("went on"), "opening another volume")
    _answer(qtbot, window, QMessageBox.Discard)
    assert asked == ["went on"]


def test_file_dialogs_open_in_the_project_folder(qtbot, window, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert window.files.folder() == str(tmp_path.resolve())  # nothing saved yet: the working directory
    folder = tmp_path / "work"
    folder.mkdir()
    save_project(qtbot, window, path=folder / "man.volanim")
    assert window.files.folder("a.bones") == str(folder.resolve() / "a.bones")
    assert window.timeline.folder() == window.previews.folder() == str(folder.resolve())  # every controller


def test_files_named_on_the_command_line_are_not_unsaved_edits(qtbot, tmp_path):
    """``volanim-studio --demo mannequin --bones B`` then Ctrl+Q asked "Save changes?" about nothing."""
    from volanim_studio.app import build_parser
    from volanim_studio.qt.main_window import main_window_for

    w = main_window_for(build_parser().parse_args(["--demo", "mannequin", "--bones",
                                                   str(ASSETS / "mannequin.bones")]))
    qtbot.addWidget(w)
    qtbot.waitUntil(lambda: not w.busy and len(w.doc.bones) == 18, timeout=JOB_TIMEOUT_MS)
    assert not w.doc.modified and not w.isWindowModified()
    # Ctrl+Z right after the start undoes nothing: "Undid: Load bones" took all 18 bones (issue #37)
    assert not w.doc.undo.can_undo
    w.activateWindow()
    qtbot.keyClick(w, Qt.Key_Z, Qt.ControlModifier)
    assert len(w.doc.bones) == 18 and not w.doc.modified
    w.doc.bone_edits.rename_joint("L_ELBOW", "L_KNUCKLE")  # an edit is one
    assert w.isWindowModified()
    w.doc.undo.mark_clean()
    w.close()


def test_a_new_volume_after_connecting_and_posing_opens_cleanly(qtbot, window, tmp_path):
    """Opening a volume over a connected, posed project raised IndexError in the view: the reset emptied
    the bones while the points still named them (found making the README's colour screenshot)."""
    assert window.files.open_bones(ASSETS / "mannequin.bones")
    assert window.files.open_connect(ASSETS / "mannequin.0.50.connect")
    window.doc.settings.colour_by = "bone"  # points coloured by their bone: the colours index the bones
    window.set_mode(Mode.POSE)
    window.doc.pose.set_angles(window.doc.bones.index("L_UPPERARM"), (0, -40, 0), merge=False)
    vol = np.zeros((40, 30, 30), np.uint8)
    vol[5:35, 5:25, 5:25] = 200
    io.write_volume(tmp_path / "box.VOL", vol)
    window.doc.undo.mark_clean()
    window.files.open_volume(tmp_path / "box.VOL", params={"lo": 1, "hi": None, "fill": True})
    qtbot.waitUntil(lambda: not window.busy, timeout=JOB_TIMEOUT_MS)
    assert window.doc.shape == (40, 30, 30) and len(window.doc.bones) == 0 and window.doc.pose.is_rest
    assert len(window.doc.attachments.bone) == len(window.doc.skeleton) and (window.doc.attachments.bone == -1).all()


def test_a_posed_project_reopens_posed_and_opening_is_not_undone(qtbot, window, tmp_path):
    """Issue #37: pose L_UPPERARM to y -44, Ctrl+S, reopen: the angles were 0, 0, 0; and Ctrl+Z right
    after opening said "Undid: Load connect" and left 0 points attached."""
    assert window.files.open_bones(ASSETS / "mannequin.bones")
    assert window.files.open_connect(ASSETS / "mannequin.0.50.connect")
    arm = window.doc.bones.index("L_UPPERARM")
    window.set_mode(Mode.POSE)
    window.doc.pose.set_angles(arm, (0, -44, 0), merge=False)
    path = save_project(qtbot, window, path=tmp_path / "posed.volanim")
    attached = int((window.doc.attachments.bone >= 0).sum())
    assert open_project(qtbot, window, path)
    assert np.allclose(window.doc.pose.angles_of(arm), (0, -44, 0))
    assert not window.doc.undo.can_undo and not window.isWindowModified()
    window.activateWindow()
    qtbot.keyClick(window, Qt.Key_Z, Qt.ControlModifier)
    assert int((window.doc.attachments.bone >= 0).sum()) == attached and len(window.doc.bones) == 18
    assert np.allclose(window.doc.pose.angles_of(arm), (0, -44, 0)) and not window.isWindowModified()


def test_a_project_in_the_autosave_area_is_saved_where_the_user_says(qtbot, window, tmp_path, recovery_dir,
                                                                      monkeypatch):
    """Issue #37: Ctrl+S on a project opened from the "-discarded" autosave folder saved into that folder
    without asking, where it is pruned after a week."""
    from PySide6.QtWidgets import QFileDialog

    cached = recovery_dir / "123-456-discarded" / "recovery.volanim"
    cached.parent.mkdir(parents=True)
    save_project(qtbot, window, path=cached)
    assert open_project(qtbot, window, cached)
    window.doc.bone_edits.rename_joint("L_ELBOW", "L_KNUCKLE")
    asked = []
    chosen = tmp_path / "mine.volanim"
    monkeypatch.setattr(QFileDialog, "getSaveFileName", lambda *a, **k: (asked.append(a) or str(chosen), ""))
    before = cached.read_bytes()
    assert save_project(qtbot, window) == chosen  # Ctrl+S
    assert asked and "autosave area" in asked[0][1] and cached.read_bytes() == before
    assert window.doc.project_path == str(chosen) and not window.isWindowModified()


# spec: docs/formats.md#skel
def test_the_studio_opens_a_thesis_skel_and_shows_all_of_it(qtbot, window, tmp_path):
    # bare 'x y z dt' rows, as the thesis's tools wrote them (no header, no thinness)
    at = window.doc.skeleton.at(0.8)
    (tmp_path / "thesis.skel").write_text("".join(f"{x} {y} {z} {r:.3f}\n" for (x, y, z), r in zip(at.points, at.dt)))
    assert window.files.open_mskel(tmp_path / "thesis.skel")
    assert len(window.doc.skeleton) == len(at) and window.doc.visible_count == len(at)
    assert window.doc.thinness_range == (0.0, 0.0)
    path = save_project(qtbot, window, path=tmp_path / "thesis.volanim")
    window.files.open_project(path)
    assert window.doc.visible_count == len(at)


def test_ctrl_s_with_nothing_loaded_says_so_without_asking_for_a_name(qtbot, monkeypatch):
    """#61 item 6: it asked for a file name, then said there was nothing to save."""
    from PySide6.QtWidgets import QFileDialog

    from ..conftest import new_window

    asked = []
    monkeypatch.setattr(QFileDialog, "getSaveFileName", lambda *a, **k: (asked.append(a) or ("", "")))
    w = new_window(qtbot)
    w.activateWindow()
    qtbot.waitUntil(w.isActiveWindow, timeout=5000)
    qtbot.keyClick(w, Qt.Key_S, Qt.ControlModifier)
    assert not asked
    assert w.statusBar().currentMessage().startswith("nothing to save yet")
    qtbot.keyClick(w, Qt.Key_S, Qt.ControlModifier | Qt.ShiftModifier)  # Save as… too
    assert not asked
    w.close()


# ---------------------------------------------------------------- #83: autosave that never lags
def _polls_later(qtbot, window, n: int = 2) -> None:
    """Wait for ``n`` more autosave polls of the window's timer, then for the write they started: a count
    of the timer's own ticks, not a time."""
    saver = window.session.autosaver
    start = saver.polls
    qtbot.waitUntil(lambda: saver.polls >= start + n and not saver.writing, timeout=JOB_TIMEOUT_MS)


def test_a_held_drag_and_the_renames_before_it_are_on_disk_while_the_slider_is_still_down(qtbot, window):
    """Six renames, then a pose drag held: a kill -9 then recovered 4 of the 6 renames and none of the
    drag, because autosave waited for the release."""
    from ..conftest import rig_and_pose

    w = rig_and_pose(qtbot, window)
    doc = w.doc
    for i, joint in enumerate(["R_ELBOW", "L_KNEE", "R_KNEE", "R_WRIST", "L_ANKLE", "R_ANKLE"]):
        doc.bone_edits.rename_joint(joint, f"RENAMED{i}")
    doc.select_bones([doc.bones.index("L_UPPERARM")])
    slider = w.pose_panel.sliders[1]
    slider.setSliderDown(True)
    for v in range(0, 41, 4):
        slider.setValue(v)
    _polls_later(qtbot, w)
    assert slider.isSliderDown() and doc.settings.dragging  # still held
    data = read_project(w.session.autosaver.path)
    assert sum(j.startswith("RENAMED") for j in io.read_bones(data["bones"]).joints) == 6
    assert np.allclose(data["state"]["pose"][0][("L_SHOULDER", "L_ELBOW")], (0, 40, 0))
    slider.setSliderDown(False)


def test_discard_keeps_the_drag_released_just_before(qtbot, window, recovery_dir):
    """Drag R_UPPERARM to 45 with the mouse, release, Ctrl+Q, Discard: the copy kept for a week must open
    at 45 (it was reported to open at the value before the drag)."""
    from PySide6.QtCore import QPoint
    from PySide6.QtWidgets import QStyle, QStyleOptionSlider

    from ..conftest import new_window, rig_and_pose

    w = rig_and_pose(qtbot, window)
    doc = w.doc
    arm = doc.bones.index("R_UPPERARM")
    doc.select_bones([arm])
    slider = w.pose_panel.sliders[1]
    opt = QStyleOptionSlider()
    slider.initStyleOption(opt)
    start = slider.style().subControlRect(QStyle.CC_Slider, opt, QStyle.SC_SliderHandle, slider).center()
    qtbot.mousePress(slider, Qt.LeftButton, pos=start)
    dx = 0
    while slider.value() < 45:  # a real drag of the handle, a pixel at a time, until it reads 45
        dx += 1
        qtbot.mouseMove(slider, start + QPoint(dx, 0))
        assert dx < slider.width()
    qtbot.mouseRelease(slider, Qt.LeftButton, pos=start + QPoint(dx, 0))
    angle = doc.pose.angles_of(arm)[1]
    assert angle >= 45
    qtbot.keyClick(w, Qt.Key_Q, Qt.ControlModifier)
    _answer(qtbot, w, QMessageBox.Discard)
    qtbot.waitUntil(lambda: not w.isVisible(), timeout=5000)
    kept = list(recovery_dir.glob("*-discarded/recovery.volanim"))
    assert len(kept) == 1
    other = new_window(qtbot)
    try:
        assert open_project(qtbot, other, kept[0])
        assert np.allclose(other.doc.pose.angles_of(other.doc.bones.index("R_UPPERARM")), (0, angle, 0))
    finally:
        other.doc.undo.mark_clean()
        other.close()


def test_a_save_is_written_off_the_gui_thread_and_an_edit_made_meanwhile_stays_unsaved(qtbot, window, tmp_path):
    """Save takes the project at the click and writes it on the savers' thread (mannequin-large's save held
    the GUI thread 170 ms); a rename made before it is written is not in it, and the window says so."""
    assert window.files.open_bones(ASSETS / "mannequin.bones")
    path = window.files.save_project(path=tmp_path / "man.volanim")
    assert path == tmp_path / "man.volanim" and window.savers.busy
    # the result is applied on the GUI thread, so nothing is adopted before this edit
    window.doc.bone_edits.rename_joint("L_ELBOW", "L_KNUCKLE")
    qtbot.waitUntil(lambda: not window.savers.busy, timeout=JOB_TIMEOUT_MS)
    assert window.doc.project_path == str(path) and window.isWindowModified()  # saved, but not the rename
    assert "L_ELBOW" in io.read_bones(read_project(path)["bones"]).joints
    window.undo()  # back to what was saved: unmodified
    assert not window.isWindowModified()

