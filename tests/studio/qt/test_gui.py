"""The studio with real widgets, real VTK rendering and simulated mouse and keys."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PySide6.QtCore import Qt

from paths import ASSETS
from volanim_core import io, samples
from volanim_core.geometry import Geometry
from volanim_studio.model.modes import Mode

from ..conftest import JOB_TIMEOUT_MS, click, clickable_point, front_view, open_project

pytestmark = pytest.mark.gui
J = samples.mannequin_bones().joints


def test_thinness_slider_shows_the_prefix(window):
    panel, skel = window.display_panel, window.doc.skeleton
    for step in (0, 250, 500, 900, 1000):
        panel.thinness_slider.setValue(step)
        t = window.doc.thinness
        assert window.scene.shown_points == skel.count_at(t) == int((skel.thinness >= t).sum())
    assert f"{window.scene.shown_points} of {len(skel)} points shown" == panel.count_label.text()


def test_a_held_slider_draws_fewer_points_and_a_coarser_hull(window, monkeypatch):
    """While the thinness slider is held: a spread subset of the points, the coarse hull and no FXAA
    pass (software GL spends most of such a frame on them); on release, everything again."""
    from volanim_core.skeleton.hull import LOD_FACES
    from volanim_studio.scene import view

    monkeypatch.setattr(view, "LOD_POINTS", 1000)  # the mannequin shows ~3 k points: make the LOD bite
    panel, scene, doc = window.display_panel, window.scene, window.doc
    full_faces = len(doc.hull[1])
    assert full_faces > LOD_FACES and doc.hull_lod is not None and len(doc.hull_lod[1]) <= LOD_FACES
    panel.thinness_slider.setValue(0)
    assert scene.shown_points == doc.visible_count > 1000 and scene.hull.drawn_faces == full_faces
    renderer = window.plotter.renderer
    assert renderer.GetUseFXAA()
    panel.thinness_slider.setSliderDown(True)
    panel.thinness_slider.setValue(100)
    assert scene.shown_points == min(1000, doc.visible_count) and scene.hull.drawn_faces == len(doc.hull_lod[1])
    assert not renderer.GetUseFXAA()
    panel.thinness_slider.setSliderDown(False)
    assert scene.shown_points == doc.visible_count and scene.hull.drawn_faces == full_faces
    assert renderer.GetUseFXAA()


def test_a_change_draws_one_frame_and_an_idle_window_draws_none(qtbot, window):
    """Software GL spends 0.1-0.6 s on a frame: the studio drew each slider step three times
    (pyvistaqt's 5 Hz timer, plotter.render(), then the widget's paint) and redrew while idle."""
    renders = []
    window.plotter.ren_win.AddObserver("StartEvent", lambda *_: renders.append(1))
    qtbot.wait(300)  # anything pending from loading is drawn
    renders.clear()
    qtbot.wait(700)  # idle: the old timer drew ~3 frames here
    assert renders == []
    panel = window.display_panel
    for step in (300, 500, 700):
        panel.thinness_slider.setValue(step)
        qtbot.waitUntil(lambda: len(renders) >= 1, timeout=5000)
        qtbot.wait(250)
        assert len(renders) == 1, f"{len(renders)} renders for one slider step"
        renders.clear()


def test_two_clicks_make_a_bone_between_exactly_those_points(qtbot, window):
    qtbot.keyClick(window, Qt.Key_B)
    assert window.mode == Mode.BONES
    a = clickable_point(window, J["L_SHOULDER"])
    b = clickable_point(window, J["L_ELBOW"])
    click(qtbot, window, window.scene.display_of_point(a))
    click(qtbot, window, window.scene.display_of_point(b))
    bones = window.doc.bones
    assert len(bones) == 1
    p, d = bones.segment(0)
    assert np.array_equal(p, window.doc.skeleton.points[a]) and np.array_equal(d, window.doc.skeleton.points[b])
    info = window.point_label.text()
    x, y, z = window.doc.skeleton.points[b]
    assert info.startswith(f"x {x}  y {y}  z {z}") and "DT" in info and "thinness" in info


def test_click_on_hull_with_no_point_behind_picks_nothing(qtbot, window):
    from volanim_studio.scene.view import PICK_RADIUS

    verts, _ = window.doc.hull
    xy, _ = window.scene.project_world(window.scene.world(verts[::7]))
    pts, _ = window.scene.project_world(window.scene._world[: window.doc.visible_count])
    gap = np.array([np.min(np.linalg.norm(pts - p, axis=1)) for p in xy])
    assert gap.max() > 3 * PICK_RADIUS, "the test needs a hull pixel away from every point"
    qtbot.keyClick(window, Qt.Key_B)
    click(qtbot, window, xy[int(np.argmax(gap))])
    assert window.doc.picked_point is None and window.handlers[Mode.BONES].pending is None
    assert len(window.doc.bones) == 0


def test_chain_a_b_c_then_undo_redo_with_keys(qtbot, window):
    qtbot.keyClick(window, Qt.Key_B)
    pts = [clickable_point(window, J[n]) for n in ("L_SHOULDER", "L_ELBOW", "L_WRIST")]
    for p in pts:
        click(qtbot, window, window.scene.display_of_point(p))
    bones = window.doc.bones
    assert len(bones) == 2 and bones.bones[0].distal == bones.bones[1].proximal
    qtbot.keyClick(window, Qt.Key_Escape)
    assert window.handlers[Mode.BONES].pending is None
    qtbot.keyClick(window, Qt.Key_Z, Qt.ControlModifier)
    assert len(window.doc.bones) == 1
    qtbot.keyClick(window, Qt.Key_Z, Qt.ControlModifier | Qt.ShiftModifier)
    assert len(window.doc.bones) == 2
    # right click ends a chain too
    click(qtbot, window, window.scene.display_of_point(clickable_point(window, J["R_SHOULDER"])))
    click(qtbot, window, window.scene.display_of_point(pts[0]), Qt.RightButton)
    assert window.handlers[Mode.BONES].pending is None


def test_symmetrize_left_arm_into_right_arm(qtbot, window):
    doc = window.doc
    doc.bone_edits.add_bone(np.array(J["L_SHOULDER"]), np.array(J["L_ELBOW"]))
    doc.bone_edits.add_bone(np.array(J["L_ELBOW"]), np.array(J["L_WRIST"]))
    for old, new in zip(list(doc.bones.joints), ("L_SHOULDER", "L_ELBOW", "L_WRIST")):
        doc.bone_edits.rename_joint(old, new)
    tree = window.bone_panel.tree
    tree.topLevelItem(0).setSelected(True)
    tree.topLevelItem(1).setSelected(True)
    assert doc.selected_bones == (0, 1)
    qtbot.keyClick(window, Qt.Key_M)
    assert len(doc.bones) == 4
    # (the message named the shared R_ELBOW twice)
    assert window.statusBar().currentMessage().startswith("Mirrored to R_SHOULDER, R_ELBOW, R_WRIST across")
    for name in ("SHOULDER", "ELBOW", "WRIST"):
        left, right = doc.bones.joints[f"L_{name}"], doc.bones.joints[f"R_{name}"]
        assert np.allclose(right, [2 * doc.symmetry_x - left[0], left[1], left[2]])
    assert tree.topLevelItemCount() == 4 and tree.topLevelItem(2).text(2) == "R_SHOULDER"


def test_root_order_by_clicking_bones(qtbot, window, tmp_path):
    assert window.files.open_bones(ASSETS / "mannequin.bones")
    front_view(window)
    qtbot.keyClick(window, Qt.Key_R)
    doc = window.doc
    for name in ("L_SHIN", "R_FOREARM", "HEAD"):
        i = doc.bones.index(name)
        a, b = doc.bones.segment(i)
        click(qtbot, window, window.scene.project_world(window.scene.world(((a + b) / 2)[None]))[0][0])
    assert [b.label for b in doc.bones.bones[:3]] == ["L_SHIN", "R_FOREARM", "HEAD"]
    assert window.bone_panel.tree.topLevelItem(0).text(1) == "L_SHIN"
    qtbot.keyClick(window, Qt.Key_Z, Qt.ControlModifier)
    assert [b.label for b in doc.bones.bones[:2]] == ["L_SHIN", "R_FOREARM"]


def test_rename_in_panel_and_save_reopen_identical(qtbot, window, tmp_path):
    doc = window.doc
    doc.bone_edits.add_bone(np.array(J["L_HIP"]), np.array(J["L_KNEE"]))
    item = window.bone_panel.tree.topLevelItem(0)
    item.setText(1, "L_THIGH")
    item = window.bone_panel.tree.topLevelItem(0)
    item.setText(2, "L_HIP")
    assert doc.bones.bones[0].label == "L_THIGH" and doc.bones.bones[0].proximal == "L_HIP"
    assert window.files.save_bones(tmp_path / "a.bones")
    assert io.read_bones(tmp_path / "a.bones") == doc.bones
    path = window.files.save_project(path=tmp_path / "s.volanim")
    from volanim_studio.qt.main_window import MainWindow

    other = MainWindow()
    qtbot.addWidget(other)
    assert open_project(qtbot, other, path)
    assert other.doc.bones == doc.bones and len(other.doc.skeleton) == len(doc.skeleton)
    other.close()


def test_a_project_reads_as_done_only_once_it_is_applied(qtbot, window, tmp_path):
    """Between two events of the application there must never be a window that is no longer busy
    while its project is still unapplied: the project's files were applied by a second slot on the
    job's `succeeded`, a separate event after the one that ended the job (a busy CI saw it)."""
    from PySide6.QtCore import QCoreApplication, QEvent, QObject

    from volanim_studio.qt.main_window import MainWindow

    window.doc.bone_edits.add_bone(np.array(J["L_HIP"]), np.array(J["L_KNEE"]))
    path = window.files.save_project(path=tmp_path / "s.volanim")
    other = MainWindow()
    qtbot.addWidget(other)
    opened, between = [], []

    class Watch(QObject):
        def eventFilter(self, obj, event):  # noqa: N802 (Qt name)
            if event.type() == QEvent.MetaCall and not other.busy and not opened:
                between.append(len(other.doc.bones))
            return False

    watch = Watch()
    QCoreApplication.instance().installEventFilter(watch)
    try:
        assert other.files.open_project(path, on_opened=opened.append) is not None
        qtbot.waitUntil(lambda: bool(opened) and not other.busy, timeout=JOB_TIMEOUT_MS)
    finally:
        QCoreApplication.instance().removeEventFilter(watch)
    assert opened == [True] and other.doc.bones == window.doc.bones
    assert between == [], "an event ran while the job read as done but its project was not applied"
    other.close()


