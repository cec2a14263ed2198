"""*File → View slices…*: any volume one slice at a time, the thesis's View.tcl (as ``volanim view --slices``).

    file --read_for_slices (in the window's reader thread: io.read_scan, grey window, description)-->
      SlicesSource --slice_picture(axis, k)--> QImage, scaled to fit (tall voxels tall)
    axis box, slider, Page Up / Page Down --> k;   mouse over the picture --> status bar: x y z = value

It only looks: the document is untouched. The file is read off the GUI thread
(``FilesController.view_slices``): a Visible-Human-sized scan takes seconds to
read and to window, and meanwhile the studio keeps drawing, offers Cancel and
lets the document's own job go on.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from PySide6.QtCore import QRectF, Qt, Signal
from PySide6.QtGui import QImage, QPainter
from PySide6.QtWidgets import QComboBox, QHBoxLayout, QLabel, QMainWindow, QSlider, QVBoxLayout, QWidget

from volanim_core.render.bone_colours import label_table
from volanim_core.render.slices import AXES, default_window, describe, pixel_aspect, slice_picture, tinted, voxel_at


@dataclass(frozen=True)
class SlicesSource:
    """What a slice window shows: the voxels, their spacing, the grey window (None: colour) and a description."""

    volume: np.ndarray
    spacing: tuple
    grey: tuple | None
    what: str
    owners: np.ndarray | None = None  # labels [x, y, z] (0: none, b + 1: bone b) tinted over the slices
    owner_names: tuple = ()  # bone b's name, to say whose voxel the mouse is over


def read_for_slices(path) -> SlicesSource:
    """Read and prepare a volume for :class:`SliceWindow` (the slow part: a worker runs it). A bad file is
    a FormatError naming it."""
    from volanim_core.io import read_scan

    scan = read_scan(path, colour=True)
    volume = scan.data
    grey = default_window(volume) if volume.ndim == 3 else None
    return SlicesSource(volume, tuple(scan.geometry.spacing), grey, describe(volume, grey))


class SliceCanvas(QWidget):
    """Paints one picture as large as fits, each pixel ``aspect`` times as tall as it is wide."""

    hovered = Signal(int, int)  # the picture's column and row under the mouse

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setMouseTracking(True)
        self.setMinimumSize(200, 200)
        self.picture = np.zeros((1, 1, 3), np.uint8)
        self.aspect = 1.0
        self._image = None

    def set_picture(self, picture: np.ndarray, aspect: float) -> None:
        self.picture, self.aspect = np.ascontiguousarray(picture), float(aspect)
        h, w = picture.shape[:2]
        self._image = QImage(self.picture.data, w, h, 3 * w, QImage.Format_RGB888)  # shares the array, kept above
        self.update()

    def target(self) -> QRectF:
        """Where the picture is drawn: centred, as large as fits."""
        h, w = self.picture.shape[:2]
        scale = min(self.width() / w, self.height() / (h * self.aspect))
        tw, th = w * scale, h * self.aspect * scale
        return QRectF((self.width() - tw) / 2, (self.height() - th) / 2, tw, th)

    def paintEvent(self, event) -> None:
        painter = QPainter(self)
        painter.fillRect(self.rect(), Qt.black)
        if self._image is not None:
            painter.drawImage(self.target(), self._image)  # nearest: a voxel stays a sharp block
        painter.end()

    def mouseMoveEvent(self, event) -> None:
        t, (h, w) = self.target(), self.picture.shape[:2]
        p = event.position()
        col, row = int((p.x() - t.left()) / t.width() * w), int((p.y() - t.top()) / t.height() * h)
        if 0 <= col < w and 0 <= row < h:
            self.hovered.emit(col, row)


class SliceWindow(QMainWindow):
    def __init__(self, path, source: SlicesSource, parent=None):
        super().__init__(parent)
        self.path, self.volume, self.spacing, self.grey = Path(path), source.volume, source.spacing, source.grey
        self.owners, self.owner_names = source.owners, source.owner_names
        self.setWindowTitle(f"{'Ownership' if self.owners is not None else 'Slices'} — {self.path.name}")
        self.resize(700, 760)
        self.canvas = SliceCanvas()
        self.axis_box = QComboBox()
        self.axis_box.addItems([f"{a} slices" for a in AXES])
        self.slider = QSlider(Qt.Horizontal)
        self.label = QLabel()
        row = QHBoxLayout()
        for w in (self.axis_box, self.slider, self.label):
            row.addWidget(w)
        row.setStretch(1, 1)
        body = QWidget()
        layout = QVBoxLayout(body)
        layout.addWidget(self.canvas, 1)
        layout.addLayout(row)
        self.setCentralWidget(body)
        self.what = source.what
        self.axis_box.currentIndexChanged.connect(self.set_axis)
        self.slider.valueChanged.connect(self.show_slice)
        self.canvas.hovered.connect(self.report)
        self.axis_box.setCurrentIndex(2)  # z: slices as the scanner took them

    @property
    def axis(self) -> int:
        return self.axis_box.currentIndex()

    def set_axis(self, axis: int) -> None:
        n = self.volume.shape[axis]
        self.slider.blockSignals(True)
        self.slider.setRange(0, n - 1)
        self.slider.setPageStep(max(1, n // 10))
        self.slider.setValue(n // 2)
        self.slider.blockSignals(False)
        self.show_slice(n // 2)

    def show_slice(self, index: int) -> None:
        picture = slice_picture(self.volume, self.axis, index, self.grey)
        if self.owners is not None:
            picture = tinted(picture, self.owners, self.axis, index, label_table(len(self.owner_names)))
        self.canvas.set_picture(picture, pixel_aspect(self.spacing, self.axis))
        self.label.setText(f"{AXES[self.axis]} = {index} of 0..{self.volume.shape[self.axis] - 1}")
        self.statusBar().showMessage(f"{self.path.name}: {self.what}. Slider or Page Up / Page Down to move.")

    def report(self, col: int, row: int) -> None:
        x, y, z = voxel_at(self.volume.shape, self.axis, self.slider.value(), col, row)
        value = self.volume[x, y, z]
        shown = " ".join(str(int(v)) for v in value) if np.ndim(value) else f"{value:g}"
        owner = int(self.owners[x, y, z]) if self.owners is not None else 0
        whose = f", moved by {self.owner_names[owner - 1]}" if 0 < owner <= len(self.owner_names) else ""
        self.statusBar().showMessage(f"voxel {x} {y} {z} = {shown}{whose}")

    def keyPressEvent(self, event) -> None:
        step = {Qt.Key_PageUp: 1, Qt.Key_PageDown: -1, Qt.Key_Up: 1, Qt.Key_Down: -1}.get(event.key())
        if step is None:
            return super().keyPressEvent(event)
        self.slider.setValue(self.slider.value() + step)
