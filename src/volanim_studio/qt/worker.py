"""Background work with progress and cancel; results come back on the GUI thread.

    JobRunner.run(label, task, on_done)
        task(progress, cancel) runs in a Worker (a QThread)
            progress(done, total) --Signal--> QProgressDialog
            Cancel button --> cancel() returns True --> Cancelled --> was_cancelled
            return value --succeeded(object)--> on_done on the GUI thread (dropped if cancelled by then)
            on_done raises --> failed(message): said, and whoever waits on the job hears it failed
    JobRunner.run(..., background=True)   no dialog and nothing modal: the user goes on working; the next
        job asked for cancels it and starts once its thread has ended (a full preview's breakage report)
    JobRunner.run(..., cancellable=False)   a dialog without Cancel, for what stops at no half-way point
        (a project's save: the window's own runner, ``savers``, writes it while the user goes on)
    JobRunner.shutdown()   (window close) cancel, show "Finishing…", wait as long as it takes

Why ``shutdown`` never gives up: a QThread object destroyed while its thread
runs aborts the whole process ("QThread: Destroyed while thread is still
running"). A numba kernel cannot be interrupted, and its first compile or a
large frame can take longer than any fixed timeout, so the window waits
(keeping the UI painted) until the task has seen its cancel flag and returned.
For the same reason a job counts as running until its thread has really ended,
not merely until it emitted its result. A job cancelled after its task returned
(Cancel pressed, or the window closed, as the last step finished) is still
cancelled: its result is dropped, so nothing is applied or opened after the
user said no or the window went away.
"""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtCore import QCoreApplication, QEventLoop, QObject, Qt, QThread, QTimer, Signal
from PySide6.QtWidgets import QProgressDialog

from volanim_core.errors import Cancelled

#: What a user can cause and must be told about in words: a bad or unreadable file
#: (FormatError is a ValueError; readers raise OSError subclasses for the rest) or a
#: refused value. Every file action of the studio catches exactly these.
USER_ERRORS = (OSError, ValueError)


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
        self.background = False  # JobRunner.run(background=True): no dialog, cancelled by the next job

    def cancel(self) -> None:
        self._cancel = True

    @property
    def cancelled(self) -> bool:
        """Cancel was asked for (the task may have finished anyway)."""
        return self._cancel

    def run(self) -> None:
        try:
            result = self._task(progress=self.progressed.emit, cancel=lambda: self._cancel)
        except Cancelled:
            self.was_cancelled.emit()
        except (*USER_ERRORS, MemoryError) as exc:
            self.failed.emit(str(exc))
        except Exception as exc:  # a bug: still tell the user rather than leave the dialog hanging
            self.failed.emit(f"unexpected {type(exc).__name__}: {exc}")
            raise
        else:
            self.succeeded.emit(result)


