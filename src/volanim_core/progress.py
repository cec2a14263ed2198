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
Clock = Callable[[], float]  # seconds, only differences count (time.perf_counter); tests pass a fake one


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


class Pacer:
    """Cuts ``0..total`` into launches that each last about ``seconds``: the first is ``first`` long and
    measures the pace, each next one is sized from the last one's pace (never under ``least``). Between
    launches the caller reports progress and checks cancel, so both stay responsive; a fast job is not
    cut into many launches (a parallel launch ends on its slowest thread).

    The pace is read off ``clock``, so a loaded machine changes the launches but never the result; a test
    passes a fake clock and knows every launch.

    >>> ticks = iter(range(100))
    >>> pacer = Pacer(first=4, least=2, seconds=3.0, clock=lambda: next(ticks))  # each launch takes 1 s
    >>> list(pacer.spans(20))  # 4 rows in 1 s: 12 rows make 3 s
    [(0, 4), (4, 16), (16, 20)]
    """

    def __init__(self, first: int, least: int, seconds: float, clock: Clock = time.perf_counter):
        self.size = max(1, int(first))
        self.least = max(1, int(least))
        self.seconds = float(seconds)
        self.clock = clock

    def spans(self, total: int):
        """Yield ``(start, stop)`` launches covering ``0..total``; ``self.size`` is then the next launch's
        length (what a second pass over the same work uses)."""
        start = 0
        while start < total:
            stop = min(total, start + self.size)
            began = self.clock()
            yield start, stop
            pace = (stop - start) / max(self.clock() - began, 1e-6)
            start, self.size = stop, max(self.least, int(pace * self.seconds))


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
