"""The studio's main window: it composes the view, the panels and the controllers.

    QtInteractor --SceneView.pick--> PickEvent --> active mode handler --> Document
    Document / settings events --> SceneView (actors), panels, status bar
    File menu --> FilesController --> volanim_core readers, JobRunner (errors: a dialog naming file and line)
    Pose menu, pose sliders --> PreviewController --> live preview / JobRunner(make_preview)

The window owns the controllers (it does not inherit them) and routes
clicks and keys to the mode table; it keeps no view or tool state of its own.
"""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import Qt, QTimer
from PySide6.QtGui import QAction, QActionGroup, QKeySequence
from PySide6.QtWidgets import (
    QAbstractSpinBox,
    QDockWidget,
    QInputDialog,
    QLabel,
    QLineEdit,
    QMainWindow,
    QMessageBox,
    QTabWidget,
)
from pyvistaqt import QtInteractor

from ..model import autosave
from ..model.document import Document
from ..model.modes import HANDLERS, Mode, PickEvent
from ..scene.view import SceneView
from .bone_panel import BonePanel
from .connect_panel import ConnectPanel
from .display_panel import DisplayPanel
from .files_controller import FilesController
from .gui_gc import collect_on_gui_thread
from .mode_keys import LettersPastNumberFields
from .pose_panel import PosePanel
from .preview_controller import PreviewController
from .reconstruct_panel import ReconstructPanel
from .timeline_controller import TimelineController
from .timeline_panel import TimelinePanel
from .verdict_label import VerdictLabel
from .worker import JobRunner, Worker

SHORTCUTS = [
    ("V", "View mode: click points to inspect them"),
    ("B", "Bones mode: click point A, then B to add a bone; keep clicking to chain"),
    ("R", "Root order mode: click bones in order"),
    ("K", "Cube mode: click a point to place the cube"),
    ("Up / Down / Left / Right, PgUp / PgDown, + / -", "Cube mode: nudge the cube, resize it"),
    ("C / X", "Cube mode: connect the points in the cube to the working bone / remove them"),
    ("L", "Lasso mode: drag an outline to connect the points under it to the working bone (Ctrl: remove)"),
    ("Ctrl+A", "Auto-connect"),
    ("P", "Pose mode: click a bone, turn it with the Pose sliders; the preview follows live"),
    ("F5", "Preview the reconstruction at full resolution, with the breakage report"),
    ("Esc", "End the bone chain / restart the root order"),
    ("Right click", "End the bone chain"),
    ("Del", "Remove the selected bones (the Delete key)"),
    ("M", "Symmetrize the selected bones (L_ ↔ R_)"),
    ("F2", "Rename the joint clicked last"),
    ("Ctrl+F2", "Name the selected bone's chain in one line: SHOULDER, ELBOW, WRIST (L_/R_ added by side)"),
    ("Space", "Play / pause the timeline (a BVH clip, .trans frames or keys)"),
    ("Left / Right, Home / End", "Previous / next frame, first / last frame (outside Cube mode)"),
    ("S / Shift+S", "Set / delete the pose key at the current frame"),
    ("Ctrl+Z / Ctrl+Shift+Z", "Undo / redo"),
    ("Ctrl+O", "Open a volume"),
    ("Ctrl+S / Ctrl+Shift+S", "Save the project / save it under a new name"),
    ("Ctrl+Q", "Quit (a running job is cancelled and waited for)"),
    ("Left drag / right drag / wheel", "Rotate / zoom / zoom the view"),
    ("Ctrl+1 / Ctrl+3 / Ctrl+7 / Ctrl+5 / Ctrl+Shift+1", "Front / side / top / three-quarter / back view"),
    ("F / Shift+F / Ctrl+0", "Frame the selection / frame everything / reset the view"),
    ("F1", "This list"),
]


#: What Name chain offers (it keeps as many names as the chain has joints; the side's L_/R_ is added)
CHAIN_PRESETS = {
    "arm": ("SHOULDER", "ELBOW", "WRIST", "FINGERS"),
    "arm from the neck": ("NECK", "SHOULDER", "ELBOW", "WRIST", "FINGERS"),
    "leg": ("HIP", "KNEE", "ANKLE", "TOE"),
    "leg from the pelvis": ("PELVIS", "HIP", "KNEE", "ANKLE", "TOE"),
    "spine": ("PELVIS", "NECK", "HEAD"),
}


