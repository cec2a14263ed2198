"""Which BVH joint drives which bone: the suggestions, editable, before a clip is retargeted."""

from __future__ import annotations

from PySide6.QtWidgets import (
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QScrollArea,
    QVBoxLayout,
    QWidget,
)

from volanim_core.motion.bvh import Motion
from volanim_core.motion.retarget import suggest_mapping
from volanim_core.rig.bones import BoneSkeleton

UNMAPPED = "(follows its parent)"
AXES = ["auto", "y", "z", "x", "-y", "-z", "-x"]


class MappingDialog(QDialog):
    """One row per bone: a BVH joint (suggested from the names) or none; the clip's axes."""

    def __init__(self, bones: BoneSkeleton, motion: Motion, clip_name: str, parent=None):
        super().__init__(parent)
        self.setWindowTitle(f"Map {clip_name} onto the bones")
        suggested = suggest_mapping(bones, motion)
        self.combos: dict[str, QComboBox] = {}
        form = QFormLayout()
        for b in bones.bones:
            combo = QComboBox()
            combo.addItems([UNMAPPED, *motion.names])
            combo.setCurrentText(suggested.get(b.label, UNMAPPED))
            form.addRow(b.label, combo)
            self.combos[b.label] = combo
        inner = QWidget()
        inner.setLayout(form)
        scroll = QScrollArea()
        scroll.setWidget(inner)
        scroll.setWidgetResizable(True)
        unmapped = [b.label for b in bones.bones if b.label not in suggested]
        note = QLabel(f"{motion.frames} frames at {motion.fps:.4g} fps, {len(motion.names)} joints. "
                      f"{len(suggested)} of {len(bones)} bones matched by name"
                      + (f"; unmapped (they follow their parent): {', '.join(unmapped)}." if unmapped else "."))
        note.setWordWrap(True)
        self.up, self.forward = QComboBox(), QComboBox()
        self.up.addItems(AXES)
        self.forward.addItems(AXES)
        axes = QHBoxLayout()
        for text, w in (("Clip's up axis", self.up), ("facing", self.forward)):
            axes.addWidget(QLabel(text))
            axes.addWidget(w)
        axes.addStretch(1)
        buttons = QDialogButtonBox(QDialogButtonBox.Ok | QDialogButtonBox.Cancel)
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        layout = QVBoxLayout(self)
        layout.addWidget(note)
        layout.addWidget(scroll, 1)
        layout.addLayout(axes)
        layout.addWidget(buttons)
        self.resize(460, 620)

    def mapping(self) -> dict[str, str]:
        return {label: c.currentText() for label, c in self.combos.items() if c.currentText() != UNMAPPED}

    def axes(self) -> tuple[str, str]:
        return self.up.currentText(), self.forward.currentText()
