"""The live previews' thread (#85): the next picture is begun once the last one is drawn."""

from __future__ import annotations

import pytest

from volanim_studio.qt.live_worker import LiveWorker

pytestmark = pytest.mark.gui


def test_the_next_picture_is_begun_once_the_last_one_is_drawn(qtbot):
    """A draw holds Python's lock and both cores (software GL): a picture made meanwhile took the draw's time
    on top of its own. The second ask waits, however long the window takes to draw the first."""
    worker = LiveWorker()
    made, order = [], []
    worker.made.connect(made.append)
    try:
        worker.ask(lambda: order.append("first") or 1)
        qtbot.waitUntil(lambda: made == [1])
        worker.ask(lambda: order.append("second") or 2)
        qtbot.wait(100)  # the window drawing the first picture
        assert not worker.idle  # asked, not begun
        order.append("drawn")
        worker.drawn()
        qtbot.waitUntil(lambda: made == [1, 2])
        assert order == ["first", "drawn", "second"] and worker.begun == 2
    finally:
        worker.drawn()
        worker.close()


def test_an_ask_with_nothing_drawn_yet_is_begun_at_once_and_close_never_waits_on_a_draw(qtbot):
    worker = LiveWorker()
    made = []
    worker.made.connect(made.append)
    worker.ask(lambda: 1)
    qtbot.waitUntil(lambda: made == [1])
    worker.ask(lambda: 2)  # waits for a draw that never comes: close still returns
    worker.close()
    assert made == [1] and worker.begun == 1
