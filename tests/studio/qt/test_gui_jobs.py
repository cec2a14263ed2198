"""Long jobs: cancel leaves the window responsive, closing waits for a running job."""

from __future__ import annotations

import threading

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


@pytest.mark.long("a 46 M-voxel volume opened and viewed: the reads and the surface stay off the GUI thread")
def test_a_46m_voxel_volume_opens_and_is_viewed_while_the_event_loop_turns(qtbot, window, tmp_path, monkeypatch):
    """#61 item 9: *Open volume* read the file, and the quick look made a large volume's surface, on the GUI
    thread (the window froze). Each heavy call is watched where it runs: never on the GUI thread, and before
    it returns the GUI's timer has ticked again -- the event loop turned while it worked (a call on the GUI
    thread would wait for a tick forever; it is refused instead)."""
    import threading
    import time

    import numpy as np
    from PySide6.QtCore import QTimer

    from volanim_core.render import surfaces
    from volanim_studio import tasks

    from ..conftest import viewer_opened

    big = np.zeros((400, 400, 288), np.uint8)  # 46,080,000 voxels
    big[120:280, 150:250, 40:250] = 180  # a slab of a body, and a limb off it
    big[180:220, 180:220, 250:280] = 180
    io.write_volume(tmp_path / "big.VOL", big)
    ticks = []
    timer = QTimer()
    timer.timeout.connect(lambda: ticks.append(time.perf_counter()))
    timer.start(20)
    calls = []

    def watched(name, real):
        def call(*args, **kwargs):
            on_gui = threading.current_thread() is threading.main_thread()
            calls.append((name, on_gui))
            if on_gui:
                raise AssertionError(f"{name} ran on the GUI thread")
            before = len(ticks)
            out = real(*args, **kwargs)
            deadline = time.monotonic() + 120
            while len(ticks) < before + 2 and time.monotonic() < deadline:  # the loop ticks while we wait
                time.sleep(0.005)
            assert len(ticks) >= before + 2, f"the GUI's timer stopped while {name} ran"
            return out
        return call

    for name in ("load_volume_file", "prepare_volume"):
        monkeypatch.setattr(tasks, name, watched(name, getattr(tasks, name)))
    monkeypatch.setattr(surfaces, "label_surface", watched("label_surface", surfaces.label_surface))

    window.files.open_volume(tmp_path / "big.VOL", params={"lo": 1, "hi": None, "fill": False})
    assert window.busy and calls == []  # the open returned at once: nothing read yet on this thread
    qtbot.waitUntil(lambda: not window.busy, timeout=4 * JOB_TIMEOUT_MS)
    assert window.doc.shape == big.shape and len(window.doc.skeleton) > 0, window.last_error
    viewer = viewer_opened(window, qtbot, window.files.view_file, tmp_path / "big.VOL")
    timer.stop()
    assert viewer is not None and "400x400x288 voxels" in viewer.what, window.last_error
    assert [n for n, _ in calls] == ["load_volume_file", "prepare_volume", "label_surface"]
    assert not any(on_gui for _, on_gui in calls)
    gaps = np.diff(ticks)
    print(f"timer: {len(ticks)} ticks, longest gap {gaps.max():.3f} s, 95th percentile {np.percentile(gaps, 95):.3f} s")
    viewer.close()


def test_a_result_that_cannot_be_applied_is_a_failed_job_said_and_heard(qtbot, window):
    """Applying a job's result raised and the job was neither said to fail nor heard to: whoever waited on
    it (open_project's on_opened) waited forever. Now it is a failed job: shown, and ``failed`` emitted."""
    heard = []

    def apply(result):
        raise ValueError(f"{result} voxels do not fit the grid")

    worker = window.jobs.run("Applying", lambda progress, cancel: 12, apply)
    worker.failed.connect(heard.append)
    qtbot.waitUntil(lambda: not window.busy and bool(heard), timeout=JOB_TIMEOUT_MS)
    assert heard == ["12 voxels do not fit the grid"]
    assert "12 voxels do not fit the grid" in window.last_error
    window.files.load_demo("mannequin")  # the runner takes the next job
    qtbot.waitUntil(lambda: not window.busy, timeout=JOB_TIMEOUT_MS)
    assert window.doc.demo_name == "mannequin"