def test_malformed_file_shows_error_dialog_and_keeps_document(qtbot, window, tmp_path):
    window.doc.bone_edits.add_bone(np.array(J["L_HIP"]), np.array(J["L_KNEE"]))
    before = window.doc.bones
    bad = tmp_path / "bad.bones"
    bad.write_text("joint A 1 2 3\nbone A B\n")
    assert not window.files.open_bones(bad)
    assert f"{bad}:2:" in window.last_error and "no 'joint' line defines" in window.last_error
    assert window._error_box.isVisible()
    assert window.doc.bones == before
    (tmp_path / "short.VOL").write_bytes(b"10 10 10".ljust(100) + b"\0" * 10)
    assert window.files.open_volume(tmp_path / "short.VOL", params={"lo": 1, "hi": None, "fill": False}) is None
    assert "expected 1100" in window.last_error


def test_cancel_leaves_the_gui_responsive(qtbot, window, tmp_path):
    io.write_volume(tmp_path / "frog.VOL", samples.frog().volume)
    messages = []
    window.doc.events.message.connect(lambda text: messages.append(text))
    worker = window.files.open_volume(tmp_path / "frog.VOL", params={"lo": 1, "hi": None, "fill": True})
    assert window.busy
    from PySide6.QtWidgets import QPushButton

    window.jobs.dialog.findChild(QPushButton).click()  # the progress dialog's Cancel button
    qtbot.waitUntil(lambda: not window.busy, timeout=JOB_TIMEOUT_MS)
    assert worker.isFinished() and any("cancelled" in m for m in messages)
    assert len(window.doc.skeleton) < 10000  # still the mannequin
    window.display_panel.thinness_slider.setValue(100)  # and the GUI still works
    assert window.scene.shown_points == window.doc.visible_count


