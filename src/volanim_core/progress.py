"""Progress and cancellation without Qt.

Long functions take ``progress=None`` and ``cancel=None``:

* ``progress(done, total)`` is called between chunks of work;
* ``cancel()`` returning True makes the function raise :class:`Cancelled`.

The CLI passes a :class:`TextProgress`; the studio's worker passes callables
that forward to a Qt progress bar and read its Cancel button.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable

from volanim_core.errors import Cancelled

ProgressFn = Callable[[int, int], None]
CancelFn = Callable[[], bool]


class Reporter:
    """Combines a progress callback and a cancel check; both optional."""

    def __init__(self, progress: ProgressFn | None = None, cancel: CancelFn | None = None):
        self._progress = progress
        self._cancel = cancel

    def __call__(self, done: int, total: int) -> None:
        if self._cancel is not None and self._cancel():
            raise Cancelled("cancelled by the user")
        if self._progress is not None:
            self._progress(done, total)


def stage(progress: ProgressFn | None, start: int, stop: int, total: int = 100) -> ProgressFn:
    """One stage's ``progress(done, of)`` drawn on ``start..stop`` of a whole job's ``total``: a job
    of several stages shows one bar that only moves forward. ``progress`` may be a
    :class:`Reporter` (its cancel check then runs at each of the stage's steps) or None."""
    def report(done: int, of: int) -> None:
        if progress is not None:
            progress(start + (stop - start) * done // max(of, 1), total)
    return report


class TextProgress:
    """A one-line progress bar on stderr (redrawn at most 10 times a second)."""

    def __init__(self, label: str, stream=None, width: int = 30):
        self.label = label
        self.stream = stream or sys.stderr
        self.width = width
        self._last = 0.0
        self._shown = False

    def __call__(self, done: int, total: int) -> None:
        now = time.monotonic()
        if done < total and now - self._last < 0.1:
            return
        self._last = now
        frac = done / total if total else 1.0
        filled = int(frac * self.width)
        bar = "#" * filled + "-" * (self.width - filled)
        self.stream.write(f"\r{self.label} [{bar}] {100 * frac:5.1f}%")
        self._shown = True
        if done >= total:
            self.stream.write("\n")
            self._shown = False
        self.stream.flush()

    def close(self) -> None:
        if self._shown:
            self.stream.write("\n")
            self._shown = False