class MainWindow(QMainWindow):
    def __init__(self, doc: Document | None = None, *, autosave_every_edits: int = 5,
                 autosave_seconds: float = 60.0):
        super().__init__()
        collect_on_gui_thread()  # before any worker thread runs: garbage holding Qt/VTK objects dies here
        self.doc = doc or Document()
        self.setWindowTitle("volanim studio")
        self.resize(1400, 900)
        self.plotter = QtInteractor(self)
        self.setCentralWidget(self.plotter.interactor if hasattr(self.plotter, "interactor") else self.plotter)
        self.scene = SceneView(self.plotter, self.doc, on_pick=self.handle_pick)
        self.handlers = {m: cls(self.doc) for m, cls in HANDLERS.items()}
        self.mode = Mode.VIEW
        self.jobs = JobRunner(self, show_error=self.show_error, message=lambda text: self.doc.message(text),
                              on_idle=self.activateWindow)  # focus back after a job (Xvfb has no WM to do it)
        self.last_error: str | None = None
        self._error_box: QMessageBox | None = None

        self.files = FilesController(self)
        self.previews = PreviewController(self)
        self.previews.in_pose_mode = lambda: self.mode == Mode.POSE
        self.display_panel = DisplayPanel(self.doc)
        self.display_panel.dragging.connect(self.scene.set_dragging)
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
        dock = QDockWidget("Panels", self)
        dock.setWidget(tabs)
        dock.setFeatures(QDockWidget.DockWidgetMovable | QDockWidget.DockWidgetFloatable)
        self.addDockWidget(Qt.RightDockWidgetArea, dock)
        self.timeline_panel = TimelinePanel(self.doc)
        self.timeline = TimelineController(self, self.previews)
        self.timeline.enter_pose = lambda: self.set_mode(Mode.POSE) if self.mode != Mode.POSE else None
        timeline_dock = QDockWidget("Timeline", self)
        timeline_dock.setWidget(self.timeline_panel)
        timeline_dock.setFeatures(QDockWidget.DockWidgetMovable | QDockWidget.DockWidgetFloatable)
        self.addDockWidget(Qt.BottomDockWidgetArea, timeline_dock)
        self.point_label = QLabel("")
        self.verdict_label = VerdictLabel(self.doc)
        self.statusBar().addPermanentWidget(self.verdict_label)
        self.statusBar().addPermanentWidget(self.point_label)
        self._build_actions()
        self.doc.events.message.connect(lambda text: self.statusBar().showMessage(text, 15000))
        self.doc.events.picked.connect(self._on_picked_changed)
        self.doc.events.attachments.connect(lambda **_: self._on_picked_changed(index=self.doc.picked_point))
        self.doc.events.bones.connect(lambda **_: self._on_picked_changed(index=self.doc.picked_point))
        self.doc.undo.events.changed.connect(self._on_undo_changed)
        self.doc.events.project.connect(self._update_title)
        self.doc.events.skeleton.connect(self._update_title)
        self.doc.undo.events.changed.connect(self._update_title)
        self._close_confirmed = False
        self._save_box: QMessageBox | None = None
        self.autosaver = autosave.Autosaver(self.doc, every_edits=autosave_every_edits,
                                            every_seconds=autosave_seconds)
        self.doc.undo.events.changed.connect(self._autosave_after_edit)
        self.autosave_timer = QTimer(self)
        self.autosave_timer.timeout.connect(self._autosave_tick)
        self.autosave_timer.start(int(1000 * min(autosave_seconds, 60.0)))
        self.set_mode(Mode.VIEW)
        self._update_title()
        self._letters = LettersPastNumberFields(self)
        for box in self.findChildren(QAbstractSpinBox):
            box.installEventFilter(self._letters)
            box.findChild(QLineEdit).installEventFilter(self._letters)

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
                autosave.decline(f)  # kept a week (the folder can still be opened as a project), not asked again
            return None

        def opened(ok: bool) -> None:
            if not ok:  # nothing is deleted: the next start offers it again
                self.doc.message(f"The autosave in {latest.parent} was not restored; it is kept.")
                return
            self.doc.project_path = None  # a restored session saves where the user says, not into the cache
            self.doc.undo.mark_modified()  # it is saved nowhere yet
            self._update_title()
            try:
                self.autosaver.save()  # what was restored is safe in this session's folder ...
            except (OSError, ValueError) as exc:
                self.doc.message(f"Restored, but the autosave of it failed ({exc}); the old autosave is kept.")
                return
            for f in found:  # ... before the crashed sessions' folders go
                autosave.discard(f)
            self.doc.message(f"Restored the autosaved session ({len(self.doc.bones)} bones).")

        return self.files.open_project(latest, on_opened=opened)

    # ------------------------------------------------------ unsaved changes
    def _update_title(self, **_) -> None:
        """``volanim studio — NAME[*]``: Qt shows the ``*`` while the document has unsaved edits."""
        path = self.doc.project_path
        name = Path(path).name if path else (None if self.doc.is_empty else "untitled")
        self.setWindowTitle("volanim studio" + (f" — {name}" if name else "") + "[*]")
        self.setWindowModified(self.doc.modified)

    def when_saved_or_discarded(self, then, doing: str) -> None:
        """Run ``then()`` once unsaved edits are saved or discarded; at once when there are none.

        Asks Save / Discard / Cancel without blocking (the window's event loop keeps
        running, so a job in flight still reports). Discarded edits are set aside for a
        week in the autosave folder, so a wrong answer loses nothing.
        """
        if not self.doc.modified:
            then()
            return
        name = Path(self.doc.project_path).name if self.doc.project_path else "This project"
        box = QMessageBox(QMessageBox.Warning, "Save changes?",
                          f"{name} has unsaved changes. Save them before {doing}?",
                          QMessageBox.Save | QMessageBox.Discard | QMessageBox.Cancel, self)
        box.setInformativeText("Discarded changes are kept for a week in the autosave folder "
                               f"({self.autosaver.root}); they can be opened as a project.")
        box.setDefaultButton(QMessageBox.Save)

        def answered(_result) -> None:
            self._save_box = None
            button = box.standardButton(box.clickedButton()) if box.clickedButton() else QMessageBox.Cancel
            if button == QMessageBox.Save:
                if self.files.save_project() is None:
                    return  # not saved (the user cancelled the file dialog, or it failed and said why)
            elif button == QMessageBox.Discard:
                try:
                    kept = self.autosaver.set_aside()
                except (OSError, ValueError) as exc:
                    self.show_error("Discard changes", f"The discarded changes could not be set aside ({exc}); "
                                    "nothing was discarded.")
                    return
                self.doc.message(f"Discarded changes are kept in {kept}.")
            else:
                return
            then()

        box.finished.connect(answered)
        self._save_box = box
        box.open()

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
        file.addSeparator()
        self._action("&Quit", self.close, "Ctrl+Q", menu=file)
        edit = bar.addMenu("&Edit")
        self.undo_action = self._action("Undo", self.undo, "Ctrl+Z", menu=edit)
        self.redo_action = self._action("Redo", self.redo, "Ctrl+Shift+Z", menu=edit)
        self._action("Delete selected bones", lambda: self.key("Delete"), "Delete", menu=edit)
        self._action("Symmetrize selected bones", self.symmetrize, "M", menu=edit)
        self._action("End chain", lambda: self.key("Escape"), "Esc")
        edit.addSeparator()
        self._action("Rename joint…", self.rename_joint_dialog, "F2", menu=edit)
        self._action("Name chain…", self.name_chain_dialog, "Ctrl+F2", menu=edit)
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
        self.timeline.wire(self.timeline_panel)
        self.connect_panel.auto_button.clicked.connect(self.auto_connect)
        self.connect_panel.mirror_button.clicked.connect(self.mirror_connectivity)
        help_menu = bar.addMenu("&Help")
        self._action("&Shortcuts", self.show_shortcuts, "F1", menu=help_menu)
        self._on_undo_changed()

    def set_mode(self, mode: Mode) -> None:
        self.handlers[self.mode].leave()
        if self.mode == Mode.POSE and mode != Mode.POSE:
            self.previews.leave_pose()
        self.mode = Mode(mode)
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

    def auto_connect(self) -> None:
        st = self.doc.settings
        try:
            report = self.doc.attachments.auto(scope=st.auto_scope, overwrite=st.auto_overwrite,
                                               selection=self.doc.point_selection, method=st.auto_method)
        except ValueError as exc:
            self.show_error("Auto-connect", str(exc))
            return
        self.doc.settings.colour_by = "bone"  # what was connected to what is the thing to look at now
        self.doc.message(f"Auto-connect: {report}.")
        if not report.unattached:
            return
        text = f"Auto-connect {report}. Connect the rest with the cube or lasso."
        if st.auto_method == "path" and report.unattached > report.attached:
            # most points found no straight path inside the volume to a bone (a crude rig, a curled
            # body): the fallback method attaches those to the nearest bone instead
            text += ("\n\nMost points found no path. The method path-or-nearest connects those to the "
                     "nearest bone: use it now?")
            box = QMessageBox(QMessageBox.Question, "Auto-connect", text, QMessageBox.Yes | QMessageBox.No, self)
            box.button(QMessageBox.Yes).setText("Use path-or-nearest")

            def answered(_result):
                if box.standardButton(box.clickedButton()) == QMessageBox.Yes:
                    st.auto_method = "path-or-nearest"
                    self.auto_connect()

            box.finished.connect(answered)
            self.last_error = text
            self._error_box = box
            box.open()
            return
        self.show_error("Auto-connect", text)

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
        if self.handlers[Mode.BONES].pending is None:
            self.scene.names.clear_chain_preview()

    def key(self, name: str) -> None:
        if name == "Delete" and self.mode != Mode.BONES and self.doc.selected_bones:
            self.doc.bone_edits.remove_bones(self.doc.selected_bones)
            return
        self.handlers[self.mode].key(name)
        if self.handlers[Mode.BONES].pending is None:
            self.scene.names.clear_chain_preview()

    # ---------------------------------------------------------------- naming
    def _named_joint(self, what: str) -> str | None:
        joint = self.doc.picked_joint
        if joint is None:
            self.doc.message(f"Click a joint first, then {what}.")
        return joint

    def rename_joint_dialog(self) -> QInputDialog | None:
        """F2: rename the joint clicked last (a non-blocking dialog; Enter applies, one undo step)."""
        joint = self._named_joint("press F2 to rename it")
        if joint is None:
            return None
        box = QInputDialog(self)
        box.setWindowTitle("Rename joint")
        box.setLabelText(f"New name for {joint}:")
        box.setTextValue(joint)
        box.textValueSelected.connect(lambda text: self._apply_name(
            lambda: self.doc.bone_edits.rename_joint(joint, text), f"Renamed {joint} to {text.strip()}."))
        self._name_box = box
        box.open()
        return box

    def name_chain_dialog(self) -> QInputDialog | None:
        """Ctrl+F2: name the chain of the selected bone (the one just built), else the chain that starts
        at the joint clicked last, in one line: "SHOULDER, ELBOW, WRIST"."""
        edits = self.doc.bone_edits
        if self.doc.selected_bones:
            chain = edits.chain_through(self.doc.selected_bones[0])
        elif self.doc.picked_joint is not None:
            chain = edits.chain_from(self.doc.picked_joint)
        else:
            self.doc.message("Select a bone of the chain (or click its first joint), then Ctrl+F2.")
            return None
        side = edits.side_prefix(chain[-1])
        box = QInputDialog(self)
        box.setWindowTitle("Name chain")
        box.setLabelText(f"Names for the {len(chain)} joints {' → '.join(chain)}, in order\n"
                         f"(commas or spaces; {side or 'no prefix'} is added on this side when left out):")
        box.setComboBoxEditable(True)
        box.setComboBoxItems([""] + [", ".join(p[:len(chain)]) for p in CHAIN_PRESETS.values()
                                     if len(p) >= len(chain)])
        box.textValueSelected.connect(lambda text: self._apply_name(
            lambda: edits.rename_chain(chain, text), None))
        self._name_box = box
        box.open()
        return box

    def _apply_name(self, action, done: str | None) -> None:
        try:
            result = action()
        except ValueError as exc:
            self.show_error("Name", str(exc))
            return
        self.doc.message(done or f"Named the chain {', '.join(result)}.")

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

    @property
    def busy(self) -> bool:
        """A background job is running (its thread has not ended yet)."""
        return self.jobs.busy

    def _close_now(self) -> None:
        self._close_confirmed = True
        self.close()

    def screenshot(self, path) -> None:
        self.plotter.screenshot(str(path))

    def closeEvent(self, event):  # noqa: N802 (Qt name)
        if self.doc.modified and not self._close_confirmed:
            event.ignore()  # ask first; close again once the edits are saved or set aside
            if self._save_box is None:
                self.when_saved_or_discarded(self._close_now, "closing")
            return
        self.timeline.stop()
        self.jobs.shutdown()  # cancel and wait for the worker: destroying a running QThread aborts
        self.autosave_timer.stop()
        self.autosaver.close()
        self.plotter.close()
        super().closeEvent(event)


def main_window_for(args) -> MainWindow:
    """A window loaded as the command line asks (see ``app.main``)."""
    w = MainWindow()
    worker = None
    if args.project:
        worker = w.files.open_project(args.project)
    elif args.demo:
        worker = w.files.load_demo(args.demo)
    elif args.volume:
        worker = w.files.open_volume(args.volume)

    def then(_=None):  # files that build on the loaded skeleton, after any background load
        if args.mskel:
            w.files.open_mskel(args.mskel)
        if args.bones:
            w.files.open_bones(args.bones)
        if args.connect:
            w.files.open_connect(args.connect)

    if worker is not None:
        worker.succeeded.connect(then)
    else:
        then()
    if not (args.project or args.demo or args.volume or args.mskel or args.connect or args.bones):
        w.offer_recovery()  # a plain start: offer a crashed session's autosave
    return w


__all__ = ["MainWindow", "main_window_for"]
