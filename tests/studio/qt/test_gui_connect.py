"""Studio II with real widgets: cube, lasso (real mouse drags), mirror, autosave, crash recovery."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt
from PySide6.QtWidgets import QMessageBox

from paths import ASSETS
from volanim_core import io, samples
from volanim_core.render.bone_colours import label_table
from volanim_core.skeleton.points import Skeleton
from volanim_studio.model.interaction import Mode
from volanim_studio.model.project import read_project

from ..conftest import JOB_TIMEOUT_MS, click, clickable_point, front_view, open_project, save_project

pytestmark = pytest.mark.gui

J = samples.mannequin_bones().joints


def qpos(window, xy) -> QPoint:
    w = window.plotter
    s = w.devicePixelRatioF()
    return QPoint(int(round(xy[0] / s)), int(round(w.height() - 1 - xy[1] / s)))


def drag_lasso(qtbot, window, polygon, modifier=Qt.NoModifier) -> None:
    """Press, move through the outline and release, as a user's mouse would."""
    w = window.plotter
    pts = [qpos(window, p) for p in polygon]
    qtbot.mousePress(w, Qt.LeftButton, modifier, pts[0])
    for p in pts[1:]:
        qtbot.mouseMove(w, p)
    qtbot.mouseRelease(w, Qt.LeftButton, modifier, pts[0])


def test_cube_connect_changes_colours_and_counts(qtbot, window):
    assert window.files.open_bones(ASSETS / "mannequin.bones")
    qtbot.keyClick(window, Qt.Key_K)
    assert window.mode == Mode.CUBE
    assert window.doc.settings.colour_by == "bone" == window.display_panel.colour_by.currentText()
    p = clickable_point(window, J["L_ELBOW"])
    click(qtbot, window, window.scene.display_of_point(p))
    assert np.array_equal(window.doc.cube_centre, window.doc.skeleton.points[p])
    forearm = window.doc.bones.index("L_FOREARM")
    window.bone_panel.tree.topLevelItem(forearm).setSelected(True)
    assert window.doc.working_bone == forearm and "L_FOREARM" in window.connect_panel.working.text()
    qtbot.mouseClick(window.connect_panel.cube_connect, Qt.LeftButton)
    inside = np.flatnonzero(window.doc.attachments.bone == forearm)
    assert len(inside) > 0 and p in inside
    want = label_table(forearm + 1)[forearm + 1]
    assert (window.scene._colours[inside] == want).all()
    assert window.bone_panel.tree.topLevelItem(forearm).text(4) == str(len(inside))
    assert window.point_label.text().endswith("bone L_FOREARM")  # the status bar follows the attachment
    unconnected = window.doc.visible_count - len(inside)
    assert window.bone_panel.unconnected.text().startswith(f"{unconnected} of")
    qtbot.keyClick(window, Qt.Key_Right)  # nudge, then remove with X
    qtbot.keyClick(window, Qt.Key_X)
    assert (window.doc.attachments.bone == forearm).sum() < len(inside)
    qtbot.keyClick(window, Qt.Key_Z, Qt.ControlModifier)
    assert (window.doc.attachments.bone == forearm).sum() == len(inside)


@pytest.fixture
def depth_scene(window):
    """Front block F (y=10), back block B right behind it (y=60) and a side block S (y=40) not behind F."""
    g = np.stack(np.meshgrid(np.arange(0, 10, 2), [0], np.arange(0, 10, 2), indexing="ij"), -1).reshape(-1, 3)
    front, back = g + [40, 10, 140], g + [40, 60, 140]
    side = g[:5] + [60, 40, 140]
    pts = np.vstack([front, back, side]).astype(np.int32)
    doc = window.doc
    doc.set_skeleton(Skeleton(pts, np.ones(len(pts)), np.ones(len(pts))))
    doc.set_hull(None, None)
    doc.bone_edits.add_bone((45, 30, 120), (45, 30, 160))
    doc.select_bones([0])
    window.plotter.enable_parallel_projection()
    front_view(window)  # along +y, whatever the scene's shape (the studio's presets go by the shape)
    window.set_mode(Mode.LASSO)
    window.display_panel.point_size.setValue(10)
    n = len(front)
    return window, (set(range(n)), set(range(n, 2 * n)), set(range(2 * n, len(pts))))