def test_shortcuts_dialog(qtbot, window):
    qtbot.keyClick(window, Qt.Key_F1)
    assert window._shortcut_box.isVisible() and "Ctrl+Z" in window._shortcut_box.text()


HIDPI_SCRIPT = r"""
import sys
import numpy as np
from PySide6.QtWidgets import QApplication
from PySide6.QtTest import QTest
from PySide6.QtCore import Qt, QPoint
app = QApplication([])
sys.path.insert(0, sys.argv[1])
from conftest import front_view, clickable_point
from volanim_studio.qt.main_window import MainWindow
from volanim_core import samples
w = MainWindow(); w.resize(1000, 700); w.show(); QTest.qWaitForWindowExposed(w); w.activateWindow()
w.files.load_demo("mannequin")
while w.busy:
    app.processEvents()
front_view(w)
assert w.plotter.devicePixelRatioF() == 2.0, w.plotter.devicePixelRatioF()
w.set_mode("bones")
J = samples.mannequin_bones().joints
pts = [clickable_point(w, J[n]) for n in ("L_HIP", "L_KNEE")]
for p in pts:
    vx, vy = w.scene.display_of_point(p)
    s = w.plotter.devicePixelRatioF()
    pos = QPoint(round(vx / s), round(w.plotter.height() - 1 - vy / s))
    QTest.mouseClick(w.plotter, Qt.LeftButton, Qt.NoModifier, pos)
a, b = w.doc.bones.segment(0)
assert np.array_equal(a, w.doc.skeleton.points[pts[0]]) and np.array_equal(b, w.doc.skeleton.points[pts[1]])
# the lasso at DPR 2: an outline drawn with the mouse around one point's projection selects it
w.doc.select_bones([0])
w.set_mode("lasso")
w.connect_panel.depth_mode.setCurrentText("through")
target = clickable_point(w, J["L_ANKLE"])
vx, vy = w.scene.display_of_point(target)
s = w.plotter.devicePixelRatioF()
r = 6.0  # device pixels: tighter than the points' spacing on screen
ring = [(vx + r * np.cos(t), vy + r * np.sin(t)) for t in np.linspace(0, 2 * np.pi, 12)]
q = [QPoint(round(x / s), round(w.plotter.height() - 1 - y / s)) for x, y in ring]
QTest.mousePress(w.plotter, Qt.LeftButton, Qt.NoModifier, q[0])
for p in q[1:]:
    QTest.mouseMove(w.plotter, p)
QTest.mouseRelease(w.plotter, Qt.LeftButton, Qt.NoModifier, q[-1])
got = np.flatnonzero(w.doc.attachments.bone == 0)
assert target in got and len(got) <= 4, got
print("HIDPI-OK")
w.close()
"""


