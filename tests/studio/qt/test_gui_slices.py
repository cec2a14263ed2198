"""File → View slices… (#43, View.tcl): nibabel's own scan, one slice at a time, in a Qt window.

The oracle is nibabel: the pixels Qt paints and the value the status bar reports under the mouse
are nibabel's voxels, sliced and windowed here with NumPy. The file is read in the window's
reader thread: the studio stays usable while a large scan is read, its document job goes on,
and closing the studio mid-read waits for the read and opens nothing.
"""

from __future__ import annotations

from pathlib import Path

import nibabel as nib
import numpy as np
from PySide6.QtCore import QPoint, Qt
from PySide6.QtTest import QTest

from volanim_core import io
from volanim_studio.qt.worker import Worker

from ..conftest import JOB_TIMEOUT_MS, new_window, viewer_opened

ANATOMICAL = Path(nib.__file__).parent / "tests" / "data" / "anatomical.nii"


def opened(window, qtbot, path):
    return viewer_opened(window, qtbot, window.files.view_slices, path)


def big_scan(folder: Path) -> tuple[Path, np.ndarray]:
    """A 96 MB .VOL (400 x 400 x 600, a gradient along z): seconds to read and window on a busy machine."""
    data = np.broadcast_to((np.arange(600) % 251).astype(np.uint8), (400, 400, 600))
    path = folder / "big.VOL"
    io.write_volume(path, np.ascontiguousarray(data))
    return path, data


def grey(data: np.ndarray, plane: np.ndarray) -> np.ndarray:
    """NumPy's own windowing of a plane ``[u, v]``: the scan's min..max onto 0..255, shown u right, v up."""
    lo, hi = data.min(), data.max()
    return np.round(np.clip((plane - lo) / (hi - lo), 0, 1) * 255).T[::-1]


def painted(canvas) -> np.ndarray:
    """What Qt drew on the canvas, one pixel from the middle of each of the picture's blocks."""
    image = canvas.grab().toImage().convertToFormat(canvas.grab().toImage().Format.Format_RGB888)
    ratio = image.width() / canvas.width()
    t = canvas.target()
    h, w = canvas.picture.shape[:2]
    rows = ((t.top() + (np.arange(h) + 0.5) * t.height() / h) * ratio).astype(int)
    cols = ((t.left() + (np.arange(w) + 0.5) * t.width() / w) * ratio).astype(int)
    bits = np.frombuffer(image.constBits(), np.uint8).reshape(image.height(), image.bytesPerLine())
    return bits[:, : image.width() * 3].reshape(image.height(), image.width(), 3)[np.ix_(rows, cols)][..., 0]


def test_view_slices_shows_nibabels_voxels_and_reports_the_one_under_the_mouse(window, qtbot, tmp_path):
    data = np.asanyarray(nib.load(ANATOMICAL).dataobj).astype(np.float64)
    viewer = opened(window, qtbot, ANATOMICAL)
    assert viewer is not None and viewer.isVisible() and "anatomical.nii" in window.statusBar().currentMessage()
    qtbot.waitExposed(viewer)
    nz = data.shape[2]
    assert viewer.slider.value() == nz // 2
    assert np.abs(painted(viewer.canvas) - grey(data, data[:, :, nz // 2])).max() <= 1
    viewer.slider.setValue(3)
    assert np.abs(painted(viewer.canvas) - grey(data, data[:, :, 3])).max() <= 1
    QTest.keyClick(viewer, Qt.Key_PageUp)
    assert viewer.slider.value() == 4
    viewer.axis_box.setCurrentIndex(1)  # y slices: x right, z up
    ny = data.shape[1]
    assert viewer.slider.maximum() == ny - 1 and viewer.slider.value() == ny // 2
    assert np.abs(painted(viewer.canvas) - grey(data, data[:, ny // 2, :])).max() <= 1
    # the mouse over voxel (x=10, z=5): the status bar says nibabel's value there
    t, (h, w) = viewer.canvas.target(), viewer.canvas.picture.shape[:2]
    at = QPoint(int(t.left() + (10 + 0.5) * t.width() / w), int(t.top() + (h - 1 - 5 + 0.5) * t.height() / h))
    QTest.mouseMove(viewer.canvas, at)
    qtbot.waitUntil(lambda: "voxel 10" in viewer.statusBar().currentMessage(), timeout=3000)
    assert viewer.statusBar().currentMessage() == f"voxel 10 {ny // 2} 5 = {data[10, ny // 2, 5]:g}"
    viewer.close()
    (tmp_path / "bad.nii").write_bytes(b"not a scan")
    assert opened(window, qtbot, tmp_path / "bad.nii") is None  # nothing opens; the error names the file
    assert "bad.nii" in window.last_error


def test_a_large_scan_is_read_off_the_gui_thread_while_the_documents_job_goes_on(window, qtbot, tmp_path):
    path, data = big_scan(tmp_path)
    job = window.files.load_demo("mannequin")  # the document's own job, running
    reading = window.files.view_slices(path)
    # view_slices returned at once: the read runs in the reader thread, the document's job was not waited
    # for (it reports back through this thread's event loop, which has not run since), nothing is open yet
    assert isinstance(reading, Worker) and window.readers.busy and window.jobs.busy and job is window.jobs.worker
    assert window.files.open_viewers() == []
    assert window.files.view_slices(ANATOMICAL) is None  # one read for viewing at a time: said, not queued
    assert "Still reading" in window.statusBar().currentMessage()
    qtbot.waitUntil(lambda: not window.busy, timeout=JOB_TIMEOUT_MS)
    viewer = window.files.open_viewers()[-1]
    assert viewer.path == path and viewer.slider.maximum() == data.shape[2] - 1
    assert viewer.statusBar().currentMessage().startswith("big.VOL: 400x400x600 voxels, grey 0..250")
    viewer.slider.setValue(7)
    assert np.abs(painted(viewer.canvas) - grey(data, data[:, :, 7])).max() <= 1
    assert len(window.doc.skeleton) > 0  # and the demo the document was loading is loaded
    viewer.close()


def test_closing_the_studio_while_a_scan_is_read_waits_for_it_and_opens_nothing(qtbot, tmp_path):
    path, _ = big_scan(tmp_path)
    w = new_window(qtbot)
    assert isinstance(w.files.view_slices(path), Worker)
    w.close()  # the read cannot stop half-way: the window waits for it (never destroying a running thread)
    assert not w.busy and not w.readers.busy
    qtbot.wait(50)
    assert w.files.open_viewers() == []  # cancelled: the slice window is not opened after the studio closed
