"""Guards against a Qt binding bug that crashed the studio's scripts: PySide6 6.12.0 drops a
reference to None on every QApplication.processEvents() call; Python 3.11 aborts after ~100k."""

from __future__ import annotations

import sys

import pytest

pytestmark = pytest.mark.gui


def test_process_events_does_not_leak_none(qapp):
    before = sys.getrefcount(None)
    for _ in range(2000):
        qapp.processEvents()
    assert abs(sys.getrefcount(None) - before) < 100
