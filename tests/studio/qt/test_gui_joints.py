"""Smooth joints in the studio (#42): the Reconstruct tab's Joints choice re-runs the preview, the report
follows it, the project keeps it, and a .connect that records smooth joints sets it."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core import io, samples
from volanim_core.rig.skinning import Joints

from ..conftest import JOB_TIMEOUT_MS, open_project, rig_and_pose, save_project
from .test_gui_pose import drag

pytestmark = pytest.mark.gui

J = samples.mannequin_bones().joints


def test_smooth_joints_mend_the_stump_a_rigid_shoulder_leaves(qtbot, window, tmp_path):
    w = rig_and_pose(qtbot, window)
    doc = w.doc
    doc.settings.body = "spheres"  # the thesis's re-growth, which the points' attachments move (not the owned body)
    ua, spine = doc.bones.index("L_UPPERARM"), doc.bones.index("SPINE")
    near = np.flatnonzero((np.linalg.norm(doc.skeleton.points - J["L_SHOULDER"], axis=1) < 12)
                          & (doc.attachments.bone == ua))
    doc.attachments.assign(near, spine)  # a rig's mistake at the shoulder
    doc.select_bones([ua])
    drag(qtbot, w, 1, range(0, -91, -10))
    qtbot.waitUntil(lambda: not w.busy and w.doc.preview.report is not None, timeout=JOB_TIMEOUT_MS)
    assert "STUMP left behind near L_SHOULDER" in w.verdict_label.text()
    rigid = w.doc.preview.report
    assert not w.reconstruct_panel.blend.isEnabled()

    w.reconstruct_panel.joint_kind.setCurrentText("smooth")  # what the user picks: the preview runs again
    assert doc.settings.joints == "smooth" and w.reconstruct_panel.blend.isEnabled()
    qtbot.waitUntil(lambda: not w.busy and w.doc.preview.report is not rigid, timeout=JOB_TIMEOUT_MS)
    smooth = w.doc.preview.report
    assert doc.pose.tskel().joints == Joints("smooth", 1.0)
    assert smooth.healthy and smooth.cracks < rigid.cracks
    assert "one piece, no stump" in w.verdict_label.text()

    shown = []
    doc.events.preview.connect(lambda **_: shown.append(doc.preview))
    w.previews.preview()  # a preview the old way is running when the blend changes (two steps of the box)
    assert w.busy
    w.reconstruct_panel.blend.setValue(1.25)
    w.reconstruct_panel.blend.setValue(1.5)
    assert doc.settings.blend == 1.5
    qtbot.waitUntil(lambda: not w.busy and not w.previews._again.isActive() and bool(shown), timeout=JOB_TIMEOUT_MS)
    assert "A job is running" not in w.statusBar().currentMessage()  # the change was not dropped
    assert shown[-1].report is not None and shown[-1].report.healthy
    path = save_project(qtbot, w, path=tmp_path / "p.volanim")
    assert path is not None
    # the project's .connect records them
    saved = [f.read_text() for f in (tmp_path / "p.volanim.d").glob("*.connect")]
    assert len(saved) == 1 and all("\n# joints: smooth 1.5\n" in t for t in saved)

    from volanim_studio.qt.main_window import MainWindow

    other = MainWindow()
    qtbot.addWidget(other)
    assert open_project(qtbot, other, path)
    assert other.doc.settings.joints == "smooth" and other.doc.settings.blend == 1.5
    assert other.reconstruct_panel.joint_kind.currentText() == "smooth"
    assert other.reconstruct_panel.blend.value() == 1.5
    assert other.doc.pose.tskel().joints == Joints("smooth", 1.5)
    other.close()


def test_a_connect_recording_smooth_joints_sets_the_tab(qtbot, window, tmp_path):
    from paths import ASSETS

    conn = io.read_connect(ASSETS / "mannequin.0.50.connect").with_joints(Joints("smooth", 2.0))
    io.write_connect(tmp_path / "smooth.connect", conn)
    assert window.files.open_bones(ASSETS / "mannequin.bones")
    assert window.files.open_connect(tmp_path / "smooth.connect")
    assert window.doc.settings.joints == "smooth" and window.doc.settings.blend == 2.0
    assert window.reconstruct_panel.joint_kind.currentText() == "smooth"
