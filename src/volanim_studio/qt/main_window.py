"""The studio's main window: it composes the view, the panels and the controllers.

    QtInteractor --SceneView.pick--> PickEvent --> active mode handler --> Document
    Document / settings events --> SceneView (actors), panels, status bar
    File menu --> FilesController --> volanim_core readers, JobRunner (errors: a dialog naming file and line)
    Pose menu, pose sliders --> PreviewController --> live preview / JobRunner(make_preview)

The window owns the controllers (it does not inherit them) and routes
clicks and keys to the mode table; it keeps no view or tool state of its own.
"""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtGui import QAction, QActionGroup, QKeySequence
from PySide6.QtWidgets import (
    QAbstractSpinBox,
    QApplication,
    QDockWidget,
    QLabel,
    QMainWindow,
    QMessageBox,
    QSizePolicy,
    QTabWidget,
)
from pyvistaqt import QtInteractor

from ..model.document import Document
from ..model.interaction import HANDLERS, Mode, PickEvent
from ..scene.view import SceneView
from ..shortcuts import SHORTCUTS
from .bone_panel import BonePanel
from .connect_controller import ConnectController
from .connect_panel import ConnectPanel
from .display_panel import DisplayPanel
from .export_controller import ExportController
from .files_controller import FilesController
from .gui_gc import collect_on_gui_thread, freeze_start_up
from .interactor import close_interactor
from .mode_keys import LettersPastNumberFields
from .naming_controller import NamingController
from .pose_panel import PosePanel
from .preview_controller import PreviewController
from .propose_dialog import ProposeController
from .reconstruct_panel import ReconstructPanel
from .session_controller import SessionController
from .status_line import ElidedLabel, StatusLine
from .timeline_controller import TimelineController
from .timeline_panel import TimelinePanel
from .verdict_label import VerdictLabel
from .worker import JobRunner


