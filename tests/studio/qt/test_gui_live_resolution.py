"""The studio picks the live preview's resolution that keeps the rate, says so, and releases at full size
(#85 item 4). The pictures' costs come from clocks the test gives (the live thread's and the draws'): what
resolution a picture is made at never depends on this machine's load."""

from __future__ import annotations

import itertools
import threading

import pytest

from ..conftest import JOB_TIMEOUT_MS
from .test_gui_pose import posed_window  # noqa: F401  (the fixture)

pytestmark = pytest.mark.gui


def ticking(step: float):
    """A clock that moves ``step`` seconds each time it is read (from any thread)."""
    count, lock = itertools.count(), threading.Lock()

    def clock() -> float:
        with lock:
            return next(count) * step
    return clock


def test_slow_live_pictures_go_to_half_size_say_so_and_fast_ones_come_back(qtbot, posed_window):  # noqa: F811
    w = posed_window
    assert w.doc.settings.live_resolution == "auto"
    live = []
    w.doc.events.preview.connect(lambda **_: live.append(w.doc.preview) if w.doc.preview.live else None)
    w.doc.select_bones([w.doc.bones.index("L_UPPERARM")])
    slider = w.pose_panel.sliders[1]

    def pictures(values):
        """One live picture per value: each waited for before the next is asked."""
        for v in values:
            n = len(live)
            slider.setValue(v)
            qtbot.waitUntil(lambda n=n: len(live) > n and w.previews.live_worker.idle, timeout=JOB_TIMEOUT_MS)
        return [p.factor for p in live[-len(values):]]

    # the live thread's clock alone: each of a picture's three stages costs one step; the draws cost nothing
    # (a draw is painted when the event loop gets to it, before or after the next step is set)
    w.scene.frames.clock = lambda: 0.0
    w.previews.clock = ticking(0.05)  # 150 ms a picture: under 10 a second
    slider.setSliderDown(True)
    assert pictures([-5, -10, -15, -20]) == [1, 1, 1, 2]
    assert w.verdict_label.plain.startswith("Live at 1/2: ")
    w.previews.clock = ticking(0.002)  # 6 ms: full size keeps the rate. The window at half size holds the
    assert pictures([-25, -30, -35, -40]) == [2, 2, 1, 1]  # slow picture and two fast ones: their median
    assert w.verdict_label.plain.startswith("Live at full size: ")
    w.previews.clock = ticking(0.05)
    assert pictures([-45, -50, -55]) == [1, 1, 2]  # the window at full size: one fast picture, then two slow
    slider.setSliderDown(False)  # the release: the full picture at full size, whatever the live one's
    qtbot.waitUntil(lambda: not w.busy and w.doc.preview is not None and not w.doc.preview.live
                    and w.doc.preview.report is not None, timeout=JOB_TIMEOUT_MS)
    assert w.doc.preview.factor == 1
    w.doc.settings.live_resolution = "quarter"  # the user's own choice, kept whatever the cost
    slider.setSliderDown(True)
    assert pictures([-60, -65]) == [4, 4]
    slider.setSliderDown(False)
    qtbot.waitUntil(lambda: not w.busy, timeout=JOB_TIMEOUT_MS)
