"""The studio's main window: 3D view in the centre, modes, panels, menus, status.

    QtInteractor --SceneView.pick--> PickEvent --> active mode handler --> Document
    Document events --> SceneView (actors), DisplayPanel, BonePanel, status bar
    File menu --> volanim_core readers (errors: a dialog naming the file and line)
    Open volume --> ThresholdDialog --> Worker(tasks.prepare_volume) with progress/cancel
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PySide6.QtCore import Qt, QTimer
from PySide6.QtGui import QAction, QActionGroup, QKeySequence
from PySide6.QtWidgets import QDockWidget, QFileDialog, QLabel, QMainWindow, QMessageBox, QProgressDialog, QTabWidget
from pyvistaqt import QtInteractor

from volanim_core import io
from volanim_core.errors import FormatError

from . import tasks
from .model import autosave
from .model.document import Document, read_project
from .model.modes import HANDLERS, Mode, PickEvent
from .model.preview import make_preview
from .qt_connect_panel import ConnectPanel
from .qt_panels import BonePanel, DisplayPanel
from .qt_pose_panel import PosePanel, ReconstructPanel
from .qt_scene import SceneView
from .qt_threshold_dialog import ThresholdDialog
from .qt_worker import Worker

SHORTCUTS = [
    ("V", "View mode: click points to inspect them"),
    ("B", "Bones mode: click point A, then B to add a bone; keep clicking to chain"),
    ("R", "Root order mode: click bones in order"),
    ("K", "Cube mode: click a point to place the cube; arrows / PgUp / PgDn nudge, +/- size, C connect, X remove"),
    ("L", "Lasso mode: drag an outline to connect the points under it to the working bone (Ctrl: remove)"),
    ("Ctrl+A", "Auto-connect"),
    ("P", "Pose mode: click a bone, turn it with the Pose sliders; the preview follows live"),
    ("F5", "Preview the reconstruction at full resolution, with the breakage report"),
    ("Esc", "End the bone chain / restart the root order"),
    ("Right click", "End the bone chain"),
    ("Delete", "Remove the selected bones"),
    ("M", "Symmetrize the selected bones (L_ ↔ R_)"),
    ("Ctrl+Z / Ctrl+Shift+Z", "Undo / redo"),
    ("Ctrl+O", "Open a volume"),
    ("Ctrl+S", "Save the project"),
    ("Left drag / right drag / wheel", "Rotate / zoom / zoom the view"),
]


class MainWindow(QMainWindow):
    def __init__(self, doc: Document | None = None, *, autosave_every_edits: int = 5,
                 autosave_seconds: float = 60.0):
        super().__init__()
        self.doc = doc or Document()
        self.setWindowTitle("volanim studio")
        self.resize(1400, 900)
        self.plotter = QtInteractor(self)
        self.setCentralWidget(self.plotter.interactor if hasattr(self.plotter, "interactor") else self.plotter)
        self.scene = SceneView(self.plotter, self.doc, on_pick=self.handle_pick)
        self.handlers = {m: cls(self.doc) for m, cls in HANDLERS.items()}
        self.mode = Mode.VIEW
        self.worker: Worker | None = None
        self.progress: QProgressDialog | None = None
        self.last_error: str | None = None
        self._error_box: QMessageBox | None = None

        self.display_panel = DisplayPanel(self.doc, self.scene)
        self.bone_panel = BonePanel(self.doc)
        self.connect_panel = ConnectPanel(self.doc, self.handlers[Mode.CUBE], self.handlers[Mode.LASSO])
        self.pose_panel = PosePanel(self.doc)
        self.reconstruct_panel = ReconstructPanel(self.doc)
        self.scene.on_lasso = self.handle_lasso
        tabs = self.panel_tabs = QTabWidget()
        tabs.addTab(self.bone_panel, "Bones")
        tabs.addTab(self.connect_panel, "Connect")
        tabs.addTab(self.pose_panel, "Pose")
        tabs.addTab(self.reconstruct_panel, "Reconstruct")
        tabs.addTab(self.display_panel, "Display")
        self._posing_drag = False
        self._rest_preview = None
        self.live_timings: list[float] = []  # seconds per live update (pose change -> drawn)
        tabs.setMinimumWidth(420)
        dock = QDockWidget("Panels", self)
        dock.setWidget(tabs)
        dock.setFeatures(QDockWidget.DockWidgetMovable | QDockWidget.DockWidgetFloatable)
        self.addDockWidget(Qt.RightDockWidgetArea, dock)
        self.point_label = QLabel("")
        self.statusBar().addPermanentWidget(self.point_label)
        self._build_actions()
        self.doc.events.message.connect(lambda text: self.statusBar().showMessage(text, 15000))
        self.doc.events.picked.connect(self._on_picked_changed)
        self.doc.events.attachments.connect(lambda **_: self._on_picked_changed(index=self.doc.picked_point))
        self.doc.events.bones.connect(lambda **_: self._on_picked_changed(index=self.doc.picked_point))
        self.doc.undo.events.changed.connect(self._on_undo_changed)
        self.doc.events.project.connect(lambda path: self.setWindowTitle(f"volanim studio — {Path(path).name}"))
        self.autosaver = autosave.Autosaver(self.doc, every_edits=autosave_every_edits,
                                            every_seconds=autosave_seconds)
        self.doc.undo.events.changed.connect(self._autosave_after_edit)
        self.autosave_timer = QTimer(self)
        self.autosave_timer.timeout.connect(self._autosave_tick)
        self.autosave_timer.start(int(1000 * min(autosave_seconds, 60.0)))
        self.set_mode(Mode.VIEW)

    # ------------------------------------------------------------ autosave
    def _autosave_after_edit(self, **_) -> None:
        try:
            self.autosaver.edited()
        except (OSError, ValueError) as exc:
            self.doc.message(f"Autosave failed: {exc}")

    def _autosave_tick(self) -> None:
        try:
            self.autosaver.tick()
        except (OSError, ValueError) as exc:
            self.doc.message(f"Autosave failed: {exc}")

    def offer_recovery(self, ask=None) -> Worker | None:
        """If an earlier session crashed, offer to restore its last autosave.

        ``ask(path) -> bool`` replaces the question dialog (tests).
        """
        found = autosave.find_recoveries()
        if not found:
            return None
        latest = found[0]
        if ask is None:
            answer = QMessageBox.question(
                self, "Restore unsaved work?", f"volanim studio did not close properly last time.\n"
                f"Restore the session autosaved at {latest.parent.name}?", QMessageBox.Yes | QMessageBox.No)
            restore = answer == QMessageBox.Yes
        else:
            restore = ask(latest)
        if not restore:
            for f in found:
                autosave.discard(f)
            return None
        worker = self.open_project(latest)

        def cleanup(_=None):
            self.doc.project_path = None  # a restored session saves where the user says, not into the cache
            self.setWindowTitle("volanim studio — restored")
            for f in found:
                autosave.discard(f)
            self.doc.message(f"Restored the autosaved session ({len(self.doc.bones)} bones).")

        if worker is not None:
            worker.succeeded.connect(cleanup)
        else:
            cleanup()
        return worker

    # ------------------------------------------------------------- actions
    def _action(self, text, slot, shortcut=None, checkable=False, menu=None) -> QAction:
        a = QAction(text, self)
        if shortcut:
            a.setShortcut(QKeySequence(shortcut))
            a.setShortcutContext(Qt.WindowShortcut)
        a.setCheckable(checkable)
        a.triggered.connect(slot)
        self.addAction(a)
        if menu is not None:
            menu.addAction(a)
        return a

    def _build_actions(self) -> None:
        bar = self.menuBar()
        file = bar.addMenu("&File")
        self._action("Open &volume…", lambda: self.open_volume_dialog(), "Ctrl+O", menu=file)
        self._action("Open &skeleton (.mskel)…", lambda: self._open_dialog("mskel"), menu=file)
        self._action("Open &bones…", lambda: self._open_dialog("bones"), menu=file)
        self._action("Open &project…", lambda: self._open_dialog("project"), menu=file)
        file.addSeparator()
        self._action("&Save project", self.save_project, "Ctrl+S", menu=file)
        self._action("Save project &as…", lambda: self.save_project(ask=True), "Ctrl+Shift+S", menu=file)
        self._action("Save bones…", lambda: self._save_dialog("bones"), menu=file)
        self._action("Save connections…", lambda: self._save_dialog("connections"), menu=file)
        self._action("Screenshot…", lambda: self._save_dialog("png"), menu=file)
        file.addSeparator()
        self._action("&Quit", self.close, "Ctrl+Q", menu=file)
        edit = bar.addMenu("&Edit")
        self.undo_action = self._action("Undo", self.undo, "Ctrl+Z", menu=edit)
        self.redo_action = self._action("Redo", self.redo, "Ctrl+Shift+Z", menu=edit)
        self._action("Delete selected bones", lambda: self.key("Delete"), "Delete", menu=edit)
        self._action("Symmetrize selected bones", self.symmetrize, "M", menu=edit)
        self._action("End chain", lambda: self.key("Escape"), "Esc")
        modes = bar.addMenu("&Mode")
        toolbar = self.addToolBar("Modes")
        group = QActionGroup(self)
        self.mode_actions = {}
        for mode, text, key in ((Mode.VIEW, "View", "V"), (Mode.BONES, "Bones", "B"),
                                (Mode.ROOT_ORDER, "Root order", "R"), (Mode.CUBE, "Cube", "K"),
                                (Mode.LASSO, "Lasso", "L"), (Mode.POSE, "Pose", "P")):
            a = self._action(text, lambda _=False, m=mode: self.set_mode(m), key, checkable=True, menu=modes)
            group.addAction(a)
            toolbar.addAction(a)
            self.mode_actions[mode] = a
        toolbar.addSeparator()
        self.remove_action = self._action("Remove bones", self._toggle_remove, checkable=True)
        toolbar.addAction(self.remove_action)
        sym = self._action("Symmetrize", self.symmetrize)
        toolbar.addAction(sym)
        # cube keys: live only in cube mode, so arrows still move through lists elsewhere
        self.cube_actions = [
            self._action(f"Cube {name}", lambda _=False, n=name: self.key(n), key)
            for name, key in (("Left", "Left"), ("Right", "Right"), ("Up", "Up"), ("Down", "Down"),
                              ("PageUp", "PgUp"), ("PageDown", "PgDown"), ("Plus", "+"), ("Minus", "-"),
                              ("C", "C"), ("X", "X"))]
        connect_menu = bar.addMenu("&Connect")
        self._action("Auto-connect", self.auto_connect, "Ctrl+A", menu=connect_menu)
        self._action("Mirror connectivity of selected bones", self.mirror_connectivity, menu=connect_menu)
        self._action("Save .connect…", lambda: self._save_dialog("connect"), menu=connect_menu)
        self._action("Open .connect…", lambda: self._open_dialog("connect"), menu=connect_menu)
        pose = bar.addMenu("&Pose")
        self._action("Preview reconstruction", lambda: self.preview(), "F5", menu=pose)
        self._action("Reset pose", lambda: self.doc.pose.reset(), menu=pose)
        self._action("Load pose (.trans)…", lambda: self._open_dialog("trans"), menu=pose)
        self._action("Save pose (.trans)…", lambda: self._save_dialog("trans"), menu=pose)
        self._action("Save frame (.tskel)…", lambda: self._save_dialog("tskel"), menu=pose)
        self._action("Export reconstruction…", lambda: self._save_dialog("volume"), menu=pose)
        self.pose_panel.drag_started.connect(self._pose_drag_started)
        self.pose_panel.drag_finished.connect(self._pose_drag_finished)
        self.pose_panel.load_trans.clicked.connect(lambda: self._open_dialog("trans"))
        self.pose_panel.save_trans.clicked.connect(lambda: self._save_dialog("trans"))
        self.pose_panel.save_tskel.clicked.connect(lambda: self._save_dialog("tskel"))
        rp = self.reconstruct_panel
        rp.preview_button.clicked.connect(lambda: self.preview())
        rp.show_rest.toggled.connect(lambda _: self._draw_preview())
        rp.slices.toggled.connect(self._slices_toggled)
        rp.export_button.clicked.connect(lambda: self._save_dialog("volume"))
        rp.joint_clicked.connect(self.jump_to_joint)
        self.doc.events.pose.connect(self._on_pose_changed)
        self.doc.events.preview.connect(lambda **_: self._draw_preview())
        self.doc.events.attachments.connect(self._forget_rest)
        self.doc.events.bones.connect(self._forget_rest)
        self._live_timer = QTimer(self)
        self._live_timer.setSingleShot(True)
        self._live_timer.setInterval(0)
        self._live_timer.timeout.connect(self.live_preview)
        self.connect_panel.auto_button.clicked.connect(self.auto_connect)
        self.connect_panel.mirror_button.clicked.connect(self.mirror_connectivity)
        help_menu = bar.addMenu("&Help")
        self._action("&Shortcuts", self.show_shortcuts, "F1", menu=help_menu)
        self._on_undo_changed()

    def set_mode(self, mode: Mode) -> None:
        self.handlers[self.mode].leave()
        self.mode = Mode(mode)
        self.mode_actions[self.mode].setChecked(True)
        self.scene.set_lasso_enabled(self.mode == Mode.LASSO)
        self.scene.set_posing(self.mode == Mode.POSE)
        if self.mode == Mode.POSE:
            self.panel_tabs.setCurrentWidget(self.pose_panel)
        for a in getattr(self, "cube_actions", []):
            a.setEnabled(self.mode == Mode.CUBE)
        if self.mode in (Mode.CUBE, Mode.LASSO):
            self.panel_tabs.setCurrentWidget(self.connect_panel)
            if self.scene.colour_by != "bone":
                self.display_panel.colour_by.setCurrentText("bone")
        self.handlers[self.mode].enter()

    def handle_lasso(self, polygon, ctrl: bool) -> None:
        shown, xy, depth, view_depth = self.scene.shown_projection()
        lasso = self.handlers[Mode.LASSO]
        lasso.finish(polygon, xy, depth, view_depth, shown, remove=True if ctrl else None)

    # -------------------------------------------------------------- posing
    def _pose_drag_started(self) -> None:
        self._posing_drag = True
        if self.worker is not None and getattr(self.worker, "is_preview", False):
            self.worker.cancel()  # a newer pose is coming

    def _pose_drag_finished(self) -> None:
        self._posing_drag = False
        if self.mode == Mode.POSE and len(self.doc.attachments.bone) and (self.doc.attachments.bone >= 0).any():
            self.preview()

    def _on_pose_changed(self, **_) -> None:
        if self._posing_drag and self.reconstruct_panel.live.isChecked():
            self._live_timer.start()  # coalesced: one live preview per event-loop pass

    def live_preview(self) -> None:
        """Half-resolution binary or bone preview on the GUI thread (tens of ms on the mannequin)."""
        import time

        t0 = time.perf_counter()
        mode = self.reconstruct_panel.mode.currentText()
        mode = mode if mode in ("binary", "bone") else "bone"
        try:
            p = make_preview(self.doc.pose.tskel(), mode=mode, factor=2, padding=2)
        except ValueError as exc:
            self.doc.message(str(exc))
            return
        self.doc.set_preview(p)  # drawn by the scene's coalesced render: one frame per pose change
        self.live_timings.append(time.perf_counter() - t0)

    def preview(self, *, report: bool = True) -> Worker | None:
        """Full-resolution reconstruction with the breakage report, in the background."""
        settings = self.reconstruct_panel.settings()
        if self.worker is not None:
            self.doc.message("A job is running; preview again when it ends.")
            return None
        if settings["mode"] == "sampled" and self.doc.volume is None:
            self.show_error("Preview", "sampled mode needs the volume: open it (File → Open volume)")
            return None
        try:
            tskel = self.doc.pose.tskel()
            if not len(tskel):
                raise ValueError("no attached points to reconstruct: connect points to bones first (Connect tab)")
        except ValueError as exc:
            self.show_error("Preview", str(exc))
            return None
        joints = dict(self.doc.bones.joints)
        posed = self.doc.pose.posed_joints()
        source = self.doc.volume if settings["mode"] == "sampled" else None
        worker = self.run_task("Reconstructing", lambda progress, cancel: make_preview(
            tskel, **settings, source=source, joints=joints, posed_joints=posed, report=report,
            progress=progress, cancel=cancel), self.doc.set_preview)
        worker.is_preview = True
        return worker

    def _forget_rest(self, **_) -> None:
        self._rest_preview = None

    def _draw_preview(self) -> None:
        p = self.doc.preview
        if self.reconstruct_panel.show_rest.isChecked():
            if self._rest_preview is None and len(self.doc.attachments.bone):
                from volanim_core.tskel import identity_tskel

                try:
                    rest = identity_tskel(self.doc.pose.tskel().connectivity)
                    mode = p.mode if p is not None else "bone"
                    self._rest_preview = make_preview(rest, mode=mode, source=self.doc.volume)
                except ValueError as exc:
                    self.doc.message(str(exc))
                    return
            p = self._rest_preview
        if p is None:
            self.scene.clear_volume()
            return
        if p.factor > 1 and p.mode in ("bone", "binary"):  # a live preview: a surface draws fastest
            self.scene.show_surface(p.reconstruction.volume, p.origin_voxels, p.spacing, p.mode)
        else:
            self.scene.show_volume(p.reconstruction.volume, p.origin_voxels, p.spacing, p.mode)

    def _slices_toggled(self, on: bool) -> None:
        self.scene.slices = on
        self._draw_preview()

    def jump_to_joint(self, name: str) -> None:
        posed = self.doc.pose.posed_joints()
        if name in posed:
            self.scene.jump_to(posed[name])
            self.doc.message(f"Centred on {name}. Fix the points there (Lasso, L), then preview again (F5).")

    def export_preview(self, path) -> bool:
        p = self.doc.preview
        if p is None:
            self.show_error("Export", "nothing to export: preview first (F5)")
            return False
        vol = p.reconstruction.volume
        if str(path).lower().endswith(".vol") and vol.dtype != np.uint8:
            vol = np.minimum(vol, 255).astype(np.uint8)
        try:
            io.write_volume(path, vol, origin=tuple(p.origin_voxels), spacing=p.spacing)
        except (OSError, ValueError) as exc:
            self.show_error("Export", str(exc))
            return False
        self.doc.message(f"Exported {vol.shape[0]}x{vol.shape[1]}x{vol.shape[2]} ({p.mode}) to {path}; "
                         f"origin {tuple(int(v) for v in p.origin_voxels)}.")
        return True

    def load_trans(self, path) -> bool:
        try:
            self.doc.pose.load_trans(path)
        except (FormatError, ValueError) as exc:
            self.show_error("Load pose", str(exc))
            return False
        self.doc.message(f"Loaded the pose from {Path(path).name}.")
        return True

    def auto_connect(self) -> None:
        p = self.connect_panel
        try:
            report = self.doc.attachments.auto(scope=p.scope.currentText(), overwrite=p.overwrite.isChecked(),
                                               selection=self.doc.point_selection, method=p.method.currentText())
        except ValueError as exc:
            self.show_error("Auto-connect", str(exc))
            return
        self.doc.message(f"Auto-connect: {report}.")
        if report.unattached:
            self.show_error("Auto-connect", f"Auto-connect {report}. Connect the rest with the cube or lasso.")

    def mirror_connectivity(self) -> None:
        try:
            copied, lonely = self.doc.attachments.mirror()
        except ValueError as exc:
            self.show_error("Mirror connectivity", str(exc))
            return
        text = f"Mirrored {copied} attachments"
        if lonely:
            text += f"; {lonely} points found no partner on the other side (connect them by hand)"
        self.doc.message(text + ".")

    def _toggle_remove(self, on: bool) -> None:
        self.handlers[Mode.BONES].remove = on
        if on:
            self.set_mode(Mode.BONES)
            self.doc.message("Remove: click a bone to delete it (toggle off to add bones again).")

    def handle_pick(self, ev: PickEvent) -> None:
        try:
            self.handlers[self.mode].press(ev)
        except ValueError as exc:
            self.doc.message(str(exc))

    def key(self, name: str) -> None:
        if name == "Delete" and self.mode != Mode.BONES and self.doc.selected_bones:
            self.doc.remove_bones(self.doc.selected_bones)
            return
        self.handlers[self.mode].key(name)

    def undo(self) -> None:
        label = self.doc.undo.undo()
        self.doc.message(f"Undid: {label}" if label else "Nothing to undo.")

    def redo(self) -> None:
        label = self.doc.undo.redo()
        self.doc.message(f"Redid: {label}" if label else "Nothing to redo.")

    def _on_undo_changed(self, **_) -> None:
        u = self.doc.undo
        self.undo_action.setEnabled(u.can_undo)
        self.undo_action.setText(f"Undo {u.undo_label}" if u.can_undo else "Undo")
        self.redo_action.setEnabled(u.can_redo)
        self.redo_action.setText(f"Redo {u.redo_label}" if u.can_redo else "Redo")

    def symmetrize(self) -> None:
        try:
            written = self.doc.symmetrize()
        except ValueError as exc:
            self.show_error("Symmetrize", str(exc))
            return
        self.doc.message(f"Mirrored to {', '.join(written)} across x = {self.doc.symmetry_x:g}.")

    def _on_picked_changed(self, index=None, **_) -> None:
        if index is None or self.doc.skeleton is None or index >= len(self.doc.skeleton):
            self.point_label.setText("")
            return
        i = self.doc.point_info(index)
        self.point_label.setText(f"x {i['x']}  y {i['y']}  z {i['z']}   DT {i['dt']:.3f}   "
                                 f"thinness {i['thinness']:.3f}   bone {i['bone'] or '—'}")

    def show_shortcuts(self) -> None:
        rows = "".join(f"<tr><td><b>{k}</b></td><td>{v}</td></tr>" for k, v in SHORTCUTS)
        box = QMessageBox(QMessageBox.Information, "Shortcuts", f"<table cellspacing=6>{rows}</table>",
                          QMessageBox.Close, self)
        box.setTextFormat(Qt.RichText)
        self._shortcut_box = box
        box.open()

    # -------------------------------------------------------------- errors
    def show_error(self, title: str, message: str) -> None:
        """A non-blocking error dialog; the document is untouched."""
        self.last_error = message
        box = QMessageBox(QMessageBox.Warning, title, message, QMessageBox.Ok, self)
        self._error_box = box
        box.open()

    # -------------------------------------------------------------- loading
    def run_task(self, label: str, task, on_done) -> Worker:
        """Run ``task(progress, cancel)`` in a worker with a progress dialog and Cancel."""
        if self.worker is not None:
            raise RuntimeError("another job is running")
        dialog = QProgressDialog(label, "Cancel", 0, 100, self)
        dialog.setWindowModality(Qt.WindowModal)
        dialog.setMinimumDuration(300)
        worker = Worker(task, self)
        worker.progressed.connect(lambda d, t: dialog.setValue(int(100 * d / max(t, 1))))
        dialog.canceled.connect(worker.cancel)

        def finish():
            dialog.reset()
            self.worker = None
            self.progress = None
            self.activateWindow()  # give keyboard focus back (window managers differ; Xvfb has none)

        worker.succeeded.connect(lambda result: (finish(), on_done(result)))
        worker.failed.connect(lambda msg: (finish(), self.show_error(label, msg)))
        worker.was_cancelled.connect(lambda: (finish(), self.doc.message(f"{label}: cancelled.")))
        self.worker, self.progress = worker, dialog
        worker.start()
        return worker

    @property
    def busy(self) -> bool:
        return self.worker is not None

    def _apply_prepared(self, result: dict, path=None, threshold=None, spacing=None, dims=None) -> None:
        self.doc.set_volume(result["volume"], result["mask"], spacing=spacing or result.get("spacing", (1, 1, 1)),
                            path=path, threshold=threshold, dims=dims)
        self.doc.set_skeleton(result["skeleton"])
        self.doc.set_hull(*result["hull"])
        self.doc.message(f"{len(result['skeleton'])} skeleton points; thinness slider shows the prefix ≥ t.")

    def load_demo(self, name: str) -> Worker:
        def done(r):
            self._apply_prepared(r, spacing=r["spacing"])
            self.doc.demo_name = name

        return self.run_task(f"Preparing the {name} demo", lambda progress, cancel: tasks.load_demo(
            name, progress=progress, cancel=cancel), done)

    def open_volume(self, path, *, dims=None, params: dict | None = None) -> Worker | None:
        """Read a volume; ask for the threshold (unless ``params``); segment it in a worker."""
        try:
            loaded = tasks.load_volume_file(str(path), dims)
        except FormatError as exc:
            self.show_error("Open volume", str(exc))
            return None
        if params is None:
            dialog = ThresholdDialog(loaded["volume"], Path(path).name, self)
            if dialog.exec() != ThresholdDialog.Accepted:
                return None
            params = dialog.parameters()
        vol = loaded["volume"]
        return self.run_task(f"Skeletonizing {Path(path).name}", lambda progress, cancel: tasks.prepare_volume(
            vol, progress=progress, cancel=cancel, **params), lambda r: self._apply_prepared(
            r, path=path, threshold=(params["lo"], params["hi"]), spacing=loaded["spacing"], dims=dims))

    def open_volume_dialog(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self, "Open volume", "", "Volumes (*.vol *.VOL *.vti *.nrrd *.nii "
                                              "*.nii.gz *.mha *.mhd);;All files (*)")
        if path:
            self.open_volume(path)

    def open_mskel(self, path) -> bool:
        try:
            skel = io.read_mskel(path)
        except FormatError as exc:
            self.show_error("Open skeleton", str(exc))
            return False
        self.doc.set_skeleton(skel, path)
        self.doc.message(f"Loaded {len(skel)} points from {Path(path).name}.")
        return True

    def open_bones(self, path) -> bool:
        try:
            self.doc.load_bones(path)
        except FormatError as exc:
            self.show_error("Open bones", str(exc))
            return False
        self.doc.message(f"Loaded {len(self.doc.bones)} bones from {Path(path).name}.")
        return True

    def open_project(self, path) -> Worker | None:
        try:
            data = read_project(path)
        except FormatError as exc:
            self.show_error("Open project", str(exc))
            return None

        def rest(_=None):
            if data.get("mskel") and (self.doc.skeleton is None or not (data.get("volume") or data.get("demo"))):
                self.open_mskel(data["mskel"])
            elif data.get("mskel"):
                self.doc.mskel_path = data["mskel"]
            if data.get("bones"):
                self.open_bones(data["bones"])
            if data.get("connect"):
                self.open_connect(data["connect"])
            if data.get("symmetry_x") is not None:
                self.doc.symmetry_x = data["symmetry_x"]
            if data.get("thinness") is not None:
                self.doc.thinness = data["thinness"]
            self.doc.project_path = str(path)
            self.doc.events.project.emit(path=str(path))
            if data.get("camera"):
                self.set_camera(data["camera"])

        if data.get("demo") and not data.get("volume"):
            worker = self.load_demo(data["demo"])
            worker.succeeded.connect(rest)
            return worker
        if data.get("volume"):
            lo, hi = data.get("threshold") or (1, None)
            params = {"lo": lo, "hi": hi, "fill": False}
            worker = self.open_volume(data["volume"], dims=data.get("volume_dims"), params=params)
            if worker is not None:
                worker.succeeded.connect(rest)
            return worker
        rest()
        return None

    def open_connect(self, path) -> bool:
        try:
            warnings = self.doc.attachments.load(path)
        except (FormatError, ValueError) as exc:
            self.show_error("Open connectivity", str(exc))
            return False
        if warnings:
            self.show_error("Open connectivity", "\n".join(warnings))
        per_bone, unconnected = self.doc.attachments.counts()
        self.doc.message(f"Loaded {int(per_bone.sum())} attachments from {Path(path).name}.")
        return True

    def save_connect(self, path=None) -> Path | None:
        if path is None:
            stem = Path(self.doc.project_path or "untitled").with_suffix("").name
            path, _ = QFileDialog.getSaveFileName(self, "Save connectivity", self.doc.attachments.default_filename(
                stem), "Connectivity (*.connect)")
            if not path:
                return None
        try:
            n = self.doc.attachments.save(path)
        except (OSError, ValueError) as exc:
            self.show_error("Save connectivity", str(exc))
            return None
        self.doc.message(f"Saved {n} attached points (thinness ≥ {self.doc.thinness:.2f}) to {path}.")
        return Path(path)

    def _open_dialog(self, kind: str) -> None:
        filters = {"mskel": "Skeletons (*.mskel)", "bones": "Bones (*.bones)", "project": "Projects (*.volanim)",
                   "connect": "Connectivity (*.connect)", "trans": "Poses (*.trans)"}
        path, _ = QFileDialog.getOpenFileName(self, f"Open {kind}", "", f"{filters[kind]};;All files (*)")
        if path:
            {"mskel": self.open_mskel, "bones": self.open_bones, "project": self.open_project,
             "connect": self.open_connect, "trans": self.load_trans}[kind](path)

    # -------------------------------------------------------------- saving
    def camera(self) -> dict:
        cam = self.plotter.renderer.GetActiveCamera()
        return {"position": list(cam.GetPosition()), "focal_point": list(cam.GetFocalPoint()),
                "view_up": list(cam.GetViewUp())}

    def set_camera(self, data: dict) -> None:
        cam = self.plotter.renderer.GetActiveCamera()
        cam.SetPosition(*data["position"])
        cam.SetFocalPoint(*data["focal_point"])
        cam.SetViewUp(*data["view_up"])
        self.plotter.renderer.ResetCameraClippingRange()
        self.scene.render()

    def save_project(self, ask: bool = False, path=None) -> Path | None:
        if path is None:
            path = self.doc.project_path
            if ask or not path:
                path, _ = QFileDialog.getSaveFileName(self, "Save project", "session.volanim",
                                                      "Projects (*.volanim)")
                if not path:
                    return None
        try:
            saved = self.doc.save_project(path, camera=self.camera())
        except (OSError, ValueError) as exc:
            self.show_error("Save project", str(exc))
            return None
        self.doc.message(f"Saved {saved}.")
        return saved

    def save_bones(self, path) -> bool:
        try:
            self.doc.save_bones(path)
        except (OSError, ValueError) as exc:
            self.show_error("Save bones", str(exc))
            return False
        self.doc.message(f"Saved {len(self.doc.bones)} bones to {path}.")
        return True

    def _save_dialog(self, kind: str) -> None:
        if kind == "connect":
            self.save_connect()
            return
        if kind in ("trans", "tskel", "volume"):
            filters = {"trans": "Poses (*.trans)", "tskel": "Frames (*.tskel)",
                       "volume": "Volumes (*.vti *.nrrd *.VOL *.vol)"}
            default = {"trans": "pose.trans", "tskel": "pose.tskel", "volume": "preview.vti"}[kind]
            path, _ = QFileDialog.getSaveFileName(self, f"Save {kind}", default, filters[kind])
            if not path:
                return
            if kind == "volume":
                self.export_preview(path)
                return
            try:
                if kind == "trans":
                    self.doc.pose.save_trans(path)
                else:
                    self.doc.pose.save_tskel(path)
            except (OSError, ValueError) as exc:
                self.show_error(f"Save {kind}", str(exc))
                return
            self.doc.message(f"Saved {path}.")
            return
        filters = {"bones": "Bones (*.bones)", "connections": "Connections (*.connections)", "png": "PNG (*.png)"}
        path, _ = QFileDialog.getSaveFileName(self, f"Save {kind}", f"untitled.{kind}", filters[kind])
        if not path:
            return
        if kind == "bones":
            self.save_bones(path)
        elif kind == "connections":
            self.doc.save_connections(path)
        else:
            self.plotter.screenshot(path)

    def screenshot(self, path) -> None:
        self.plotter.screenshot(str(path))

    def closeEvent(self, event):  # noqa: N802 (Qt name)
        if self.worker is not None:
            self.worker.cancel()
            self.worker.wait(5000)
        self.autosave_timer.stop()
        self.autosaver.close()
        self.plotter.close()
        super().closeEvent(event)


def main_window_for(args) -> MainWindow:
    """A window loaded as the command line asks (see ``app.main``)."""
    w = MainWindow()
    worker = None
    if not (args.project or args.demo or args.volume or args.mskel or args.connect):
        worker = w.offer_recovery()
    if worker is not None:
        pass
    elif args.project:
        worker = w.open_project(args.project)
    elif args.demo:
        worker = w.load_demo(args.demo)
    elif args.volume:
        worker = w.open_volume(args.volume)

    def then(_=None):  # files that build on the loaded skeleton, after any background load
        if args.mskel:
            w.open_mskel(args.mskel)
        if args.bones:
            w.open_bones(args.bones)
        if args.connect:
            w.open_connect(args.connect)

    if worker is not None:
        worker.succeeded.connect(then)
    else:
        then()
    return w


__all__ = ["MainWindow", "main_window_for", "np"]
