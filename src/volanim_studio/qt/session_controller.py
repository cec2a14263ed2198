"""The session's safety net: autosave, crash recovery, the unsaved-changes marker and "Save changes?".

    timer, every autosave.POLL_SECONDS --> Autosaver.poll: anything changed (an edit, a held drag's
        latest step, the view) is snapshotted and written on the autosave's own thread
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


class SessionController(Controller):
    def __init__(self, window, *, poll_seconds: float = autosave.POLL_SECONDS):
        super().__init__(window)
        self.autosaver = autosave.Autosaver(self.doc)
        self.timer = QTimer(window)
        self.timer.timeout.connect(self.poll)
        self.timer.start(int(1000 * poll_seconds))
        self.save_box: QMessageBox | None = None  # the "Save changes?" question while it is open
        self.close_confirmed = False
        for event in (self.doc.events.project, self.doc.events.skeleton, self.doc.undo.events.changed):
            event.connect(self.update_title)
        self.update_title()

    # ------------------------------------------------------------ autosave
    def poll(self) -> None:
        """Autosave what changed since the last snapshot, whatever else is going on (a held drag too: the
        snapshot is cheap and the writing happens on the autosave's own thread)."""
        try:
            self.autosaver.poll()
        except (OSError, ValueError) as exc:
            self.doc.message(f"Autosave failed: {exc}")

    def close(self) -> None:
        """A clean exit (the edits were saved or set aside): nothing left to recover."""
        self.timer.stop()
        self.autosaver.close()

    def offer_recovery(self, ask=None) -> Worker | None:
        """If earlier sessions crashed, offer to restore one of their autosaves, each said with what it holds.

        ``ask(recoveries) -> chosen path or None`` replaces the question dialog (tests). None declines them
        all (kept a week, openable as projects, not asked again). The chosen one is removed only once this
        session has autosaved what it restored; the others are untouched and offered next time.
        """
        found = autosave.find_recoveries()
        if not found:
            return None
        chosen = (ask or self._ask_recovery)(found)
        if chosen is None:
            for f in found:
                autosave.decline(f)  # kept a week (the folder can still be opened as a project), not asked again
            return None

        def opened(ok: bool) -> None:
            if not ok:  # nothing is deleted: the next start offers it again
                self.doc.message(f"The autosave in {chosen.parent} was not restored; it is kept.")
                return
            self.doc.project_path = None  # a restored session saves where the user says, not into the cache
            self.doc.undo.mark_modified()  # it is saved nowhere yet
            try:
                self.autosaver.save()  # what was restored is safe in this session's folder ...
            except (OSError, ValueError) as exc:
                self.doc.message(f"Restored, but the autosave of it failed ({exc}); the old autosave is kept.")
                return
            autosave.discard(chosen)  # ... before the restored session's folder goes (only that one)
            others = len(found) - 1
            self.doc.message(f"Restored the autosaved session ({len(self.doc.bones)} bones)."
                             + (f" {others} other autosave{'s' if others > 1 else ''} kept for the next start."
                                if others else ""))

        return self.window.files.open_project(chosen, on_opened=opened)

    def _ask_recovery(self, found: list[Path]) -> Path | None:
        from .recovery_dialog import RecoveryDialog

        dialog = RecoveryDialog(found, [autosave.describe(f) for f in found], self.window)
        return dialog.chosen if dialog.exec() else None

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
            if button == QMessageBox.Save:  # then() once it is written (not if it fails: the error is said)
                self.window.files.save_project(then=lambda: self.when_saved_or_discarded(then, doing))
                return
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