@pytest.mark.parametrize("mode", ["through", "visible", "slab"])
def test_lasso_depth_modes(qtbot, depth_scene, mode):
    window, (front, back, side) = depth_scene
    window.connect_panel.depth_mode.setCurrentText(mode)
    window.connect_panel.slab.setValue(15)
    xy, _ = window.scene.project_world(window.scene._world)
    lo, hi = xy.min(0) - 15, xy.max(0) + 15
    drag_lasso(qtbot, window, [(lo[0], lo[1]), (hi[0], lo[1]), (hi[0], hi[1]), (lo[0], hi[1])])
    got = set(np.flatnonzero(window.doc.attachments.bone == 0).tolist())
    want = {"through": front | back | side, "visible": front | side, "slab": front}[mode]
    assert got == want
    drag_lasso(qtbot, window, [(lo[0], lo[1]), (hi[0], lo[1]), (hi[0], hi[1]), (lo[0], hi[1])],
               Qt.ControlModifier)  # Ctrl removes
    assert (window.doc.attachments.bone == -1).all()


def test_auto_connect_and_mirror_in_the_gui(qtbot, window):
    assert window.files.open_bones(ASSETS / "mannequin.bones")
    window.connect_panel.scope.setCurrentText("all")
    window.connecting.auto_connect()  # what the button and Ctrl+A call (no events processed until the wait)
    assert window.busy  # measured in a worker, with progress and Cancel
    qtbot.waitUntil(lambda: not window.busy, timeout=JOB_TIMEOUT_MS)
    doc = window.doc
    assert (doc.attachments.bone[: doc.visible_count] >= 0).all()
    assert doc.undo.undo_label.startswith("Auto-connect")  # one undo step
    left, right = doc.bones.index("L_FOREARM"), doc.bones.index("R_FOREARM")
    n_left = int((doc.attachments.bone == left).sum())
    doc.attachments.assign(np.flatnonzero(doc.attachments.bone == right), -1)
    window.bone_panel.tree.topLevelItem(left).setSelected(True)
    qtbot.mouseClick(window.connect_panel.mirror_button, Qt.LeftButton)
    assert int((doc.attachments.bone == right).sum()) == n_left
    window.connect_panel.only_unconnected.setChecked(True)
    assert window.scene.shown_points == int((doc.attachments.bone[: doc.visible_count] < 0).sum())


def test_save_connect_quit_reopen_and_continue(qtbot, window, tmp_path):
    assert window.files.open_bones(ASSETS / "mannequin.bones")
    window.doc.attachments.auto(scope="all")
    path = save_project(qtbot, window, path=tmp_path / "man.volanim")
    saved = window.files.save_connect(tmp_path / window.doc.attachments.default_filename("man"))
    assert saved.name.startswith("man.") and saved.suffix == ".connect"
    before = window.doc.attachments.bone.copy()
    from volanim_studio.qt.main_window import MainWindow

    other = MainWindow()
    qtbot.addWidget(other)
    assert open_project(qtbot, other, path)
    assert np.array_equal(other.doc.attachments.bone, before)
    other.close()


def test_autosave_file_appears(qtbot, window, recovery_dir):
    assert window.files.open_bones(ASSETS / "mannequin.bones")
    for i in range(5):
        window.doc.attachments.assign([i], 0)
    saver = window.session.autosaver
    qtbot.waitUntil(lambda: saver.caught_up, timeout=JOB_TIMEOUT_MS)  # the window's poll
    files = list(recovery_dir.glob("*/recovery.volanim"))
    assert len(files) == 1
    assert io.read_bones(read_project(files[0])["bones"]) == window.doc.bones
    save_project(qtbot, window, path=recovery_dir.parent / "man.volanim")
    window.close()
    assert not list(recovery_dir.glob("*/recovery.volanim"))  # a clean exit when saved leaves nothing to recover


CRASH = """
import os, sys
from PySide6.QtWidgets import QApplication
app = QApplication([])
from volanim_studio.qt.main_window import MainWindow
w = MainWindow()
w.show()
w.files.load_demo("mannequin")
while w.busy:
    app.processEvents()
w.files.open_bones(sys.argv[1])
w.doc.attachments.auto(scope="all")
saver = w.session.autosaver
while saver.written == 0 or not saver.caught_up:  # the window's poll saves it
    app.processEvents()
print("EDITED", int((w.doc.attachments.bone >= 0).sum()), flush=True)
os._exit(3)  # a crash: no close, no cleanup
"""


