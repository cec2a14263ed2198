"""The Pose tab (turn the working bone) and the Reconstruct tab (preview settings and
the breakage report). Widgets write the model; model events write the widgets back
with signals blocked."""

from __future__ import annotations

from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDoubleSpinBox,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QListWidget,
    QListWidgetItem,
    QPushButton,
    QSlider,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from volanim_core.reconstruct import MODES

from .model.document import Document


class PosePanel(QWidget):
    """Three angle sliders (degrees about x, y, z at the proximal joint) for the working bone."""

    drag_started = Signal()
    drag_finished = Signal()

    def __init__(self, doc: Document, parent=None):
        super().__init__(parent)
        self.doc = doc
        self.bone_label = QLabel()
        self.sliders, self.spins = [], []
        box = QGroupBox("Rotate about the proximal joint (children follow)")
        form = QFormLayout(box)
        for axis in "xyz":
            slider = QSlider(Qt.Horizontal)
            slider.setRange(-180, 180)
            spin = QDoubleSpinBox(decimals=1, minimum=-180.0, maximum=180.0, singleStep=1.0)
            row = QHBoxLayout()
            row.addWidget(slider)
            row.addWidget(spin)
            form.addRow(f"{axis} °", row)
            slider.valueChanged.connect(self._slider_changed)
            slider.sliderPressed.connect(self.drag_started.emit)
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
        layout = QVBoxLayout(self)
        layout.addWidget(self.bone_label)
        layout.addWidget(box)
        layout.addLayout(buttons)
        layout.addLayout(files)
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
        if b is not None:
            self.doc.pose.set_angles(b, self._angles())

    def _spin_changed(self) -> None:
        b = self.doc.working_bone
        if b is not None:
            self.doc.pose.set_angles(b, [s.value() for s in self.spins], merge=False)
            self.drag_finished.emit()

    def _released(self) -> None:
        self.doc.undo.seal()
        self.drag_finished.emit()

    def _reset_bone(self) -> None:
        if self.doc.working_bone is not None:
            self.doc.pose.reset(self.doc.working_bone)
            self.drag_finished.emit()

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


class ReconstructPanel(QWidget):
    """Preview settings, the compare toggle, export, and the breakage report."""

    joint_clicked = Signal(str)

    def __init__(self, doc: Document, parent=None):
        super().__init__(parent)
        self.doc = doc
        self.mode = QComboBox()
        self.mode.addItems(MODES)
        self.mode.setCurrentText("bone")
        self.kernel = QComboBox()
        self.kernel.addItems(["1", "3", "5"])
        self.padding = QSpinBox(minimum=0, maximum=50)
        self.padding.setValue(2)
        self.live = QCheckBox("Live preview while posing (half resolution)")
        self.live.setChecked(True)
        self.slices = QCheckBox("Orthogonal slices")
        self.show_rest = QCheckBox("Show the rest pose instead (compare)")
        self.metric_label = QLabel("euclid")
        self.metric_label.setToolTip("The distance metric of the skeleton's DT (set when skeletonizing); "
                                     "radii are in it")
        self.preview_button = QPushButton("Preview")
        self.export_button = QPushButton("Export volume…")
        self.report = QLabel("No preview yet.")
        self.report.setWordWrap(True)
        self.joints = QListWidget()
        settings = QGroupBox("Reconstruction")
        form = QFormLayout(settings)
        form.addRow("Mode", self.mode)
        form.addRow("Kernel (sampled)", self.kernel)
        form.addRow("Padding", self.padding)
        form.addRow("Metric (from the skeleton)", self.metric_label)
        form.addRow(self.live)
        form.addRow(self.preview_button)
        view = QGroupBox("View")
        vl = QVBoxLayout(view)
        vl.addWidget(self.show_rest)
        vl.addWidget(self.slices)
        vl.addWidget(self.export_button)
        report = QGroupBox("Breakage report")
        rl = QVBoxLayout(report)
        rl.addWidget(self.report)
        rl.addWidget(QLabel("Breakage gathers near (click to go there):"))
        rl.addWidget(self.joints)
        layout = QVBoxLayout(self)
        for w in (settings, view, report):
            layout.addWidget(w)
        self.joints.itemClicked.connect(lambda item: self.joint_clicked.emit(item.data(Qt.UserRole)))
        doc.events.skeleton.connect(
            lambda **_: self.metric_label.setText(doc.skeleton.metric if doc.skeleton is not None else "euclid"))
        doc.events.preview.connect(self._on_preview_changed)

    def settings(self) -> dict:
        return {"mode": self.mode.currentText(), "kernel": int(self.kernel.currentText()),
                "padding": self.padding.value()}

    def _on_preview_changed(self, **_) -> None:
        p = self.doc.preview
        if p is None or p.report is None:
            return
        r = p.report
        verdict = "healthy: one piece" if r.healthy else "BROKEN into pieces"
        self.report.setText(f"<b>{verdict}</b><br>" + "<br>".join(r.lines()))
        self.joints.clear()
        for size, joint, _ in r.pieces:
            item = QListWidgetItem(f"detached piece: {size} voxels near {joint}")
            item.setData(Qt.UserRole, joint)
            self.joints.addItem(item)
        total = max(sum(j.gap for j in r.joints), 1e-9)
        for j in r.joints:
            item = QListWidgetItem(f"{j.name}: {j.lost} cracks ({100 * j.gap / total:.0f} % of the opening)")
            item.setData(Qt.UserRole, j.name)
            self.joints.addItem(item)
