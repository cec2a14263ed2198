"""Garbage is collected on the GUI thread only, whatever a worker thread allocates.

Python's automatic collection runs in whichever thread happens to allocate when a
generation fills up. A worker reconstructing a frame allocates a lot, so it used to
collect the GUI's cyclic garbage too, and a cycle holding a Qt widget or a VTK window
(a closed dialog, a replaced actor) was then destroyed off the GUI thread: a rare
segmentation fault (seen once in CI, in the preview-cancel test).
"""

from __future__ import annotations

import gc
import threading

import pytest

from ..conftest import JOB_TIMEOUT_MS

pytestmark = pytest.mark.gui


class _Cycle:
    """Unreachable garbage that only the cycle collector frees; records the thread that freed it."""

    freed_on: list[str] = []

    def __init__(self):
        self.me = self

    def __del__(self):
        _Cycle.freed_on.append(threading.current_thread().name)


def test_a_worker_that_allocates_does_not_collect_the_gui_threads_garbage(qtbot, window):
    _Cycle.freed_on = []
    gc.collect()  # generation counts start from zero: the next collection is an automatic one
    _Cycle()

    def allocate(progress, cancel):  # many container allocations: several automatic collections' worth
        return len([[] for _ in range(100_000)])

    window.jobs.run("Allocating", allocate, lambda n: None)
    qtbot.waitUntil(lambda: not window.busy, timeout=JOB_TIMEOUT_MS)
    gui = threading.main_thread().name
    # not by the worker; the GUI thread's own collector may already have freed it while this test
    # waited (its timer runs whenever generation 0 fills -- a slow job gave it time: one local run)
    assert set(_Cycle.freed_on) <= {gui}
    keep = [[] for _ in range(2 * gc.get_threshold()[0])]  # the GUI thread fills generation 0
    qtbot.waitUntil(lambda: bool(_Cycle.freed_on), timeout=10_000)  # and its collector timer frees the cycle
    assert _Cycle.freed_on == [gui] and len(keep)