def test_restore_after_a_crash(qtbot, tmp_path, recovery_dir):
    script = tmp_path / "crash.py"
    script.write_text(textwrap.dedent(CRASH))
    out = subprocess.run([sys.executable, str(script), str(ASSETS / "mannequin.bones")], capture_output=True,
                         text=True, timeout=300, env=dict(os.environ))
    assert out.returncode == 3 and "EDITED" in out.stdout, (out.returncode, out.stdout, out.stderr[-2000:])
    attached = int(out.stdout.split("EDITED")[1].split()[0])
    listing = sorted(str(p.relative_to(recovery_dir)) for p in recovery_dir.rglob("*"))
    from volanim_studio.qt.main_window import MainWindow

    w = MainWindow()
    qtbot.addWidget(w)
    asked = []
    w.session.offer_recovery(ask=lambda found: asked.extend(found) or found[0])
    qtbot.waitUntil(lambda: not w.busy, timeout=JOB_TIMEOUT_MS)
    assert asked, listing
    assert len(w.doc.bones) == 18, (listing, w.last_error)
    assert int((w.doc.attachments.bone >= 0).sum()) == attached, (listing, w.last_error)
    # the restored state is autosaved in this session's folder; then the crashed session's copy goes
    saved = list(recovery_dir.glob("*/recovery.volanim"))
    assert len(saved) == 1 and saved[0].parent == w.session.autosaver.folder
    again = read_project(saved[0])
    assert io.read_connect(again["connect"]).bone.size == attached
    assert w.isWindowModified() and w.doc.project_path is None  # saved nowhere yet: Ctrl+S asks where
    w.doc.undo.mark_clean()
    w.close()


def test_a_restore_that_fails_deletes_nothing(qtbot, tmp_path, recovery_dir):
    """The old restore deleted the recovery folder even when it could not load it."""
    import json

    from volanim_studio.model import Document, autosave

    doc = Document()
    doc.bone_edits.set_bones(samples.mannequin_bones())
    saver = autosave.Autosaver(doc, recovery_dir)
    saver.save()
    (saver.folder / "session.json").write_text(json.dumps({"pid": 2**22 + 12345}))  # a dead session
    bones = read_project(saver.path)["bones"]
    with open(bones, "a") as fh:
        fh.write("joint X 1 2 3\n")  # the only save is damaged: there is no previous one to fall back to
    before = sorted(p.name for p in saver.folder.rglob("*"))
    from volanim_studio.qt.main_window import MainWindow

    w = MainWindow()
    qtbot.addWidget(w)
    w.session.offer_recovery(ask=lambda found: found[0])
    qtbot.waitUntil(lambda: not w.busy, timeout=JOB_TIMEOUT_MS)
    assert "changed or damaged" in (w.last_error or "")
    assert sorted(p.name for p in saver.folder.rglob("*")) == before  # nothing deleted
    assert autosave.find_recoveries(recovery_dir) == [saver.path]  # offered again next time
    w.close()


def test_dead_sessions_without_autosave_are_pruned(tmp_path):
    import json

    from volanim_studio.model import autosave

    dead = tmp_path / "999999999-1"
    dead.mkdir()
    (dead / "session.json").write_text(json.dumps({"pid": 999999999}))
    kept = tmp_path / "999999999-2"
    kept.mkdir()
    (kept / "session.json").write_text(json.dumps({"pid": 999999999}))
    (kept / autosave.RECOVERY_FILE).write_text("{}")
    assert autosave.prune(tmp_path) == 1
    assert not dead.exists() and kept.exists()  # a crashed session with work stays for restore


def test_cube_size_slider_follows_the_plus_minus_keys(qtbot, window):
    """The slider used to stay where it was while +/- resized the cube behind its back."""
    window.doc.bone_edits.set_bones(samples.mannequin_bones())
    qtbot.keyClick(window, Qt.Key_K)
    window.doc.set_cube(window.doc.skeleton.points[0])
    before = window.connect_panel.cube_size.value()
    qtbot.keyClick(window, Qt.Key_Plus)
    qtbot.keyClick(window, Qt.Key_Plus)
    assert window.connect_panel.cube_size.value() == before + 4 == window.doc.settings.cube_size
    assert window.connect_panel.cube_size_label.text() == f"{before + 4:g}"
    window.connect_panel.cube_size.setValue(7)  # and the other way round
    assert window.doc.settings.cube_size == 7