def test_picking_at_device_pixel_ratio_2(tmp_path):
    script = tmp_path / "hidpi.py"
    script.write_text(HIDPI_SCRIPT)
    env = dict(os.environ, QT_SCALE_FACTOR="2")
    out = subprocess.run([sys.executable, str(script), str(Path(__file__).parents[1])], env=env, capture_output=True,
                         text=True, timeout=180)
    assert "HIDPI-OK" in out.stdout, out.stderr[-3000:]


def test_threshold_dialog_histogram_and_parameters(qtbot):
    from volanim_studio.qt.threshold_dialog import ThresholdDialog

    vol = samples.mannequin().volume
    dialog = ThresholdDialog(vol, "mannequin.VOL")
    qtbot.addWidget(dialog)
    assert dialog.histogram.counts.shape == (256,) and dialog.histogram.counts.max() > 0
    dialog.lo.setValue(100)
    dialog.hi.setValue(240)
    assert (dialog.histogram.lo, dialog.histogram.hi) == (100, 240)  # the highlighted band follows
    dialog.fill.setChecked(False)
    dialog.metric_box.setCurrentText("345")
    assert dialog.parameters() == {"lo": 100, "hi": 240, "fill": False, "metric": "345",
                                   "min_thinness": 0.5, "spacing": [1.0, 1.0, 1.0]}
    dialog.show()
    image = dialog.grab().toImage()  # painting asks QPaintDevice.metric(): it segfaulted while shadowed
    assert image.width() == dialog.width() * image.devicePixelRatio()


