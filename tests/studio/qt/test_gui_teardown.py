"""A test's windows are destroyed in its own teardown, never during the next test's start-up."""

from __future__ import annotations

import pytest

pytestmark = pytest.mark.gui
DESTROYED: list[str] = []


def test_a_window_is_opened_and_left_to_pytest_qt(qtbot):
    from volanim_studio.qt.main_window import MainWindow

    w = MainWindow()
    qtbot.addWidget(w)  # pytest-qt closes it and calls deleteLater after the test
    w.show()
    qtbot.waitExposed(w)
    w.destroyed.connect(lambda *_: DESTROYED.append("window"))


def test_the_previous_window_is_gone_before_this_test_runs_an_event_loop():
    # no event loop has run since the previous test: only its own teardown can have deleted it
    assert DESTROYED == ["window"]