def test_a_background_job_has_no_dialog_and_the_next_job_cancels_it(qtbot, window):
    """#65: the breakage report ran behind a modal progress dialog for seconds (mannequin-large: 5 s) after the
    picture was shown, so the user could not pose on. A background job shows nothing modal, does not count as
    busy for the controllers, and the next job asked for cancels it, waits for its thread and starts: its
    result is never applied and its cancellation is not announced."""
    released, applied = threading.Event(), []

    def wait_for_cancel(progress, cancel):
        while not cancel():  # a chunked task: it looks at cancel between chunks
            released.wait(0.01)
        return "stale"

    worker = window.jobs.run("Checking", wait_for_cancel, applied.append, background=True)
    assert worker.background and window.jobs.dialog is None
    assert not window.jobs.busy and window.jobs.running and window.busy
    messages = []
    window.doc.events.message.connect(lambda text: messages.append(text))
    window.jobs.run("Next", lambda progress, cancel: "fresh", applied.append)  # starts once the first has ended
    assert worker.cancelled and worker.isFinished()
    assert window.jobs.busy and window.jobs.dialog is not None  # a job the user waits for: its dialog
    qtbot.waitUntil(lambda: not window.busy, timeout=JOB_TIMEOUT_MS)
    assert applied == ["fresh"]
    assert not any("Checking" in m for m in messages)


def test_a_preview_asked_for_while_a_background_job_is_being_ended_waits_its_turn(qtbot, window):
    """#83: ending a background job handles events while its thread winds down. A "preview when idle" timer
    that fired then saw a free runner, started a preview inside the first job's start, and that job then
    raised "another job is running" (seen once in make test: F5 just after entering Pose mode)."""
    from PySide6.QtCore import QTimer

    from paths import ASSETS

    assert window.files.open_bones(ASSETS / "mannequin.bones")
    assert window.files.open_connect(ASSETS / "mannequin.0.50.connect")
    from volanim_studio.model.interaction import Mode

    window.set_mode(Mode.POSE)
    qtbot.waitUntil(lambda: not window.jobs.running, timeout=JOB_TIMEOUT_MS)
    released = threading.Event()

    def wait_for_cancel(progress, cancel):
        while not cancel():
            released.wait(0.01)
        return None

    window.jobs.run("Checking", wait_for_cancel, lambda _: None, background=True)
    QTimer.singleShot(0, window.previews._preview_when_idle)  # fires while the next run() ends that job
    applied = []
    worker = window.jobs.run("Next", lambda progress, cancel: "fresh", applied.append)
    assert worker is not None  # no "another job is running"
    qtbot.waitUntil(lambda: not window.jobs.running and applied == ["fresh"], timeout=JOB_TIMEOUT_MS)
    qtbot.waitUntil(lambda: window.doc.preview_is_current and not window.jobs.running, timeout=JOB_TIMEOUT_MS)


def test_the_threshold_dialog_s_range_and_histogram_are_made_by_the_reader(qtbot, window, tmp_path, monkeypatch):
    """#83 item 13: the threshold dialog took the value range and histogram of a scan on the GUI thread. They
    are made in the worker that read it; the dialog only draws them."""
    import numpy as np

    from volanim_studio import tasks
    from volanim_studio.qt import threshold_dialog
    from volanim_studio.qt.threshold_dialog import ThresholdDialog

    real = tasks.value_histogram
    where = []

    def watched(volume):
        where.append(threading.current_thread() is threading.main_thread())
        return real(volume)

    monkeypatch.setattr(tasks, "value_histogram", watched)
    monkeypatch.setattr(threshold_dialog, "value_histogram", watched)
    shown = []

    def exec_(dialog):
        shown.append((dialog.lo.minimum(), dialog.hi.maximum()))
        return ThresholdDialog.Rejected

    monkeypatch.setattr(ThresholdDialog, "exec", exec_)
    volume = np.zeros((30, 20, 10), np.uint8)
    volume[5:25, 5:15, 2:8] = 180
    volume[0, 0, 0] = 7
    io.write_volume(tmp_path / "box.VOL", volume)
    window.files.open_volume(tmp_path / "box.VOL")
    qtbot.waitUntil(lambda: bool(shown) and not window.busy, timeout=JOB_TIMEOUT_MS)
    assert where == [False]  # once, in the worker
    assert shown == [(0.0, 180.0)]  # the scan's own range, from the worker's figures
