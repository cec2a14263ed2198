"""Fixtures for GUI tests: a real MainWindow on the demo mannequin, under Xvfb (pytest-xvfb)."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt


def front_view(window) -> None:
    """Look at the mannequin from the front (-y), z up, so tests click known places."""
    r = window.plotter.renderer
    cam = r.GetActiveCamera()
    b = r.ComputeVisiblePropBounds()
    c = [(b[0] + b[1]) / 2, (b[2] + b[3]) / 2, (b[4] + b[5]) / 2]
    cam.SetFocalPoint(*c)
    cam.SetPosition(c[0], c[1] - 900, c[2])
    cam.SetViewUp(0, 0, 1)
    r.ResetCamera()
    window.plotter.render()


def rig_and_pose(qtbot, window):
    """The mannequin's bones and attachments from assets/, the front view, then Pose mode (P) and the body's
    preview it shows."""
    from paths import ASSETS
    from volanim_studio.model.interaction import Mode

    assert window.files.open_bones(ASSETS / "mannequin.bones")
    assert window.files.open_connect(ASSETS / "mannequin.0.50.connect")
    front_view(window)
    qtbot.keyClick(window, Qt.Key_P)
    assert window.mode == Mode.POSE
    # Pose mode shows the body (#83): its preview and report are made before the test goes on
    qtbot.waitUntil(lambda: not window.jobs.running, timeout=JOB_TIMEOUT_MS)
    return window


def qt_pos(window, display_xy) -> QPoint:
    """The Qt widget position of VTK display coordinates (device pixels, origin bottom-left)."""
    w = window.plotter
    s = w.devicePixelRatioF()
    return QPoint(int(round(display_xy[0] / s)), int(round(w.height() - 1 - display_xy[1] / s)))


def click(qtbot, window, display_xy, button=Qt.LeftButton, modifier=Qt.NoModifier) -> None:
    """Click at VTK display coordinates through Qt."""
    qtbot.mouseClick(window.plotter, button, modifier, qt_pos(window, display_xy))


def clickable_point(window, near_voxel) -> int:
    """A shown skeleton point close to ``near_voxel`` that a click on its projection picks."""
    doc, scene = window.doc, window.scene
    n = doc.visible_count
    order = np.argsort(((doc.skeleton.points[:n] - np.asarray(near_voxel)) ** 2).sum(1))
    for i in order[:200]:
        xy = scene.display_of_point(int(i))
        if scene.pick(*xy).point == i:
            return int(i)
    raise AssertionError(f"no clickable point near {near_voxel}")


#: How long a test waits for a background job. Generous on purpose: tests wait on a *state*
#: (the job ended), so a passing test never sleeps this long, while a shared machine that is
#: 2x slower some hours (or busy with a benchmark) must not turn a slow job into a failure.
JOB_TIMEOUT_MS = 600_000


def open_project(qtbot, window, path) -> bool:
    """Open a project and wait until it is applied (``on_opened``), and its job's thread has ended.

    ``on_opened`` is the controller's own completion callback. (``not window.busy`` used to come
    one event too early -- the project's files were applied by a second handler -- which a busy CI
    machine saw once; ``test_a_project_reads_as_done_only_once_it_is_applied`` pins the fix.)
    """
    opened = []
    window.files.open_project(path, on_opened=opened.append)
    qtbot.waitUntil(lambda: bool(opened), timeout=JOB_TIMEOUT_MS)
    qtbot.waitUntil(lambda: not window.busy, timeout=JOB_TIMEOUT_MS)
    return opened[0]


def save_project(qtbot, window, **kw):
    """Save as Ctrl+S does (``FilesController.save_project``: written on the savers' thread) and wait until
    the document has adopted it; its result (the path, None when nothing was started)."""
    path = window.files.save_project(**kw)
    qtbot.waitUntil(lambda: not window.savers.busy, timeout=JOB_TIMEOUT_MS)
    return path


@pytest.fixture(autouse=True)
def widgets_deleted_in_their_own_test():
    """Destroy the test's closed widgets before the next test starts.

    pytest-qt closes a test's widgets with ``deleteLater``, which Qt runs at the next
    event loop: the next test's window start-up (``waitUntil`` in ``window``). Two CI
    runs crashed exactly there, with the old window's GL widget and render window being
    torn down while the new one made its first frames. Deleting them here -- after
    pytest-qt closed them, still inside this test's teardown -- keeps the two apart.
    """
    yield
    from PySide6.QtCore import QCoreApplication, QEvent

    if QCoreApplication.instance() is not None:
        QCoreApplication.sendPostedEvents(None, QEvent.Type.DeferredDelete)


@pytest.fixture(scope="session", autouse=True)
def compiled_kernels():
    """Compile every numba kernel before any GUI test waits on one.

    A fresh clone has no numba cache: compiling all variants takes ~25 s, and
    it used to happen inside whichever GUI test ran a reconstruction first.
    """
    from volanim_core.warmup import compile_kernels

    compile_kernels()


@pytest.fixture(scope="module")
def mannequin():
    """The demo mannequin and its default skeleton (computed once per module)."""
    from volanim_core import samples
    from volanim_core.skeleton.skeletonize import skeletonize

    s = samples.mannequin()
    return s, skeletonize(s.mask)


@pytest.fixture
def doc(mannequin):
    """A document holding the mannequin's volume and skeleton, no bones."""
    from volanim_studio.model import Document

    s, skel = mannequin
    d = Document()
    d.set_volume(s.volume, s.mask)
    d.set_skeleton(skel)
    return d


@pytest.fixture(autouse=True)
def recovery_dir(tmp_path, monkeypatch):
    """Autosaves go to a test folder, never to the user's cache."""
    folder = tmp_path / "recovery"
    monkeypatch.setenv("VOLANIM_RECOVERY_DIR", str(folder))
    return folder


def new_window(qtbot):
    """A shown MainWindow of 1200x800 with nothing loaded (closed by pytest-qt after the test)."""
    from volanim_studio.qt.main_window import MainWindow

    w = MainWindow()
    qtbot.addWidget(w)
    w.resize(1200, 800)
    w.show()
    qtbot.waitExposed(w)
    return w


def viewer_opened(window, qtbot, view, path):
    """``view(path)`` (``window.files.view_file`` or ``view_slices``: the file is read in the window's
    reader thread), the read waited for: the looking window it opened, or None (a refusal)."""
    from volanim_studio.qt.worker import Worker

    before = window.files.open_viewers()
    assert isinstance(view(path), Worker), "the file is read in the background"
    qtbot.waitUntil(lambda: not window.readers.busy, timeout=JOB_TIMEOUT_MS)
    new = [v for v in window.files.open_viewers() if v not in before]
    return new[-1] if new else None


@pytest.fixture
def window(qtbot):
    w = new_window(qtbot)
    w.activateWindow()  # window shortcuts need an active window; Xvfb has no window manager to do it
    qtbot.waitUntil(w.isActiveWindow, timeout=5000)
    w.files.load_demo("mannequin")
    qtbot.waitUntil(lambda: not w.busy, timeout=JOB_TIMEOUT_MS)
    qtbot.waitUntil(w.isActiveWindow, timeout=5000)
    front_view(w)
    yield w
    w.doc.undo.mark_clean()  # the test's edits are not for keeping: no "Save changes?" on close
    w.close()  # cancels and waits for any running job (JobRunner.shutdown)
    assert not w.busy, "closing the window must leave no worker thread running"
