"""Screenshots of the studio for the README, taken from real widgets under Xvfb.

Run: make screenshots   (xvfb-run -a .venv/bin/python docs/make_screenshots.py)
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
ROOT = HERE.parent


def grab(window, path: Path, beside=None) -> None:
    """The whole window: Qt widgets from grab(), the 3D view from VTK (grab() cannot read GL); ``beside``, a
    dialog (drawn by Qt alone), to the window's right as it stands on the desktop."""
    from PySide6.QtCore import QPoint
    from PySide6.QtGui import QImage, QPainter

    pix = window.grab()
    shot = np.ascontiguousarray(window.plotter.screenshot(return_img=True)[:, :, :3])
    h, w, _ = shot.shape
    img = QImage(shot.data, w, h, 3 * w, QImage.Format_RGB888).scaled(window.plotter.size())
    painter = QPainter(pix)
    painter.drawImage(window.plotter.mapTo(window, QPoint(0, 0)), img)
    painter.end()
    if beside is not None:
        from PySide6.QtGui import QColor, QPixmap

        other = beside.grab()
        both = QPixmap(pix.width() + other.width() + 12, max(pix.height(), other.height()))
        both.fill(QColor(60, 60, 60))
        painter = QPainter(both)
        painter.drawPixmap(0, 0, pix)
        painter.drawPixmap(pix.width() + 12, 0, other)
        painter.end()
        pix = both
    pix.save(str(path))
    print(f"wrote {path}")


