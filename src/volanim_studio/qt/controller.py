"""What the main window hands each controller, and the one way a user action reports a user error."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from .worker import USER_ERRORS

FAILED = object()  # what :meth:`Controller.attempt` returns when the action was refused


class Controller:
    """Base of the window's controllers (composed by the window, never inheriting from it)."""

    def __init__(self, window):
        self.window = window  # the parent of dialogs
        self.doc = window.doc
        self.scene = window.scene
        self.jobs = window.jobs
        self.show_error = window.show_error
        self.ask = window.ask

    def folder(self, name: str = "") -> str:
        """Where a file dialog opens: the project's folder (else the volume's, the skeleton's, the
        working directory), with ``name`` as the suggested file."""
        from pathlib import Path

        d = self.doc
        known = next((p for p in (d.project_path, d.volume_path, d.mskel_path) if p), None)
        where = Path(known).resolve().parent if known else Path.cwd()
        return str(where / name) if name else str(where)

    def attempt(self, title: str, action: Callable[[], Any], done: str | Callable[[Any], str] | None = None):
        """Run ``action()``: a bad file, a full disk or a refused value is shown under ``title`` (the
        document stays as it was) and :data:`FAILED` returned; otherwise ``done`` (a message, or a
        function of the result making one) goes to the status bar and the result is returned."""
        try:
            result = action()
        except USER_ERRORS as exc:
            self.show_error(title, str(exc))
            return FAILED
        if done is not None:
            self.doc.message(done(result) if callable(done) else done)
        return result

    def read_then(self, path, read: Callable, apply: Callable[[Any], Any]):
        """``read(progress)`` in the window's reader thread (a progress dialog with Cancel; the document's
        own job, if one runs, goes on), then ``apply(what was read)`` on the GUI thread (#61: no file is
        read on the GUI thread). The reader's worker, or None while another file is still being read
        (said in the status bar). A bad file is shown naming it; a read cannot stop half-way, so Cancel
        (or closing the studio) lets it finish and applies nothing (the runner drops a cancelled result)."""
        from pathlib import Path

        name = Path(path).name
        readers = self.window.readers
        if readers.busy:
            self.doc.message(f"Still reading a file: open {name} when it has been read.")
            return None
        return readers.run(f"Reading {name}", lambda progress, cancel: read(progress), apply)
