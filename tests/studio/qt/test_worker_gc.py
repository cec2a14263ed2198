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


def _garbage_in_the_oldest_generation() -> None:
    """A _Cycle that has survived to generation 2 and then become garbage: only a full collection frees it."""
    held = [_Cycle()]
    gc.collect(1)
    gc.collect(1)  # survived twice: generation 2
    held.clear()
    for _ in range(gc.get_threshold()[2] + 1):  # a full collection falls due
        gc.collect(1)


def test_a_full_collection_waits_while_the_user_drags_or_plays(qtbot, window):
    """mannequin-large's session holds ~380 k objects and a full collection of them stopped the GUI thread for
    100-160 ms: in a play, one frame in ~50 s of frames froze (the gaps test's play phase, 410 ms once in CI,
    in a pytest worker holding more). While a bone is dragged or the timeline plays it waits; then it is made."""
    from volanim_studio.qt.gui_gc import HOLD_MAX_TICKS, collect_on_gui_thread

    collector = collect_on_gui_thread()
    gui = threading.main_thread().name
    for flag in ("dragging", "playing"):
        _Cycle.freed_on = []
        gc.collect()
        _garbage_in_the_oldest_generation()
        setattr(window.doc.settings, flag, True)
        assert window.interacting()
        collector.collect()
        assert _Cycle.freed_on == [] and collector.held == 1  # held
        setattr(window.doc.settings, flag, False)
        collector.collect()
        assert _Cycle.freed_on == [gui] and collector.held == 0  # made once the interaction ended

    # a minute-long play does not hold it for ever
    _Cycle.freed_on = []
    _garbage_in_the_oldest_generation()
    window.doc.settings.playing = True
    for _ in range(HOLD_MAX_TICKS):
        collector.collect()
    assert _Cycle.freed_on == []
    collector.collect()
    assert _Cycle.freed_on == [gui]
    window.doc.settings.playing = False


def test_the_studio_freezes_its_start_up_before_reading_any_file(qtbot):
    """``volanim-studio``'s window (``main_window_for``) moves the program's start-up objects out of later
    collections (a full one then walks ~100 k objects, not ~380 k), and nothing of a file it reads."""
    from volanim_studio.app import build_parser
    from volanim_studio.qt.main_window import main_window_for

    try:
        w = main_window_for(build_parser().parse_args(["--demo", "mannequin"]))
        qtbot.addWidget(w)
        assert gc.get_freeze_count() > 0
        qtbot.waitUntil(lambda: w.doc.skeleton is not None and not w.busy, timeout=JOB_TIMEOUT_MS)
        tracked = gc.get_objects()
        assert not any(o is w.doc for o in tracked)  # built before: frozen
        assert any(o is w.doc.skeleton for o in tracked) or not gc.is_tracked(w.doc.skeleton)
        assert any(o is w.doc.bones for o in tracked)  # read after: collected as usual
    finally:
        gc.unfreeze()  # the rest of this test session's objects back where they were
