"""A test's windows are destroyed in its own teardown, never during the next test's start-up."""

from __future__ import annotations

import pytest

pytestmark = pytest.mark.gui

# Two tests of their own session: the second reads what the first one's teardown did, so they must run in
# one process, in this order (as two tests of this module, two xdist workers split them now and then, and
# the second failed: the flake check caught it).
PAIR = """
DESTROYED = []


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
"""


def test_a_test_s_window_is_destroyed_in_its_own_teardown(tmp_path):
    """The pair in a session of its own, with the studio tests' teardown (``widgets_deleted_in_their_own_test``)."""
    import subprocess
    import sys

    from paths import REPO

    (tmp_path / "test_pair.py").write_text(PAIR)
    (tmp_path / "conftest.py").write_text(f"import sys\nsys.path.insert(0, {str(REPO / 'tests')!r})\n"
                                          "from studio.conftest import widgets_deleted_in_their_own_test  # noqa\n")
    plugins = ["-p", "no:cacheprovider", "-p", "no:napari", "-p", "no:npe2", "-p", "no:napari-plugin-engine"]
    r = subprocess.run([sys.executable, "-m", "pytest", "-q", *plugins, "-o", "addopts=", "test_pair.py"],
                       cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0 and "2 passed" in r.stdout, r.stdout[-3000:] + r.stderr[-3000:]


def _surface_wrappers() -> list:
    import gc

    from PySide6.QtGui import QSurface

    return [o for o in gc.get_objects() if type(o) is QSurface]


def test_a_closed_window_leaves_no_wrapper_of_its_gl_surface(qtbot):
    """QSurface is not a QObject: PySide cannot see Qt delete it, and a wrapper kept past the widget
    handed a later QMenu at the same address back to Python as a QSurface (a CI run's error)."""
    from volanim_studio.qt.main_window import MainWindow

    w = MainWindow()
    qtbot.addWidget(w)
    w.show()
    qtbot.waitExposed(w)
    w.plotter.render()
    qtbot.wait(50)
    assert _surface_wrappers(), "the interactor wraps its surface once drawn (else this test tests nothing)"
    w.close()
    assert _surface_wrappers() == []


def test_the_window_smooths_edges_with_fxaa_whatever_vtk_s_default_window_is(qtbot, monkeypatch):
    """The studio draws in Qt's GL context, so FXAA holds even where a new VTK window would be EGL. pyvista's
    check made such a window and warned (an error here), failing whole GUI workers now and then."""
    from ..conftest import new_window

    monkeypatch.setenv("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")  # what a new window would be
    w = new_window(qtbot)
    assert w.plotter.renderer.GetUseFXAA()
    assert "Generic" in type(w.plotter.ren_win).__name__  # the Qt widget's window, not the factory's
