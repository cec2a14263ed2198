"""The Pose tab: turn the working bone with three sliders. Widgets write the pose model;
pose events write the widgets back with signals blocked."""

from __future__ import annotations

import numpy as np
from PySide6.QtWidgets import (
    QDoubleSpinBox,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from ..model.document import Document
from .fine_slider import FineSlider
from .verdict_label import VerdictLabel


class PosePanel(QWidget):
    """Three angle sliders (degrees about x, y, z at the proximal joint) for the working bone."""

    def __init__(self, doc: Document, parent=None):
        super().__init__(parent)
        self.doc = doc
        self.bone_label = QLabel()
        self.sliders, self.spins = [], []
        box = QGroupBox("Rotate about the proximal joint (children follow)")
        form = QFormLayout(box)
        for axis, colour, name in (("x", "#e63c3c", "red"), ("y", "#3cc850", "green"), ("z", "#4678ff", "blue")):
            slider = FineSlider()  # Shift while dragging: a degree per 5 pixels (#85)
            slider.setRange(-180, 180)
            spin = QDoubleSpinBox(decimals=1, minimum=-180.0, maximum=180.0, singleStep=1.0)
            row = QHBoxLayout()
            row.addWidget(slider)
            row.addWidget(spin)
            form.addRow(QLabel(f"<b style='color:{colour}'>{axis}</b> ° ({name} arrow)"), row)
            slider.valueChanged.connect(self._slider_changed)
            slider.sliderPressed.connect(self._pressed)
            slider.sliderReleased.connect(self._released)
            spin.editingFinished.connect(self._spin_changed)
            self.sliders.append(slider)
            self.spins.append(spin)
        self.reset_bone = QPushButton("Reset bone")
        self.reset_all = QPushButton("Reset pose")
        self.load_trans = QPushButton("Load .trans…")
        self.save_trans = QPushButton("Save .trans…")
        self.save_tskel = QPushButton("Save .tskel…")
        buttons = QHBoxLayout()
        buttons.addWidget(self.reset_bone)
        buttons.addWidget(self.reset_all)
        files = QHBoxLayout()
        for b in (self.load_trans, self.save_trans, self.save_tskel):
            files.addWidget(b)
        self.verdict = VerdictLabel(doc)
        self.verdict.setWordWrap(True)
        layout = QVBoxLayout(self)
        layout.addWidget(self.bone_label)
        layout.addWidget(box)
        layout.addLayout(buttons)
        layout.addLayout(files)
        layout.addWidget(self.verdict)
        layout.addStretch(1)
        self.reset_bone.clicked.connect(self._reset_bone)
        self.reset_all.clicked.connect(lambda: doc.pose.reset())
        doc.events.selection.connect(self._refresh)
        doc.events.pose.connect(self._refresh)
        doc.events.bones.connect(self._refresh)
        self._refresh()

    def _angles(self) -> list[float]:
        return [float(s.value()) for s in self.sliders]

    def _slider_changed(self, _=None) -> None:
        b = self.doc.working_bone
        if b is not None:  # a held slider's moves merge into one step; each arrow key or wheel step is one
            self.doc.pose.set_angles(b, self._angles(), merge=any(s.isSliderDown() for s in self.sliders))

    def _spin_changed(self) -> None:
        b = self.doc.working_bone
        typed = [s.value() for s in self.spins]
        # editingFinished comes on Enter and again on focus-out: an unchanged value is no edit (one typed
        # angle made three undo steps, and the first Ctrl+Z changed nothing)
        if b is not None and not np.allclose(typed, self.doc.pose.angles_of(b)):
            self.doc.pose.set_angles(b, typed, merge=False)
            self.doc.pose.settle()  # one typed value is one step, previewed in full

    def _pressed(self) -> None:
        self.doc.undo.seal()  # a drag is a step of its own, whatever came before it
        self.doc.settings.dragging = True

    def _released(self) -> None:
        self.doc.undo.seal()  # press to release: one undo step
        self.doc.settings.dragging = False  # the scene draws in full again; the full preview follows

    def _reset_bone(self) -> None:
        if self.doc.working_bone is not None:
            self.doc.pose.reset(self.doc.working_bone)
            self.doc.pose.settle()

    def _refresh(self, **_) -> None:
        b = self.doc.working_bone
        enabled = b is not None
        self.bone_label.setText("Click a bone to pose it." if not enabled else
                                f"Posing <b>{self.doc.bones.bones[b].label}</b> (root {b})")
        angles = self.doc.pose.angles_of(b) if enabled else [0.0, 0.0, 0.0]
        for slider, spin, a in zip(self.sliders, self.spins, angles):
            for w, v in ((slider, int(round(a))), (spin, float(a))):
                w.blockSignals(True)
                w.setValue(v)
                w.blockSignals(False)
            slider.setEnabled(enabled)
            spin.setEnabled(enabled)
        self.reset_bone.setEnabled(enabled)
