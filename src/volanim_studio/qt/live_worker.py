"""The live previews' own thread: the newest pose wins, the GUI thread only draws (#83 item 13).

    GUI thread                          live thread
    ask(make) --> the mailbox (one slot: a newer ask replaces a waiting one)
                                        make() --> a whole picture of one pose (or the error it raised)
    made(result) <-- queued signal <--  (an ask that came while it worked is made next; older ones never)

A drag or playback asks far more often than a large body can be re-grown: the asks in between are dropped
whole, so every picture drawn is one pose's body with that pose's bones -- never half of one (#83 item 5) --
and the window never waits on a reconstruction (mannequin-large's live frame held the GUI thread 0.6 s).
``make`` must touch no Qt object and no document: it is given arrays (the tskel, the transfer function).

The next picture is begun once the last one is drawn (:meth:`drawn`), not while it is drawn. A draw holds
Python's lock (VTK's wheels never release it) and software GL's threads hold the cores: a picture made
meanwhile waited on both, and each of its stages took the draw's time on top of its own (#85: the frog's
quarter-size body, 4 ms alone, 40 ms beside the draw). Made after the draw, a stage costs what it costs.

The thread lives as long as the window; :meth:`close` waits for the picture being made (never abandoned
mid-kernel: GUI teardown never destroys a running worker).
"""

from __future__ import annotations

import threading
from collections.abc import Callable

from numba import config, set_num_threads
from PySide6.QtCore import QObject, Signal


def live_threads() -> int:
    """Threads the live pictures' kernels use: all cores but one, kept for the GUI thread (its drag events, the
    draw). On this 2-core machine: one. Two threads' kernels waited at their barriers for the core the window
    was using: the mannequin's half-size faces took 11-15 ms so, 2-4 ms on one thread (#85)."""
    return max(1, config.NUMBA_NUM_THREADS - 1)


class LiveWorker(QObject):
    """One thread making live pictures, newest first; ``made(result or exception)`` on the GUI thread."""

    made = Signal(object)
    _done = Signal(object)  # from the live thread: queued to the GUI thread, then `made`

    def __init__(self, parent=None):
        super().__init__(parent)
        self._lock = threading.Condition()
        self._waiting: Callable | None = None
        self._working = False
        self._in_flight = 0  # results sent and not yet received on the GUI thread
        self._drawing = False  # the last result not yet drawn (or dropped): the next waits for it (drawn())
        self.begun = 0  # pictures begun (a picture begun is made and sent, whatever is asked after it)
        self._done.connect(self._deliver)
        self._closed = False
        self._thread = threading.Thread(target=self._run, name="live previews", daemon=True)
        self._thread.start()

    def ask(self, make: Callable) -> None:
        """Make ``make()`` next, in place of any ask still waiting (a newer pose supersedes it)."""
        with self._lock:
            if self._closed:
                return
            self._waiting = make
            self._lock.notify()

    def drawn(self) -> None:
        """The last result is drawn (or will not be): the next picture may be begun."""
        with self._lock:
            self._drawing = False
            self._lock.notify()

    def forget(self) -> None:
        """Drop the ask still waiting (the one being made is finished, and its result still sent)."""
        with self._lock:
            self._waiting = None

    @property
    def idle(self) -> bool:
        """Nothing waiting, nothing being made, no result on its way to the GUI thread."""
        with self._lock:
            return self._waiting is None and not self._working and not self._in_flight

    def close(self) -> None:
        """Make no more; wait for the picture being made (a kernel is never abandoned half-way)."""
        with self._lock:
            self._closed = True
            self._waiting = None
            self._lock.notify()
        self._thread.join()
        with self._lock:
            self._in_flight = 0  # a result still queued is not drawn: the window is closing

    def _run(self) -> None:
        set_num_threads(live_threads())  # numba's setting is the calling thread's: this one's kernels only
        while True:
            with self._lock:
                while (self._waiting is None or self._drawing) and not self._closed:
                    self._lock.wait()
                if self._closed:
                    return
                make, self._waiting, self._working = self._waiting, None, True
                self.begun += 1
            try:
                result = make()
            except Exception as exc:  # said on the GUI thread (a bad attachment is a ValueError, a bug is shown)
                result = exc
            with self._lock:
                self._working = False
                if self._closed:
                    return
                self._in_flight += 1
                self._drawing = True
            self._done.emit(result)

    def _deliver(self, result) -> None:
        with self._lock:
            if self._closed:
                return
            self._in_flight -= 1
        self.made.emit(result)
