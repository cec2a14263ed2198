"""Long jobs: cancel leaves the window responsive, closing waits for a running job."""

from __future__ import annotations

import pytest

from volanim_core import io, samples

from ..conftest import JOB_TIMEOUT_MS

pytestmark = pytest.mark.gui


def test_cancel_leaves_the_gui_responsive(qtbot, window, tmp_path):
    io.write_volume(tmp_path / "frog.VOL", samples.frog().volume)
    messages = []
    window.doc.events.message.connect(lambda text: messages.append(text))
    worker = window.files.open_volume(tmp_path / "frog.VOL", params={"lo": 1, "hi": None, "fill": True})
    assert window.busy
    from PySide6.QtWidgets import QPushButton

    window.jobs.dialog.findChild(QPushButton).click()  # the progress dialog's Cancel button
    qtbot.waitUntil(lambda: not window.busy, timeout=JOB_TIMEOUT_MS)
    assert worker.isFinished() and any("cancelled" in m for m in messages)
    assert len(window.doc.skeleton) < 10000  # still the mannequin
    window.display_panel.thinness_slider.setValue(100)  # and the GUI still works
    assert window.scene.shown_points == window.doc.visible_count


@pytest.mark.long("closing the window while a job runs waits for the worker: teardown never destroys a running one")
def test_close_while_a_job_runs_waits_for_it_instead_of_aborting(qtbot):
    """Closing used to wait 5 s and then destroy the running QThread: SIGABRT for the whole app."""
    import time

    from volanim_studio.qt.main_window import MainWindow

    w = MainWindow()
    qtbot.addWidget(w)
    w.show()
    seen = {}

    def stubborn(progress, cancel):  # a first numba compile: it cannot look at the cancel flag for a while
        time.sleep(5.5)
        seen["cancel"] = cancel()
        return "done"

    worker = w.jobs.run("A long job", stubborn, lambda result: seen.setdefault("result", result))
    messages = []
    w.doc.events.message.connect(lambda text: messages.append(text))
    w.close()
    assert worker.isFinished() and not w.busy
    assert seen["cancel"] is True  # close asked the job to stop
    assert "result" not in seen  # and a result that came anyway is dropped: nothing applied after closing
    assert any("Finishing" in m for m in messages)  # and said what it was waiting for