class JobRunner(QObject):
    """One background job at a time for a window: progress dialog, Cancel, clean shutdown.

    ``show_error(title, text)`` and ``message(text)`` report failures and
    cancellations; ``on_idle()`` runs after every job (e.g. to give keyboard
    focus back to the window).
    """

    def __init__(self, window, *, show_error: Callable, message: Callable, on_idle: Callable | None = None):
        super().__init__(window)
        self._window = window
        self._show_error = show_error
        self._message = message
        self._on_idle = on_idle or (lambda: None)
        self.worker: Worker | None = None
        self.dialog: QProgressDialog | None = None
        self._preempting = False  # run() is ending a background job (and handling events while it waits)
        self._applying = 0  # results waiting for their next step (later())
        self._closed = False  # shut down: the window is closing, no job starts any more

    @property
    def busy(self) -> bool:
        """A job the user waits for runs, or its result is still being applied (:meth:`later`): another is
        refused. A background job does not count (``run`` cancels it first)."""
        return self._preempting or self._applying > 0 or (self.worker is not None and not self.worker.background)

    @property
    def running(self) -> bool:
        """Any job's thread is running, a background one too (or one is being started or applied)."""
        return self._preempting or self._applying > 0 or self.worker is not None

    def later(self, apply: Callable[[], None]) -> None:
        """``apply()`` at the next event-loop pass, the runner busy until it has run: a job's result put in
        the document in two steps lets the window draw in between (#83 item 13: opening mannequin-large's
        project applied the volume and the project's files in one 0.17 s pass of the GUI thread)."""
        self._applying += 1

        def run():
            try:
                if not self._closed:  # the window closed meanwhile: nothing more is put in it
                    apply()
            finally:
                self._applying -= 1
                self._on_idle()
        # a timer, not a posted call (singleShot 0): due timers go first, so the window's own (a paint, a
        # playback tick) run between the two steps instead of after both
        QTimer.singleShot(1, self._window, run)

    def run(self, label: str, task: Callable, on_done: Callable, *, background: bool = False,
            cancellable: bool = True) -> Worker:
        """Run ``task(progress, cancel)`` in a worker with a progress dialog and Cancel (``background``: with
        neither, cancelled by the next job asked for; not ``cancellable``: a dialog without Cancel, for a task
        that cannot stop half-way, like a save)."""
        # Ending a background job handles events while its thread winds down; a timer firing then (a preview
        # asked for "when idle") must see a busy runner and wait, not start a job inside this one (#83: F5 just
        # after entering Pose mode raised "another job is running"); and a background job its last signals
        # started (a picture's report) is ended in turn.
        if self._closed:  # a timer firing while the window closes (a preview "when idle"): started, a job's
            return Worker(task, self._window)  # thread would outlive the window (Qt aborts); this one never runs
        self._preempting = True
        try:
            while self.worker is not None and self.worker.background:
                self._preempt()
        finally:
            self._preempting = False
        if self.worker is not None:
            raise RuntimeError("another job is running")
        worker = Worker(task, self._window)
        worker.background = background
        dialog = None
        if not background:
            dialog = QProgressDialog(label, "Cancel", 0, 100, self._window)
            dialog.setWindowModality(Qt.WindowModal)
            dialog.setMinimumDuration(300)
            worker.progressed.connect(lambda d, t: dialog.setValue(int(100 * d / max(t, 1))))
            if cancellable:
                dialog.canceled.connect(worker.cancel)
            else:
                dialog.setCancelButton(None)

        def finish():
            worker.wait()  # run() is returning: make "not busy" mean the thread has ended
            if dialog is not None:
                dialog.reset()
            self.worker = None
            self.dialog = None
            self._on_idle()

        def cancelled():
            finish()
            if not background:  # a background job is cancelled by what the user did next: nothing to say
                self._message(f"{label}: cancelled.")

        def succeeded(result):
            if worker.cancelled:
                cancelled()
                return
            finish()
            try:
                on_done(result)
            except USER_ERRORS as exc:  # applying the result can still find it bad: a failed job, said
                worker.failed.emit(str(exc))  # whoever waits on the job (open_project's on_opened) hears of it
            except Exception as exc:  # a bug: still tell the user and whoever waits, then let it be seen
                worker.failed.emit(f"unexpected {type(exc).__name__}: {exc}")
                raise

        def failed(msg):
            if self.worker is worker:  # not after its result was applied (a next job may be running)
                finish()
            self._show_error(label, msg)

        worker.succeeded.connect(succeeded)
        worker.failed.connect(failed)
        worker.was_cancelled.connect(cancelled)
        self.worker, self.dialog = worker, dialog
        worker.start()
        return worker

    def _preempt(self) -> None:
        """Cancel the background job and wait for its thread (its task checks ``cancel`` between chunks),
        handling its last signals, so that ``self.worker`` is free again."""
        worker = self.worker
        worker.cancel()
        while not worker.wait(20):
            QCoreApplication.processEvents(QEventLoop.ExcludeUserInputEvents)
        while self.worker is worker:  # its queued signal (cancelled, or a result dropped as cancelled)
            QCoreApplication.processEvents(QEventLoop.ExcludeUserInputEvents)

    def shutdown(self) -> None:
        """Cancel the running job and wait until its thread has ended, however long that takes; start none
        after it."""
        self._closed = True
        worker = self.worker
        if worker is None:
            return
        worker.cancel()
        self._message("Finishing the running job before closing…")
        if self.dialog is not None:
            self.dialog.setLabelText("Finishing the running job before closing…")
            self.dialog.setCancelButton(None)
            self.dialog.show()
        while not worker.wait(50):
            QCoreApplication.processEvents(QEventLoop.ExcludeUserInputEvents)
        QCoreApplication.processEvents(QEventLoop.ExcludeUserInputEvents)  # its last signals