def save_close_reopen(qtbot, window, path):
    """Save ``window``'s project to ``path``, close it, and open the project in a new window."""
    from volanim_studio.qt.main_window import MainWindow

    saved = window.files.save_project(path=path)
    window.close()
    again = MainWindow()
    qtbot.addWidget(again)
    assert open_project(qtbot, again, saved)
    return again


def test_the_voxel_spacing_is_shown_kept_and_saved(qtbot, tmp_path):
    """The threshold dialog had no spacing field: a raw .vol's 1.5 mm slices could not be said (issue #18)."""
    import pyvista as pv

    from volanim_studio.qt.main_window import MainWindow
    from volanim_studio.qt.threshold_dialog import ThresholdDialog

    vol = np.zeros((30, 20, 16), np.uint8)
    vol[5:25, 5:15, 4:12] = 200
    img = pv.ImageData(dimensions=vol.shape, spacing=(1.0, 1.0, 1.5))
    img.point_data["v"] = vol.ravel(order="F")
    img.save(tmp_path / "box.vti")
    dialog = ThresholdDialog(vol, "box.vti", spacing=(1.0, 1.0, 1.5))
    qtbot.addWidget(dialog)
    assert [b.value() for b in dialog.spacing] == [1.0, 1.0, 1.5] and dialog.spacing[2].toolTip()
    dialog.spacing[2].setValue(2.0)
    params = dialog.parameters()
    assert params["spacing"] == [1.0, 1.0, 2.0]
    w = MainWindow()
    qtbot.addWidget(w)
    w.files.open_volume(tmp_path / "box.vti", params=params)
    qtbot.waitUntil(lambda: not w.busy, timeout=JOB_TIMEOUT_MS)
    # the user's 1 x 1 x 2 mm is kept; the studio works, as `volanim skeletonize` does, on 1 mm cubes
    # (#35: spheres are spheres in the body), so the 16 slices 2 mm apart became 31 slices 1 mm apart
    assert w.doc.segmentation["spacing"] == [1.0, 1.0, 2.0]
    assert w.doc.spacing == (1.0, 1.0, 1.0) and w.doc.volume.shape == (30, 20, 31)
    assert w.doc.skeleton.geometry.spacing == (1.0, 1.0, 1.0)
    w.doc.pick_point(0)  # the status bar says where the point is in the scan, in millimetres
    p = w.doc.skeleton.points[0]
    assert f"({p[0]:.1f}, {p[1]:.1f}, {p[2]:.1f}) mm" in w.point_label.text()
    again = save_close_reopen(qtbot, w, tmp_path / "box.volanim")
    assert again.doc.segmentation["spacing"] == [1.0, 1.0, 2.0] and again.last_error is None
    assert again.doc.volume.shape == (30, 20, 31)
    again.close()


def test_close_while_a_job_runs_waits_for_it_instead_of_aborting(qtbot):
    """Closing used to wait 5 s and then destroy the running QThread: SIGABRT for the whole app."""
    import time

    from volanim_studio.qt.main_window import MainWindow

    w = MainWindow()
    qtbot.addWidget(w)
    w.show()
    seen = {}

    def stubborn(progress, cancel):  # a first numba compile: it cannot look at the cancel flag for a while
        time.sleep(5.5)
        seen["cancel"] = cancel()
        return "done"

    worker = w.jobs.run("A long job", stubborn, lambda result: seen.setdefault("result", result))
    messages = []
    w.doc.events.message.connect(lambda text: messages.append(text))
    w.close()
    assert worker.isFinished() and not w.busy
    assert seen["cancel"] is True  # close asked the job to stop
    assert any("Finishing" in m for m in messages)  # and said what it was waiting for