def main() -> None:
    from PySide6.QtWidgets import QApplication

    from volanim_core import samples
    from volanim_studio.model.interaction import Mode
    from volanim_studio.qt.main_window import MainWindow

    app = QApplication.instance() or QApplication(sys.argv[:1])
    w = MainWindow()
    w.resize(1500, 900)
    w.show()
    import time

    def wait_idle():
        while w.busy:  # (sleep: every processEvents() call from Python costs; see tests/studio/test_qt_binding.py)
            app.processEvents()
            time.sleep(0.01)

    w.files.load_demo("mannequin")
    wait_idle()
    w.files.open_bones(ROOT / "assets" / "mannequin.bones")
    w.scene.front_view()
    w.set_mode(Mode.BONES)
    w.doc.select_bones([w.doc.bones.index("L_UPPERARM")])
    pts = w.doc.skeleton.points[: w.doc.visible_count]
    w.doc.pick_point(int(np.argmin(((pts - samples.mannequin_bones().joints["L_ELBOW"]) ** 2).sum(1))))
    w.doc.message("Bones: click a point to start, click another to add a bone; keep clicking to continue the chain.")
    for _ in range(5):
        app.processEvents()
    grab(w, HERE / "studio-bones.png")
    w.panel_tabs.setCurrentIndex(1)
    w.display_panel.thinness_slider.setValue(700)
    w.display_panel.colour_by.setCurrentText("dt")
    for _ in range(5):
        app.processEvents()
    grab(w, HERE / "studio-thinness.png")

    # Connect: auto-connect, then a lasso being drawn over the left shoulder
    w.display_panel.thinness_slider.setValue(0)
    w.doc.attachments.auto(scope="all")
    w.doc.select_bones([w.doc.bones.index("L_UPPERARM")])
    w.set_mode(Mode.LASSO)
    w.display_panel.point_size.setValue(5)
    c = w.scene.project_world(w.scene.world(np.array([samples.mannequin_bones().joints["L_SHOULDER"]])))[0][0]
    w.scene.lasso.points = [(c[0] + 40 * np.cos(t), c[1] + 30 * np.sin(t)) for t in np.linspace(0, 2 * np.pi, 40)]
    w.scene.lasso.draw()
    for _ in range(5):
        app.processEvents()
    grab(w, HERE / "studio-connect.png")
    w.scene.lasso.points = None
    w.scene.lasso.draw()

    # Pose: a deliberate mistake (the shoulder's points on the torso), the break, the fix

    from volanim_studio.model.interaction import Mode as M

    doc = w.doc
    ua, spine = doc.bones.index("L_UPPERARM"), doc.bones.index("SPINE")
    shoulder = samples.mannequin_bones().joints["L_SHOULDER"]
    stump = np.flatnonzero((np.linalg.norm(doc.skeleton.points - shoulder, axis=1) < 20)
                           & (doc.attachments.bone == ua))
    doc.attachments.assign(stump, spine)
    w.set_mode(M.POSE)
    doc.select_bones([ua])
    doc.pose.set_angles(ua, (0, -90, 0), merge=False)

    def preview_and_wait():
        w.previews.preview()
        wait_idle()
        for _ in range(5):
            app.processEvents()

    preview_and_wait()
    w.panel_tabs.setCurrentWidget(w.reconstruct_panel)
    grab(w, HERE / "studio-pose-broken.png")
    # the fix: back in Lasso mode, an outline over the stump connects it to L_UPPERARM
    w.set_mode(M.LASSO)
    w.scene.front_view()
    shown, xy, depth, view_depth = w.scene.shown_projection()
    sel = np.isin(shown, stump)
    lo, hi = xy[sel].min(0) - 4, xy[sel].max(0) + 4
    w.doc.settings.lasso_depth = "through"
    w.handlers[M.LASSO].finish([(lo[0], lo[1]), (hi[0], lo[1]), (hi[0], hi[1]), (lo[0], hi[1])], xy, depth,
                               view_depth, shown)
    w.set_mode(M.POSE)
    preview_and_wait()
    w.panel_tabs.setCurrentWidget(w.reconstruct_panel)
    grab(w, HERE / "studio-pose-fixed.png")

    # Timeline: the real walk clip on the mannequin, mid-stride, previewed in full
    w.timeline.load_bvh(samples.walk_clip())  # read in the reader thread, then retargeted
    while w.readers.busy:
        app.processEvents()
        time.sleep(0.005)
    w.doc.settings.current_frame = 330
    doc.settings.preview_mode = "sampled"
    w.scene.front_view()
    preview_and_wait()
    w.panel_tabs.setCurrentWidget(w.pose_panel)
    grab(w, HERE / "studio-timeline.png")

    # The transfer-function editor (View -> Transfer function, Ctrl+T) over the same frame: flesh faint,
    # the bones opaque ivory, the skin clear, its points on the preview's histogram
    from volanim_core.transfer_function import TransferFunction

    editor = w.show_transfer_editor()
    editor.resize(620, 420)
    doc.transfer.set(TransferFunction(
        [0, 80, 90, 130, 165, 200, 215, 230, 250],
        [[0, 0, 0, 0], [0, 0, 0, 0], [0.95, 0.85, 0.35, 0.02], [0.8, 0.2, 0.15, 0.05], [0.9, 0.45, 0.4, 0.06],
         [0.9, 0.5, 0.45, 0.0], [0.9, 0.5, 0.45, 0.0], [0.95, 0.92, 0.8, 0.9], [1, 1, 1, 1]]), "screenshot")
    editor.select(7)
    for _ in range(5):
        app.processEvents()
    grab(w, HERE / "studio-transfer.png", beside=editor)
    doc.transfer.set(None, "back to the mode's look")
    editor.close()

    # A colour scan: the colour mannequin, arm raised, its sampled preview in colour and the hull tinted
    w.timeline.stop()
    w.doc.undo.mark_clean()
    w.files.load_demo("mannequin-colour")
    wait_idle()
    w.files.open_bones(ROOT / "assets" / "mannequin.bones")
    w.files.open_connect(ROOT / "assets" / "mannequin.0.50.connect")
    w.set_mode(M.POSE)
    doc = w.doc
    doc.settings.preview_mode = "sampled"
    doc.settings.preview_kernel = 3
    doc.pose.set_angles(doc.bones.index("L_UPPERARM"), (0, -60, 0), merge=False)
    w.scene.front_view()
    preview_and_wait()
    w.panel_tabs.setCurrentWidget(w.reconstruct_panel)
    grab(w, HERE / "studio-colour.png")
    w.doc.undo.mark_clean()  # the session's edits are not for keeping: no "Save changes?", no autosave left
    w.close()


if __name__ == "__main__":
    main()
