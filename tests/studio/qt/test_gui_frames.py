"""A live picture counts as drawn only once a draw that holds it has ended, and a picture with its status line is
composed once (#85). The frog's drag: the next picture began when Qt composed the window for the status line,
before the picture was drawn, and was made beside the draw (its body 6 -> 35 ms); each picture was composed
twice (15-20 ms each on software GL). Orders of events in a real window, never their times."""

from __future__ import annotations

import time

import pytest
from PySide6.QtWidgets import QApplication

from ..conftest import JOB_TIMEOUT_MS, new_window
from .test_gui_pose import posed_window  # noqa: F401  (the fixture)

pytestmark = pytest.mark.gui


def events_of(w) -> list[str]:
    """'draw' as each draw begins, 'shown' at each composition of the window (Qt's frameSwapped)."""
    seen: list[str] = []
    w.scene.plotter.render_window.AddObserver("StartEvent", lambda *_: seen.append("draw"))
    w.scene.plotter.frameSwapped.connect(lambda: seen.append("shown"))
    return seen


def settled(qtbot, w) -> None:
    """The window drawn once and idle: a render asked and its draw ended."""
    ended = []
    w.scene.frames.after_next(lambda: ended.append(True))
    w.scene.render()
    qtbot.waitUntil(lambda: bool(ended), timeout=10_000)
    qtbot.wait(50)


def test_a_status_line_composed_is_not_the_picture_drawn(qtbot):
    w = new_window(qtbot)
    settled(qtbot, w)
    seen = events_of(w)
    calls = []
    w.scene.frames.after_next(lambda: calls.append(list(seen)))
    w.verdict_label.setText("Live at 1/4: 6 ms")  # the window composed again: no draw of the scene
    qtbot.waitUntil(lambda: "shown" in seen, timeout=10_000)
    assert "draw" not in seen and calls == [], "a composition without a draw let the next picture begin"
    w.scene.render()
    qtbot.waitUntil(lambda: bool(calls), timeout=10_000)
    # called as the draw asked after it was given ends, before that draw is composed (the label's setText may
    # compose the window more than once before: how often is Qt's, not ours)
    assert calls[0].count("draw") == 1 and calls[0][-1] == "draw", calls
    w.scene.render()
    qtbot.waitUntil(lambda: seen.count("draw") >= 2, timeout=10_000)
    assert len(calls) == 1  # given once, called once


def test_each_live_picture_of_a_drag_is_drawn_before_the_window_is_composed(qtbot, posed_window):  # noqa: F811
    w = posed_window
    seen = events_of(w)
    w.previews.live_worker.made.connect(lambda *_: seen.append("made"))  # after the studio's own: set, not drawn
    w.doc.select_bones([w.doc.bones.index("L_UPPERARM")])
    slider = w.pose_panel.sliders[1]
    slider.setSliderDown(True)
    app = QApplication.instance()
    for v in range(-2, -62, -2):  # a drag: a value, then one pass of the event loop, as mouse moves come
        slider.setValue(v)
        app.processEvents()
        time.sleep(0.005)
    slider.setSliderDown(False)
    qtbot.waitUntil(lambda: not w.busy, timeout=JOB_TIMEOUT_MS)
    made = [i for i, e in enumerate(seen) if e == "made"]
    assert len(made) >= 2, seen
    for i in made:
        after = [e for e in seen[i + 1:] if e != "made"]
        assert not after or after[0] == "draw", f"a picture's window composed before it was drawn: {seen}"

