"""File → View slices… (#43, View.tcl): nibabel's own scan, one slice at a time, in a Qt window.

The oracle is nibabel: the pixels Qt paints and the value the status bar reports under the mouse
are nibabel's voxels, sliced and windowed here with NumPy.
"""

from __future__ import annotations

from pathlib import Path

import nibabel as nib
import numpy as np
from PySide6.QtCore import QPoint, Qt
from PySide6.QtTest import QTest

ANATOMICAL = Path(nib.__file__).parent / "tests" / "data" / "anatomical.nii"


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
    viewer = window.files.view_slices(ANATOMICAL)
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
    assert window.files.view_slices(tmp_path / "bad.nii") is None
    assert "bad.nii" in window.last_error
