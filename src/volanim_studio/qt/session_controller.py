"""The session's safety net: autosave, crash recovery, the unsaved-changes marker and "Save changes?".

    undo stack changed / timer --> Autosaver (every N edits, every minute; a held drag's steps once the
        window is idle after its release)
    doc project / skeleton / undo events --> window title "volanim studio — NAME[*]" (* = unsaved edits)
    close, open another volume or project --> when_saved_or_discarded(then): Save / Discard / Cancel
        Discard --> Autosaver.set_aside (kept a week, openable as a project) --> then()
    a plain start --> offer_recovery: a crashed session's autosave

Owned by the main window (composed, like the other controllers).
"""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QTimer
from PySide6.QtWidgets import QMessageBox

from ..model import autosave
from .controller import Controller
from .worker import Worker

RELEASE_POLL_MS = 300  # how often a released drag's save looks for an idle window


class SessionController(Controller):
    def __init__(self, window, *, every_edits: int = 5, every_seconds: float = 60.0):
        super().__init__(window)
        self.autosaver = autosave.Autosaver(self.doc, every_edits=every_edits, every_seconds=every_seconds)
        self.doc.undo.events.changed.connect(self._after_edit)
        # a drag's steps are saved after its release, once the window is idle: its preview first (the frog's
        # first save formats 0.5 M numbers: 2 s on the GUI thread, which held the picture back, #65)
        self._after_release = QTimer(window)
        self._after_release.setInterval(RELEASE_POLL_MS)
        self._after_release.timeout.connect(self._save_after_release)
        self.doc.settings.events.dragging.connect(
            lambda value, **_: self._after_release.stop() if value else self._after_release.start())
        self.timer = QTimer(window)
        self.timer.timeout.connect(self._tick)
        self.timer.start(int(1000 * min(every_seconds, 60.0)))
        self.save_box: QMessageBox | None = None  # the "Save changes?" question while it is open
        self.close_confirmed = False
        for event in (self.doc.events.project, self.doc.events.skeleton, self.doc.undo.events.changed):
            event.connect(self.update_title)
        self.update_title()

    # ------------------------------------------------------------ autosave
    def _after_edit(self, **_) -> None:
        try:
            self.autosaver.edited()
        except (OSError, ValueError) as exc:
            self.doc.message(f"Autosave failed: {exc}")

    def _save_after_release(self) -> None:
        if self.window.busy:  # the release's preview and report: the save waits for them
            return
        self._after_release.stop()
        self._after_edit()

    def _tick(self) -> None:
        try:
            self.autosaver.tick()
        except (OSError, ValueError) as exc:
            self.doc.message(f"Autosave failed: {exc}")

    def close(self) -> None:
        """A clean exit (the edits were saved or set aside): nothing left to recover."""
        self.timer.stop()
        self._after_release.stop()
        self.autosaver.close()

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
                self.window, "Restore unsaved work?", f"volanim studio did not close properly last time.\n"
                f"Restore the session autosaved {autosave.describe(latest)}?", QMessageBox.Yes | QMessageBox.No)
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
            try:
                self.autosaver.save()  # what was restored is safe in this session's folder ...
            except (OSError, ValueError) as exc:
                self.doc.message(f"Restored, but the autosave of it failed ({exc}); the old autosave is kept.")
                return
            for f in found:  # ... before the crashed sessions' folders go
                autosave.discard(f)
            self.doc.message(f"Restored the autosaved session ({len(self.doc.bones)} bones).")

        return self.window.files.open_project(latest, on_opened=opened)

    # ------------------------------------------------------ unsaved changes
    def update_title(self, **_) -> None:
        """``volanim studio — NAME[*]``: Qt shows the ``*`` while the document has unsaved edits."""
        path = self.doc.project_path
        name = Path(path).name if path else (None if self.doc.is_empty else "untitled")
        self.window.setWindowTitle("volanim studio" + (f" — {name}" if name else "") + "[*]")
        self.window.setWindowModified(self.doc.modified)

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
                          QMessageBox.Save | QMessageBox.Discard | QMessageBox.Cancel, self.window)
        box.setInformativeText("Discarded changes are kept for a week in the autosave folder "
                               f"({self.autosaver.root}); they can be opened as a project.")
        box.setDefaultButton(QMessageBox.Save)

        def answered(_result) -> None:
            self.save_box = None
            button = box.standardButton(box.clickedButton()) if box.clickedButton() else QMessageBox.Cancel
            if button == QMessageBox.Save:
                if self.window.files.save_project() is None:
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
        self.save_box = box
        box.open()

    def may_close(self) -> bool:
        """Whether the window may close now; if not, the question is asked and a yes closes it later."""
        if not self.doc.modified or self.close_confirmed:
            return True
        if self.save_box is None:
            self.when_saved_or_discarded(self._close_now, "closing")
        return False

    def _close_now(self) -> None:
        self.close_confirmed = True
        self.window.close()