def test_reopening_a_project_gives_back_the_skeleton_that_was_connected(qtbot, tmp_path):
    """Reopening used to re-segment with fill cavities off and the default thinness floor."""
    from volanim_studio.qt.main_window import MainWindow

    vol = np.zeros((40, 30, 30), np.uint8)
    vol[5:35, 5:25, 5:25] = 200
    vol[15:25, 12:18, 12:18] = 0  # a cavity: filled or not, the skeleton differs
    io.write_volume(tmp_path / "box.VOL", vol)
    params = {"lo": 1, "hi": None, "fill": True, "metric": "345", "min_thinness": 0.25}
    first = MainWindow()
    qtbot.addWidget(first)
    first.files.open_volume(tmp_path / "box.VOL", params=params)
    qtbot.waitUntil(lambda: not first.busy, timeout=JOB_TIMEOUT_MS)
    skeleton = first.doc.skeleton
    second = save_close_reopen(qtbot, first, tmp_path / "box.volanim")
    assert second.doc.skeleton == skeleton and second.doc.skeleton.metric == "345"
    assert second.doc.segmentation == {**params, "spacing": [1.0, 1.0, 1.0], "series": None}
    assert bool(second.doc.mask[20, 15, 15])  # the cavity is filled
    second.close()


def test_view_volume_or_mesh_opens_a_window_of_its_own_and_leaves_the_document(qtbot, window, tmp_path):
    from volanim_core.io import write_volume
    from volanim_core.io.mesh_files import write_mesh
    from volanim_core.skeleton.hull import isosurface

    vol = np.zeros((20, 16, 12), np.uint8, order="F")
    vol[4:15, 3:12, 2:10] = 200
    write_volume(tmp_path / "posed.vti", vol, Geometry(origin=(5, 6, 7)))
    verts, faces = isosurface(vol > 0)
    write_mesh(tmp_path / "hull.ply", verts, faces)
    points_before = len(window.doc.skeleton)
    for name in ("posed.vti", "hull.ply"):
        viewer = window.files.view_file(tmp_path / name)
        assert viewer is not None and viewer.isVisible() and "body" in viewer.plotter.renderer.actors
        assert name in viewer.windowTitle() and name in window.statusBar().currentMessage()
        viewer.close()
    assert len(window.doc.skeleton) == points_before and window.doc.volume_path != str(tmp_path / "posed.vti")
    (tmp_path / "bad.ply").write_text("not a mesh")
    assert window.files.view_file(tmp_path / "bad.ply") is None
    assert "bad.ply" in window.last_error
    # a sequence: the file dialog picks the zarr.json inside NAME.zarr ("unknown volume format" before)
    from core.render.test_render import make_sequence

    make_sequence(tmp_path / "walk.zarr", frames=2)
    viewer = window.files.view_file(tmp_path / "walk.zarr" / "zarr.json")
    assert viewer is not None and "frame 100" in viewer.what and "body" in viewer.plotter.renderer.actors
    viewer.close()


def test_f1_lists_every_keyboard_shortcut_of_the_menus(window):
    """The F1 list is typed by hand; every shortcut a menu action has must be in it (it missed
    Ctrl+Shift+S and Ctrl+Q)."""
    import re

    from PySide6.QtGui import QAction, QKeySequence

    from volanim_studio.qt.main_window import SHORTCUTS

    listed = {t for k, _ in SHORTCUTS for t in re.split(r" / |, ", k)}
    keys = {a.shortcut().toString(QKeySequence.PortableText) for a in window.findChildren(QAction)} - {""}
    assert {"Ctrl+Shift+S", "Ctrl+Q", "F1"} <= keys
    assert not sorted(keys - listed), f"shortcuts missing from F1: {sorted(keys - listed)}"


def test_an_empty_studio_answers_f5_and_ctrl_s_in_words_and_writes_nothing(qtbot, tmp_path):
    """F5 on an empty studio printed a traceback; Ctrl+S wrote an empty project (issue #18)."""
    from volanim_studio.qt.main_window import MainWindow

    w = MainWindow()
    qtbot.addWidget(w)
    w.show()
    qtbot.waitExposed(w)
    assert w.previews.preview() is None
    assert "nothing loaded yet: open a volume, a demo or a project first" in w.last_error
    w.last_error = None
    w.previews.live_preview()  # what a timeline frame change asks for: a status message, no dialog
    assert w.last_error is None and "nothing loaded yet" in w.statusBar().currentMessage()
    out = tmp_path / "out"
    out.mkdir()
    assert w.files.save_project(path=out / "empty.volanim") is None
    assert "nothing to save yet" in w.last_error
    assert list(out.iterdir()) == [] and not w.busy
    w.close()
