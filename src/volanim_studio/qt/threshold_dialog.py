"""Threshold dialog: a histogram of the volume and the object's value range."""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QRectF, Qt
from PySide6.QtGui import QColor, QPainter
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QDoubleSpinBox,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QVBoxLayout,
    QWidget,
)

from volanim_core.skeleton.skeletonize import DEFAULT_MIN_THINNESS

from ..tasks import value_histogram


class HistogramWidget(QWidget):
    """Log-count bars of 256 bins; the selected range is highlighted."""

    def __init__(self, counts: np.ndarray, edges: np.ndarray, parent=None):
        super().__init__(parent)
        self.counts = np.log1p(counts.astype(float))
        self.edges = edges
        self.lo, self.hi = float(edges[0]), float(edges[-1])
        self.setMinimumSize(380, 140)

    def set_range(self, lo: float, hi: float) -> None:
        self.lo, self.hi = lo, hi
        self.update()

    def paintEvent(self, event):  # noqa: N802 (Qt name)
        p = QPainter(self)
        p.fillRect(self.rect(), QColor("#202124"))
        w, h = self.width(), self.height()
        n = len(self.counts)
        top = self.counts.max() or 1.0
        for i, c in enumerate(self.counts):
            inside = self.lo <= self.edges[i + 1] and self.edges[i] <= self.hi
            p.fillRect(QRectF(i * w / n, h - h * c / top, max(w / n, 1.0), h * c / top),
                       QColor("#f0a030" if inside else "#707070"))
        p.end()


class ThresholdDialog(QDialog):
    """Choose the object's value range, cavity filling and the skeleton's settings."""

    def __init__(self, volume: np.ndarray, name: str, parent=None, spacing=(1.0, 1.0, 1.0), segments=None,
                 histogram=None):
        super().__init__(parent)
        self.setWindowTitle(f"Segment {name}")
        # made by the reader's worker (#83: the range and histogram of a large scan took the GUI thread)
        vmin, vmax, counts, edges = histogram if histogram is not None else value_histogram(volume)
        self.histogram = HistogramWidget(counts, edges)
        self.lo = QDoubleSpinBox(decimals=2, minimum=vmin, maximum=vmax)
        self.hi = QDoubleSpinBox(decimals=2, minimum=vmin, maximum=vmax)
        self.lo.setValue(min(vmin + 1, vmax) if volume.dtype.kind in "ui" else (vmin + vmax) / 2)
        self.hi.setValue(vmax)
        self.fill = QCheckBox("Fill enclosed cavities")
        self.fill.setChecked(True)
        self.metric_box = QComboBox()
        self.metric_box.addItems(["euclid", "345"])
        self.min_thinness = QDoubleSpinBox(decimals=2, minimum=-10.0, maximum=10.0, singleStep=0.05)
        self.min_thinness.setValue(DEFAULT_MIN_THINNESS)
        # the file's voxel size (a raw .vol has none: 1 x 1 x 1); the frog's slices are 1.5 mm apart
        self.spacing = [QDoubleSpinBox(decimals=3, minimum=0.001, maximum=1e4, singleStep=0.1) for _ in range(3)]
        spacing_row = QHBoxLayout()
        for box, value, axis in zip(self.spacing, spacing, "xyz"):
            box.setValue(float(value))
            box.setToolTip(f"Size of a voxel along {axis} (mm or any unit; only ratios matter). Read from "
                           "the file when it says; a raw .vol does not, so check it against the scanner's notes.")
            spacing_row.addWidget(box)
        self.lo.setToolTip("Voxels with values from here ...")
        self.hi.setToolTip("... to here are the object (the orange band of the histogram).")
        self.fill.setToolTip("Holes inside the object (lungs, a cavity) become object: the skeleton goes "
                             "through the middle of the body instead of around the hole.")
        self.metric_box.setToolTip("The distance transform the skeleton's sphere radii come from: exact "
                                   "Euclidean, or the thesis's 3-4-5 chamfer.")
        self.min_thinness.setToolTip("Skeleton points thinner than this are not kept. Lower keeps more points "
                                     "(finer reconstructions, slower studio); the Display tab's slider shows "
                                     "a prefix of what is kept.")
        form = QFormLayout()
        # a 3D Slicer segmentation names its labels: pick one by name instead of by value
        self.segments = dict(segments or {})
        self.segment_box = QComboBox()
        self.segment_box.addItem("(a value range)", None)
        for value, label in sorted(self.segments.items()):
            self.segment_box.addItem(f"{label} ({value})", value)
        self.segment_box.currentIndexChanged.connect(self._segment_chosen)
        if self.segments:
            form.addRow("Segment", self.segment_box)
        form.addRow("Object from", self.lo)
        form.addRow("to", self.hi)
        form.addRow(self.fill)
        form.addRow("Distance metric", self.metric_box)
        form.addRow("Keep thinness ≥", self.min_thinness)
        form.addRow("Voxel spacing x, y, z", spacing_row)
        buttons = QDialogButtonBox(QDialogButtonBox.Ok | QDialogButtonBox.Cancel)
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        layout = QVBoxLayout(self)
        layout.addWidget(QLabel(f"{volume.shape[0]} × {volume.shape[1]} × {volume.shape[2]} voxels, "
                                f"{volume.dtype}, values {vmin:g} … {vmax:g}"))
        layout.addWidget(self.histogram)
        layout.addLayout(form)
        layout.addWidget(buttons)
        self.lo.valueChanged.connect(self._sync)
        self.hi.valueChanged.connect(self._sync)
        self._sync()
        self.setAttribute(Qt.WA_DeleteOnClose, False)

    def _segment_chosen(self, _index: int) -> None:
        value = self.segment_box.currentData()
        if value is not None:
            self.lo.setValue(value)
            self.hi.setValue(value)
            self.fill.setChecked(False)  # a segment is what it is: its holes are other segments

    def _sync(self) -> None:
        self.histogram.set_range(self.lo.value(), self.hi.value())

    def parameters(self) -> dict:
        return {"lo": self.lo.value(), "hi": self.hi.value(), "fill": self.fill.isChecked(),
                "metric": self.metric_box.currentText(), "min_thinness": self.min_thinness.value(),
                "spacing": [b.value() for b in self.spacing]}
