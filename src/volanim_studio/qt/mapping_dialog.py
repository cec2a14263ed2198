"""Which BVH joint drives which bone: the suggestions, editable, before a clip is retargeted.

    clip + bones -> match() -> one row per bone: joint combo + what placed it (name, shape, both)
    rows + axes -> Retarget.build -> detected axes, units, scale, plausibility checks (a line each)
                                  -> the figure posed at the chosen frame (front and side views)

Every change to a row, an axis or the frame recomputes the preview, so the
user sees the figure upright (or on its back) before accepting.
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QPointF, Qt
from PySide6.QtGui import QColor, QPainter, QPen
from PySide6.QtWidgets import (
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QScrollArea,
    QSlider,
    QVBoxLayout,
    QWidget,
)

from volanim_core.io.bvh_files import Motion
from volanim_core.motion.plausible import check_clip
from volanim_core.motion.retarget import Retarget, match
from volanim_core.rig.bones import BoneSkeleton

UNMAPPED = "(follows its parent)"
AXES = ["auto", "y", "z", "x", "-y", "-z", "-x"]


class FigureView(QWidget):
    """Our joints posed at one frame: front view (x, z) on the left, side view (-y, z) on the right."""

    def __init__(self, bones: BoneSkeleton, parent=None):
        super().__init__(parent)
        self.bones = bones
        self.joints: dict[str, np.ndarray] = {}
        self.setMinimumSize(320, 200)

    def show_pose(self, mats: np.ndarray | None) -> None:
        self.joints = {}
        if mats is not None:
            for b, bone in enumerate(self.bones.bones):
                for j in (bone.proximal, bone.distal):
                    self.joints[j] = self.bones.joints[j] @ mats[b, :3, :3] + mats[b, 3, :3]
        self.update()

    def paintEvent(self, event) -> None:  # noqa: N802 - Qt's name
        p = QPainter(self)
        p.fillRect(self.rect(), QColor(30, 30, 34))
        if not self.joints:
            return
        pts = np.array(list(self.joints.values()))
        centre = pts.mean(axis=0)
        rest = np.array(list(self.bones.joints.values()))
        size = max(np.ptp(rest, axis=0).max(), 1e-9) * 1.3  # the rest figure's size: a fixed scale per skeleton
        half = self.width() / 2
        scale = min(half, self.height()) / size
        p.setPen(QPen(QColor(230, 200, 120), 2))
        for view, (h, sign) in enumerate(((0, 1.0), (1, -1.0))):  # front: x across; side: -y across
            left = half * view + half / 2
            for bone in self.bones.bones:
                a, b = self.joints[bone.proximal], self.joints[bone.distal]
                p.drawLine(*(QPointF(left + sign * (v[h] - centre[h]) * scale,
                                     self.height() / 2 - (v[2] - centre[2]) * scale) for v in (a, b)))
        p.setPen(QColor(160, 160, 160))
        p.drawText(6, 14, "front")
        p.drawText(int(half) + 6, 14, "side")


class MappingDialog(QDialog):
    """One row per bone: a BVH joint (suggested by names and shape) or none; the clip's axes; a preview."""

    def __init__(self, bones: BoneSkeleton, motion: Motion, clip_name: str, parent=None):
        super().__init__(parent)
        self.setWindowTitle(f"Map {clip_name} onto the bones")
        self.bones, self.motion = bones, motion
        found = match(bones, motion)
        self.combos: dict[str, QComboBox] = {}
        self.how: dict[str, QLabel] = {}
        self.chosen = False  # a mapping the user changed is their word: the clip's kind is not asked (#86)
        form = QFormLayout()
        for b in bones.bones:
            combo = QComboBox()
            combo.addItems([UNMAPPED, *motion.names])
            combo.setCurrentText(found.mapping.get(b.label, UNMAPPED))
            how = QLabel(found.how.get(b.label, "no joint found"))
            how.setStyleSheet("color: gray")
            row = QHBoxLayout()
            row.addWidget(combo, 1)
            row.addWidget(how)
            form.addRow(b.label, row)
            self.combos[b.label], self.how[b.label] = combo, how
            combo.currentTextChanged.connect(lambda text, label=b.label: self._edited(label))
        inner = QWidget()
        inner.setLayout(form)
        scroll = QScrollArea()
        scroll.setWidget(inner)
        scroll.setWidgetResizable(True)
        unmapped = [b.label for b in bones.bones if b.label not in found.mapping]
        note = QLabel(f"{motion.frames} frames at {motion.fps:.4g} fps, {len(motion.names)} joints; naming scheme: "
                      f"{found.scheme}. {len(found.mapping)} of {len(bones)} bones placed"
                      + (f"; unmapped (they follow their parent): {', '.join(unmapped)}." if unmapped else "."))
        note.setWordWrap(True)
        self.up, self.forward = QComboBox(), QComboBox()
        self.up.addItems(AXES)
        self.forward.addItems(AXES)
        axes = QHBoxLayout()
        for text, w in (("Clip's up axis", self.up), ("facing", self.forward)):
            axes.addWidget(QLabel(text))
            axes.addWidget(w)
            w.currentTextChanged.connect(self.refresh)
        axes.addStretch(1)
        self.frame = QSlider(Qt.Horizontal)
        self.frame.setRange(0, max(motion.frames - 1, 0))
        self.frame.valueChanged.connect(self.show_frame)  # a frame re-poses; only an edit re-retargets
        self.frame_label = QLabel()
        self.detected = QLabel()
        self.detected.setWordWrap(True)
        self.figure = FigureView(bones)
        frame_row = QHBoxLayout()
        frame_row.addWidget(QLabel("Preview frame"))
        frame_row.addWidget(self.frame, 1)
        frame_row.addWidget(self.frame_label)
        buttons = QDialogButtonBox(QDialogButtonBox.Ok | QDialogButtonBox.Cancel)
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        layout = QVBoxLayout(self)
        layout.addWidget(note)
        layout.addWidget(scroll, 1)
        layout.addLayout(axes)
        layout.addWidget(self.detected)
        layout.addLayout(frame_row)
        layout.addWidget(self.figure, 1)
        layout.addWidget(buttons)
        self.retarget: Retarget | None = None
        self.resize(520, 860)
        self.refresh()

    def _edited(self, label: str) -> None:
        self.how[label].setText("your choice")
        self.chosen = True
        self.refresh()

    def mapping(self) -> dict[str, str]:
        return {label: c.currentText() for label, c in self.combos.items() if c.currentText() != UNMAPPED}

    def axes(self) -> tuple[str, str]:
        return self.up.currentText(), self.forward.currentText()

    def show_frame(self) -> None:
        frame = self.frame.value()
        self.frame_label.setText(f"{frame} / {self.motion.frames - 1}")
        self.figure.show_pose(None if self.retarget is None else self.retarget.matrices([frame])[0])

    def refresh(self) -> None:
        """Retarget with what the dialog shows now: the detected axes, units and checks, and the figure."""
        try:
            r = Retarget.build(self.bones, self.motion, self.mapping() if self.chosen else None, *self.axes())
        except ValueError as exc:  # e.g. up and facing on one axis: said, not raised
            self.retarget = None
            self.detected.setText(f"Cannot retarget this way: {exc}")
            self.show_frame()
            return
        self.retarget = r
        checks, n = check_clip(r)
        lines = [f"Axes: up {r.up}, facing {r.forward} ({r.report['axes']}). Units: {r.report['units']}, "
                 f"scale {r.scale:.3g} voxels per BVH unit ({r.report['scale']})."]
        lines += [c.line(n) for c in checks]
        self.detected.setText("\n".join(lines))
        self.detected.setStyleSheet("" if all(c.ok for c in checks) else "color: #d04040")
        self.show_frame()