class MainWindow(QMainWindow):
    def __init__(self, doc: Document | None = None):
        super().__init__()
        # before any worker thread runs: garbage holding Qt/VTK objects dies here; never a full collection in a drag
        collect_on_gui_thread().hold_full_while(self)
        self.doc = doc or Document()
        self.setWindowTitle("volanim studio")
        self.resize(1400, 900)
        # Frames are drawn when the model changes (SceneView.render), not on pyvistaqt's 5 Hz timer:
        # with software GL each unasked frame of a large cloud costs 0.2-0.6 s of the GUI thread.
        # No multisampling: 8x MSAA costs software GL ~30 % a frame. FXAA smooths edges instead (~16 ms
        # of a frame with the hull at 1200x800 on software GL; the scene drops it while a slider is held).
        self.plotter = QtInteractor(self, auto_update=False, multi_samples=0)
        # FXAA on the widget's own window (VTK's generic window in Qt's GL context), set directly: pyvista's
        # enable_anti_aliasing("fxaa") asks a new window of VTK's default kind whether this is an EGL build,
        # which says nothing of a window Qt made. Where that default is EGL (VTK_DEFAULT_OPENGL_WINDOW, or
        # no X connection for a new window: seen in long test workers) it warned and drew SSAA, 4x the pixels.
        self.plotter.renderer.SetUseFXAA(True)
        self.setCentralWidget(self.plotter.interactor if hasattr(self.plotter, "interactor") else self.plotter)
        self.scene = SceneView(self.plotter, self.doc, on_pick=self.handle_pick)
        self.handlers = {m: cls(self.doc) for m, cls in HANDLERS.items()}
        self._entered = Mode.VIEW  # the handler entered last (settings.mode is the mode)
        self.jobs = JobRunner(self, show_error=self.show_error, message=lambda text: self.doc.message(text),
                              on_idle=self.activateWindow)  # focus back after a job (Xvfb has no WM to do it)
        # Files read only to look at them (View slices, View volume or mesh) have a runner of their own:
        # a large scan's read neither freezes the window nor waits for (or blocks) the document's job.
        self.readers = JobRunner(self, show_error=self.show_error, message=lambda text: self.doc.message(text))
        # ... and a project's saves: written on a thread (no file formatted on the GUI thread), never
        # refused because a reconstruction runs
        self.savers = JobRunner(self, show_error=self.show_error, message=lambda text: self.doc.message(text))
        self.last_error: str | None = None
        self._error_box: QMessageBox | None = None

        self.files = FilesController(self)
        self.transfer_editor = None  # made when first shown (View → Transfer function…)
        self.previews = PreviewController(self)
        self.naming = NamingController(self)
        self.connecting = ConnectController(self)
        self.proposing = ProposeController(self)
        self.display_panel = DisplayPanel(self.doc)
        self.bone_panel = BonePanel(self.doc)
        self.connect_panel = ConnectPanel(self.doc, self.handlers[Mode.CUBE])
        self.pose_panel = PosePanel(self.doc)
        self.reconstruct_panel = ReconstructPanel(self.doc)
        self.scene.lasso.on_lasso = self.handle_lasso
        bones_mode = self.handlers[Mode.BONES]
        self.scene.names.pending = lambda: bones_mode.pending_position() if self.mode == Mode.BONES else None
        tabs = self.panel_tabs = QTabWidget()
        tabs.addTab(self.bone_panel, "Bones")
        tabs.addTab(self.connect_panel, "Connect")
        tabs.addTab(self.pose_panel, "Pose")
        tabs.addTab(self.reconstruct_panel, "Reconstruct")
        tabs.addTab(self.display_panel, "Display")
        tabs.setMinimumWidth(420)
        # text that grows with what it says wraps in the panel's width instead of widening the panel (#83: a
        # long verdict took 223 px from the 3-D view after each release)
        for label in tabs.findChildren(QLabel):
            if label.wordWrap():
                label.setSizePolicy(QSizePolicy.Ignored, label.sizePolicy().verticalPolicy())
        dock = QDockWidget("Panels", self)
        dock.setWidget(tabs)
        dock.setFeatures(QDockWidget.DockWidgetMovable | QDockWidget.DockWidgetFloatable)
        self.addDockWidget(Qt.RightDockWidgetArea, dock)
        self.timeline_panel = TimelinePanel(self.doc)
        self.timeline = TimelineController(self)
        self.exporting = ExportController(self)
        timeline_dock = QDockWidget("Timeline", self)
        timeline_dock.setWidget(self.timeline_panel)
        timeline_dock.setFeatures(QDockWidget.DockWidgetMovable | QDockWidget.DockWidgetFloatable)
        self.addDockWidget(Qt.BottomDockWidgetArea, timeline_dock)
        self.point_label = ElidedLabel()
        self.verdict_label = VerdictLabel(self.doc)
        # the message first, whole; then the verdict, then the point, cut with "…" when short of room (#61)
        self.status_line = StatusLine(self.statusBar(), [self.verdict_label, self.point_label])
        self._build_actions()
        self.doc.events.message.connect(lambda text: self.statusBar().showMessage(text, 15000))
        self.doc.events.picked.connect(self._on_picked_changed)
        self.doc.events.attachments.connect(lambda **_: self._on_picked_changed(index=self.doc.picked_point))
        self.doc.events.bones.connect(lambda **_: self._on_picked_changed(index=self.doc.picked_point))
        self.doc.undo.events.changed.connect(self._on_undo_changed)
        self.session = SessionController(self)
        self.doc.settings.events.mode.connect(lambda value: self._enter_mode(value))
        self._enter_mode(self.doc.settings.mode)
        self._letters = LettersPastNumberFields(self)
        for box in self.findChildren(QAbstractSpinBox):
            box.installEventFilter(self._letters)

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
        self.files.fill_menu(file, self._action)
        self.exporting.fill_menu(file, self._action)
        file.addSeparator()
        self._action("&Quit", self.close, "Ctrl+Q", menu=file)
        edit = bar.addMenu("&Edit")
        self.undo_action = self._action("Undo", self.undo, "Ctrl+Z", menu=edit)
        self.redo_action = self._action("Redo", self.redo, "Ctrl+Shift+Z", menu=edit)
        self._action("Delete selected bones", lambda: self.key("Delete"), "Delete", menu=edit)
        self._action("Symmetrize selected bones", self.symmetrize, "M", menu=edit)
        self._action("End chain", lambda: self.key("Escape"), "Esc")
        edit.addSeparator()
        self.naming.fill_menu(edit, self._action)
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
        self.proposing.fill_menu(bar.addMenu("&Bones"), self._action)
        connect_menu = bar.addMenu("&Connect")
        self.connecting.fill_menu(connect_menu, self._action)
        self._action("Save .connect…", lambda: self.files.save_dialog("connect"), menu=connect_menu)
        self._action("Open .connect…", lambda: self.files.open_dialog("connect"), menu=connect_menu)
        self.previews.fill_menu(bar.addMenu("&Pose"), self._action)
        self.previews.wire(self.pose_panel, self.reconstruct_panel)
        self.timeline.fill_menu(bar.addMenu("&Timeline"), self._action)
        view = bar.addMenu("&View")
        for name, key in (("front", "Ctrl+1"), ("side", "Ctrl+3"), ("top", "Ctrl+7"), ("three-quarter", "Ctrl+5"),
                          ("back", "Ctrl+Shift+1")):
            self._action(f"{name.capitalize()} view", lambda _=False, n=name: self.scene.view_preset(n), key, menu=view)
        view.addSeparator()
        self._action("Frame all", self.scene.frame_all, "Shift+F", menu=view)
        self._action("Frame selected", self.frame_selected, "F", menu=view)
        self._action("Reset view", self.scene.front_view, "Ctrl+0", menu=view)
        view.addSeparator()
        self._action("Save view as camera file…", lambda: self.timeline.save_camera_dialog(), menu=view)
        self._action("Transfer function…", self.show_transfer_editor, "Ctrl+T", menu=view)
        self.timeline.wire(self.timeline_panel)
        self.connect_panel.auto_button.clicked.connect(self.connecting.auto_connect)
        self.connect_panel.mirror_button.clicked.connect(self.connecting.mirror_connectivity)
        help_menu = bar.addMenu("&Help")
        self._action("&Shortcuts", self.show_shortcuts, "F1", menu=help_menu)
        self._on_undo_changed()

    @property
    def mode(self) -> Mode:
        return self.doc.settings.mode

    def set_mode(self, mode: Mode) -> None:
        """Switch the interaction mode (a setting: a project reopens in it); the same mode enters again."""
        if Mode(mode) == self.doc.settings.mode:
            self._enter_mode(mode)
        else:
            self.doc.settings.mode = mode  # --> _enter_mode

    def _enter_mode(self, mode: Mode) -> None:
        self.handlers[self._entered].leave()
        self._entered = Mode(mode)
        self.mode_actions[self.mode].setChecked(True)
        self.scene.lasso.set_enabled(self.mode == Mode.LASSO)
        self.scene.set_posing(self.mode == Mode.POSE)
        if self.mode == Mode.POSE:
            self.panel_tabs.setCurrentWidget(self.pose_panel)
        elif self.mode in (Mode.BONES, Mode.ROOT_ORDER):
            self.panel_tabs.setCurrentWidget(self.bone_panel)
        for a in getattr(self, "cube_actions", []):
            a.setEnabled(self.mode == Mode.CUBE)
        for a in self.timeline.step_actions:  # the arrows nudge the cube in Cube mode, step frames elsewhere
            a.setEnabled(self.mode != Mode.CUBE)
        if self.mode in (Mode.CUBE, Mode.LASSO):
            self.panel_tabs.setCurrentWidget(self.connect_panel)
            self.doc.settings.colour_by = "bone"
        self.handlers[self.mode].enter()

    def handle_lasso(self, polygon, ctrl: bool) -> None:
        shown, xy, depth, view_depth = self.scene.shown_projection()
        lasso = self.handlers[Mode.LASSO]
        lasso.finish(polygon, xy, depth, view_depth, shown, remove=True if ctrl else None)

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
        self._drop_ended_chain_line()

    def key(self, name: str) -> None:
        if name == "Delete" and self.mode != Mode.BONES and self.doc.selected_bones:
            self.doc.bone_edits.remove_bones(self.doc.selected_bones)
            return
        self.handlers[self.mode].key(name)
        self._drop_ended_chain_line()

    def _drop_ended_chain_line(self) -> None:
        """A click or key that ended the chain (right click, Esc) removes its line at once, not at the next move."""
        if self.handlers[Mode.BONES].pending is None:
            self.scene.names.clear_chain_preview()

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

    def frame_selected(self) -> None:
        if not self.scene.frame_selected():
            self.doc.message("Nothing selected to frame: click a bone or a point first (Shift+F frames everything).")

    def symmetrize(self) -> None:
        try:
            written = self.doc.bone_edits.symmetrize()
        except ValueError as exc:
            self.show_error("Symmetrize", str(exc))
            return
        self.doc.message(f"Mirrored to {', '.join(written)} across x = {self.doc.symmetry_x:g}.")

    def _on_picked_changed(self, index=None, **_) -> None:
        if index is None or self.doc.skeleton is None or index >= len(self.doc.skeleton):
            self.point_label.setText("")
            return
        i = self.doc.point_info(index)
        self.point_label.setText(f"x {i['x']}  y {i['y']}  z {i['z']}   ({', '.join(f'{v:.1f}' for v in i['mm'])}) mm"
                                 f"   DT {i['dt']:.3f} ({i['dt_mm']:.2f} mm)   thinness {i['thinness']:.3f}   "
                                 f"bone {i['bone'] or '—'}")

    def show_shortcuts(self):
        """F1: every shortcut in a scrolling list that fits the screen (#83: a message box of them all was
        taller than a 1000 px screen, its Close button out of reach)."""
        from PySide6.QtWidgets import QDialog, QDialogButtonBox, QTextBrowser, QVBoxLayout

        rows = "".join(f"<tr><td><b>{k}</b></td><td>{v}</td></tr>" for k, v in SHORTCUTS)
        box = QDialog(self)
        box.setWindowTitle("Shortcuts")
        text = QTextBrowser()
        text.setHtml(f"<table cellspacing=6>{rows}</table>")
        buttons = QDialogButtonBox(QDialogButtonBox.Close)
        buttons.rejected.connect(box.reject)
        layout = QVBoxLayout(box)
        layout.addWidget(text)
        layout.addWidget(buttons)
        screen = (self.screen() or QApplication.primaryScreen()).availableGeometry()
        box.resize(min(720, int(0.9 * screen.width())), min(900, int(0.8 * screen.height())))
        self._shortcut_box = box
        box.open()
        return box

    def show_transfer_editor(self):
        """The transfer-function editor (one per window, not modal: the preview follows its edits)."""
        from .transfer_editor import TransferEditor

        if self.transfer_editor is None:
            self.transfer_editor = TransferEditor(self)
        self.transfer_editor.show()
        self.transfer_editor.raise_()
        return self.transfer_editor

    # -------------------------------------------------------------- errors
    def show_error(self, title: str, message: str) -> None:
        """A non-blocking error dialog; the document is untouched."""
        self.last_error = message
        box = QMessageBox(QMessageBox.Warning, title, message, QMessageBox.Ok, self)
        self._error_box = box
        box.open()

    def ask(self, title: str, message: str, yes: str, on_yes) -> QMessageBox:
        """A non-blocking question after a refusal (the document is untouched): its Yes button reads
        ``yes`` and runs ``on_yes()``; shown where errors are (``last_error``)."""
        self.last_error = message
        box = QMessageBox(QMessageBox.Question, title, message, QMessageBox.Yes | QMessageBox.No, self)
        box.button(QMessageBox.Yes).setText(yes)
        box.finished.connect(lambda _: on_yes() if box.standardButton(box.clickedButton()) == QMessageBox.Yes
                             else None)
        self._error_box = box
        box.open()
        return box

    @property
    def busy(self) -> bool:
        """A background job, a read for a viewer, a save or a live picture is running (its thread has not
        ended yet)."""
        return (self.jobs.running or self.readers.busy or self.savers.busy
                or not self.previews.live_worker.idle)

    def interacting(self) -> bool:
        """A bone is dragged or the timeline plays: frames the user follows (a full collection waits, gui_gc)."""
        settings = self.doc.settings
        return bool(settings.dragging or settings.playing)

    def screenshot(self, path) -> None:
        self.plotter.screenshot(str(path))

    def closeEvent(self, event):  # noqa: N802 (Qt name)
        if not self.session.may_close():
            event.ignore()  # "Save changes?" is asked; a Save or Discard closes the window again
            return
        self.timeline.stop()
        self.jobs.shutdown()  # cancel and wait for the worker: destroying a running QThread aborts
        self.previews.live_worker.close()  # and for the live picture being made
        self.readers.shutdown()
        self.savers.shutdown()  # a save under way is finished, never cut
        self.session.close()
        close_interactor(self.plotter)
        super().closeEvent(event)


def main_window_for(args) -> MainWindow:
    """A window loaded as the command line asks (see ``app.main``)."""
    w = MainWindow()
    freeze_start_up()  # the program and its window, before any file is read: out of every later collection

    def then(_=None):  # files that build on the loaded skeleton, after any background load
        if args.mskel:
            w.files.open_mskel(args.mskel)
        if args.bones:
            w.files.open_bones(args.bones)
        if args.connect:
            w.files.open_connect(args.connect)
        w.doc.undo.clear()  # what the command line named is where the session starts, not an edit to undo
        w.doc.undo.mark_clean()

    if args.project:
        w.files.open_project(args.project, lambda ok: ok and then())
    elif args.demo:
        w.files.load_demo(args.demo, then=then)
    elif args.volume:
        w.files.open_volume(args.volume, then=then)  # read, thresholded by the user, segmented: then the rest
    else:
        then()
    if not (args.project or args.demo or args.volume or args.mskel or args.connect or args.bones):
        w.session.offer_recovery()  # a plain start: offer a crashed session's autosave
    return w


__all__ = ["MainWindow", "main_window_for"]