def test_auto_connect_colours_by_bone_and_offers_path_or_nearest_when_path_leaves_most(qtbot, window):
    """One bone at the left hand: a straight path inside the body reaches it from 358 of 4380 points."""
    window.doc.bone_edits.add_bone(J["L_WRIST"], J["L_FINGERS"])
    window.connect_panel.scope.setCurrentText("all")
    assert window.doc.settings.colour_by == "thinness"
    qtbot.mouseClick(window.connect_panel.auto_button, Qt.LeftButton)
    qtbot.waitUntil(lambda: not window.busy, timeout=JOB_TIMEOUT_MS)
    assert window.doc.settings.colour_by == "bone" and window.display_panel.colour_by.currentText() == "bone"
    box = window._error_box
    assert box.isVisible() and "path-or-nearest" in box.text()
    shown = window.doc.visible_count
    assert (window.doc.attachments.bone[:shown] >= 0).sum() < shown / 2
    box.button(QMessageBox.Yes).click()  # "Use path-or-nearest"
    qtbot.waitUntil(lambda: not window.busy, timeout=JOB_TIMEOUT_MS)
    assert window.doc.settings.auto_method == "path-or-nearest"
    assert (window.doc.attachments.bone[:shown] >= 0).all()


def test_the_cube_counts_its_points_and_shift_click_chooses_the_working_bone(qtbot, window):
    assert window.files.open_bones(ASSETS / "mannequin.bones")
    window.doc.attachments.auto(scope="all")
    qtbot.keyClick(window, Qt.Key_K)
    assert window.connect_panel.cube_count.text() == "click a point to place it"
    p = clickable_point(window, J["L_ELBOW"])
    click(qtbot, window, window.scene.display_of_point(p))
    inside = window.handlers[Mode.CUBE].inside()
    assert len(inside) and window.connect_panel.cube_count.text().startswith(f"{len(inside)} shown points")
    thigh = window.doc.bones.index("R_THIGH")
    q = clickable_point(window, (J["R_HIP"] + J["R_KNEE"]) / 2)
    assert window.doc.attachments.bone[q] == thigh
    centre = window.doc.cube_centre.copy()
    click(qtbot, window, window.scene.display_of_point(q), modifier=Qt.ShiftModifier)
    assert window.doc.working_bone == thigh and np.array_equal(window.doc.cube_centre, centre)  # cube stays
    qtbot.keyClick(window, Qt.Key_L)  # Lasso: a click (no outline) chooses the working bone too
    forearm = window.doc.bones.index("L_FOREARM")
    r = clickable_point(window, (J["L_ELBOW"] + J["L_WRIST"]) / 2)
    click(qtbot, window, window.scene.display_of_point(r))
    assert window.doc.working_bone == forearm


def test_the_working_bone_stays_the_bone_after_a_drag_and_open_connections(qtbot, window, tmp_path):
    """#61 item 1: HEAD chosen, rows dragged, then a connections file in another order: the cube still
    connects to HEAD (it used to keep the row and connect to L_CLAVICLE)."""
    assert window.files.open_bones(ASSETS / "mannequin.bones")
    doc, tree = window.doc, window.bone_panel.tree
    head = doc.bones.index("HEAD")
    tree.setCurrentItem(tree.topLevelItem(head))  # the user clicks HEAD's row
    assert doc.working_bone == head
    item = tree.takeTopLevelItem(head)  # what the drop does: HEAD's row moved below the left clavicle...
    tree.insertTopLevelItem(3, item)
    tree.setCurrentItem(item)
    tree.reordered.emit([tree.topLevelItem(i).data(0, Qt.UserRole) for i in range(tree.topLevelItemCount())])
    assert doc.bones.bones[doc.working_bone].label == "HEAD" and doc.working_bone == 3
    assert [it.text(1) for it in tree.selectedItems()] == ["HEAD"]
    assert "HEAD" in window.connect_panel.working.text()
    flipped = samples.mannequin_bones()
    flipped.bones = flipped.bones[::-1]
    io.write_connections(tmp_path / "flipped.connections", flipped)
    assert window.files.open_connections(tmp_path / "flipped.connections")
    assert doc.bones.bones[doc.working_bone].label == "HEAD"
    assert [it.text(1) for it in tree.selectedItems()] == ["HEAD"]
    qtbot.keyClick(window, Qt.Key_K)
    doc.set_cube(np.asarray(J["HEAD"], float) - (0, 0, 12))
    qtbot.mouseClick(window.connect_panel.cube_connect, Qt.LeftButton)
    got = {doc.bones.bones[b].label for b in doc.attachments.bone[doc.attachments.bone >= 0]}
    assert got == {"HEAD"}


def _crashed_autosave(root, doc, pid: int):
    """``doc`` autosaved as a session that crashed (its pid dead)."""
    import json

    from volanim_studio.model import autosave

    saver = autosave.Autosaver(doc, root)
    saver.save()
    (saver.folder / "session.json").write_text(json.dumps({"pid": pid}))
    return saver.path


