"""Background work with progress and cancel; results come back on the GUI thread.

    task(progress, cancel) runs in a QThread
        progress(done, total) --Signal--> QProgressDialog
        Cancel button --> cancel() returns True --> Cancelled --> cancelled signal
        return value --succeeded(object)--> handler on the GUI thread
"""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtCore import QThread, Signal

from volanim_core.errors import Cancelled, FormatError


class Worker(QThread):
    """Runs ``task(progress=..., cancel=...)`` off the GUI thread."""

    progressed = Signal(int, int)
    succeeded = Signal(object)
    failed = Signal(str)
    was_cancelled = Signal()

    def __init__(self, task: Callable, parent=None):
        super().__init__(parent)
        self._task = task
        self._cancel = False

    def cancel(self) -> None:
        self._cancel = True

    def run(self) -> None:
        try:
            result = self._task(progress=self.progressed.emit, cancel=lambda: self._cancel)
        except Cancelled:
            self.was_cancelled.emit()
        except (FormatError, ValueError, OSError, MemoryError) as exc:
            self.failed.emit(str(exc))
        except Exception as exc:  # a bug: still tell the user rather than leave the dialog hanging
            self.failed.emit(f"unexpected {type(exc).__name__}: {exc}")
            raise
        else:
            self.succeeded.emit(result)
