"""The Display tab: the thinness slider (a document property) and the view settings
(colour-by, point size, hull, clipping), bound both ways to the model."""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDoubleSpinBox,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QSlider,
    QVBoxLayout,
    QWidget,
)

from ..model.document import Document
from ..model.settings import COLOUR_BY
from .bindings import bind

SLIDER_STEPS = 1000
CLIP_CHOICES = ("no clipping", "clip x", "clip y", "clip z")


class DisplayPanel(QWidget):
    """Thinness slider, cloud style, hull opacity/visibility and clipping."""

    #: the thinness slider is held (True) or released (False): the scene draws a level-of-detail subset

    def __init__(self, doc: Document, parent=None):
        super().__init__(parent)
        self.doc = doc
        self.thinness_slider = QSlider(Qt.Horizontal)
        self.thinness_slider.setRange(0, SLIDER_STEPS)
        self.thinness_spin = QDoubleSpinBox(decimals=3, singleStep=0.01)
        self.count_label = QLabel("no skeleton")
        self.point_size = QSlider(Qt.Horizontal)
        self.point_size.setRange(1, 30)
        self.colour_by = QComboBox()
        self.colour_by.addItems(COLOUR_BY)
        self.spheres = QCheckBox("Points as spheres")
        self.names_visible = QCheckBox("Joint and bone names")
        self.hull_visible = QCheckBox("Show hull")
        self.hull_owners = QCheckBox("Colour by owning bone")
        self.hull_owners.setToolTip("Each part of the hull in the colour of the bone that moves it (the body's "
                                    "ownership, repaints included); Pose → Show ownership on slices looks inside")
        self.hull_opacity = QSlider(Qt.Horizontal)
        self.hull_opacity.setRange(0, 100)
        self.clip_axis = QComboBox()
        self.clip_axis.addItems(CLIP_CHOICES)
        self.clip_position = QSlider(Qt.Horizontal)
        self.clip_position.setRange(0, 100)
        s = doc.settings
        bind(self.point_size, s, "point_size", on_error=doc.message)
        bind(self.colour_by, s, "colour_by", on_error=doc.message)
        bind(self.spheres, s, "spheres")
        bind(self.names_visible, s, "names_visible")
        bind(self.hull_visible, s, "hull_visible")
        bind(self.hull_owners, s, "hull_owners")
        bind(self.hull_opacity, s, "hull_opacity", scale=0.01)
        bind(self.clip_axis, s, "clip_axis", to_value=lambda text: CLIP_CHOICES.index(text) - 1 if text in
             CLIP_CHOICES[1:] else None, to_widget=lambda axis: CLIP_CHOICES[0 if axis is None else axis + 1])
        bind(self.clip_position, s, "clip_position", scale=0.01)

        box = QGroupBox("Skeleton cloud")
        form = QFormLayout(box)
        row = QHBoxLayout()
        row.addWidget(self.thinness_slider)
        row.addWidget(self.thinness_spin)
        form.addRow("Thinness ≥", row)
        form.addRow("", self.count_label)
        form.addRow("Point size", self.point_size)
        form.addRow("Colour by", self.colour_by)
        form.addRow(self.spheres)
        form.addRow(self.names_visible)
        hull = QGroupBox("Hull")
        hform = QFormLayout(hull)
        hform.addRow(self.hull_visible)
        hform.addRow(self.hull_owners)
        hform.addRow("Opacity", self.hull_opacity)
        hform.addRow(self.clip_axis, self.clip_position)
        layout = QVBoxLayout(self)
        layout.addWidget(box)
        layout.addWidget(hull)
        layout.addStretch(1)

        self.thinness_slider.valueChanged.connect(self._slider_moved)
        self.thinness_slider.sliderPressed.connect(lambda: setattr(doc.settings, "dragging", True))
        self.thinness_slider.sliderReleased.connect(lambda: setattr(doc.settings, "dragging", False))
        # typed values apply on Enter or focus-out, not per key: "0.7" applied while typing "0.75"
        # wrote "0.700" back into the box and the "5" was lost
        self.thinness_spin.setKeyboardTracking(False)
        self.thinness_spin.valueChanged.connect(self._spin_changed)
        doc.events.skeleton.connect(self._on_skeleton_changed)
        doc.events.thinness.connect(self._on_thinness_changed)

    def _value_of(self, step: int) -> float:
        lo, hi = self.doc.thinness_range
        return lo + (hi - lo) * step / SLIDER_STEPS

    def _step_of(self, value: float) -> int:
        lo, hi = self.doc.thinness_range
        return 0 if hi <= lo else round((value - lo) / (hi - lo) * SLIDER_STEPS)

    def _slider_moved(self, step: int) -> None:
        self.doc.thinness = self._value_of(step)

    def _spin_changed(self, value: float) -> None:
        self.doc.thinness = value

    def _on_skeleton_changed(self, **_) -> None:
        lo, hi = self.doc.thinness_range
        self.thinness_spin.blockSignals(True)
        self.thinness_spin.setRange(lo, hi)
        self.thinness_spin.blockSignals(False)
        self._on_thinness_changed(value=self.doc.thinness)

    def _on_thinness_changed(self, value=None, **_) -> None:
        for w, v in ((self.thinness_slider, self._step_of(self.doc.thinness)), (self.thinness_spin, self.doc.thinness)):
            w.blockSignals(True)
            w.setValue(v)
            w.blockSignals(False)
        total = len(self.doc.skeleton) if self.doc.skeleton is not None else 0
        shown = self.doc.visible_count
        text = f"{shown} of {total} points shown"
        if shown > 1 and self.doc.skeleton.thinness[:shown].min() == self.doc.thinness_range[1]:
            # the slider's far end shows the thinnest points (>= its value); several may tie there (#61)
            text += f", tied for the thinnest ({self.doc.thinness_range[1]:.3f})"
        self.count_label.setText(text)