def test_the_recovery_question_lists_every_autosave_and_only_the_restored_one_goes(qtbot, tmp_path, recovery_dir):
    """A session killed while the question was up stood in front of the one with the work; Yes restored 0
    bones and deleted the real autosave. Now: empty sessions are never offered, each autosave is listed
    with what it holds, and only the chosen one is removed once restored."""
    import os
    import time

    from volanim_studio.model import Document, autosave
    from volanim_studio.qt.main_window import MainWindow
    from volanim_studio.qt.recovery_dialog import RecoveryDialog

    work = Document()
    work.demo_name = "mannequin"
    work.bone_edits.set_bones(samples.mannequin_bones())
    older = _crashed_autosave(recovery_dir, work, 2**22 + 11)
    os.utime(older, (time.time() - 60, time.time() - 60))
    work.bone_edits.rename_joint("L_ELBOW", "L_KNUCKLE")
    newer = _crashed_autosave(recovery_dir, work, 2**22 + 12)
    empty = Document()
    empty.settings.colour_by = "dt"
    assert not autosave.Autosaver(empty, recovery_dir).save()  # nothing made: not written, never offered
    assert autosave.find_recoveries(recovery_dir) == [newer, older]

    # the real dialog: both listed, with what they hold; the older one chosen
    dialog = RecoveryDialog([newer, older], [autosave.describe(newer), autosave.describe(older)])
    qtbot.addWidget(dialog)
    assert dialog.list.count() == 2 and dialog.list.isVisibleTo(dialog)
    assert all("mannequin, 18 bones" in dialog.list.item(i).text() for i in range(2))
    dialog.list.setCurrentRow(1)
    dialog.restore_button.click()
    assert dialog.result() and dialog.chosen == older

    w = MainWindow()
    qtbot.addWidget(w)
    w.session.offer_recovery(ask=lambda found: older)
    qtbot.waitUntil(lambda: not w.busy and "Restored" in w.statusBar().currentMessage(), timeout=JOB_TIMEOUT_MS)
    assert "L_ELBOW" in w.doc.bones.joints  # the older one's bones
    assert "1 other autosave kept" in w.statusBar().currentMessage()
    assert not older.exists() and newer.exists()  # only the restored one went
    assert autosave.find_recoveries(recovery_dir) == [newer]  # the other is offered next time
    w.doc.undo.mark_clean()
    w.close()


def test_a_single_autosave_is_asked_about_in_a_sentence_that_says_what_it_holds(qtbot, tmp_path):
    from volanim_studio.qt.recovery_dialog import RecoveryDialog

    path = tmp_path / "recovery.volanim"
    dialog = RecoveryDialog([path], ["Tue 01 Dec 2026 10:40: mannequin, 18 bones"])
    qtbot.addWidget(dialog)
    dialog.show()
    assert not dialog.list.isVisible()
    assert "Restore the session autosaved Tue 01 Dec 2026 10:40: mannequin, 18 bones?" in \
        dialog.findChildren(type(dialog.layout().itemAt(0).widget()))[0].text()
    dialog.skip_button.click()
    assert not dialog.result() and dialog.chosen is None


def test_fitted_auto_connect_works_when_chosen_alone(qtbot, window):
    """#83 item 11: choosing *fitted* alone attached 0 points and kept 4,380 (the default Points,
    "unconnected", left nothing to do on a connected body); it also needed Points = all and Overwrite."""
    w = window
    assert w.files.open_bones(ASSETS / "mannequin.bones")
    assert w.files.open_connect(ASSETS / "mannequin.0.50.connect")
    panel = w.connect_panel
    before = w.doc.attachments.bone.copy()
    assert panel.scope.currentText() == "unconnected" and not panel.overwrite.isChecked()
    panel.method.setCurrentText("fitted")
    assert not panel.overwrite.isEnabled() and "fitted" in panel.overwrite.toolTip()
    panel.auto_button.click()
    qtbot.waitUntil(lambda: not w.busy, timeout=JOB_TIMEOUT_MS)
    after = w.doc.attachments.bone
    from volanim_core.rig.attach import auto_connect

    shown = np.arange(len(before)) < w.doc.visible_count
    expected, _ = auto_connect(w.doc.skeleton.points, w.doc.bones, w.doc.mask, method="fitted",
                               current=before.copy(), overwrite=True, which=shown, radii=w.doc.skeleton.dt)
    assert (after != before).sum() > 0, "fitted changed nothing"
    assert np.array_equal(after, expected)  # what fitted decides over every shown point
    w.undo()
    assert np.array_equal(w.doc.attachments.bone, before)
