"""Timeline → Render movie…: where, which frames, which look."""

from __future__ import annotations

from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QFileDialog,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QSpinBox,
    QWidget,
)

SIZES = ("640x480", "1280x720", "1920x1080", "320x240")


class MovieDialog(QDialog):
    """Ask for the movie's file, frame range, style, size and overlay; :meth:`options` reads them."""

    def __init__(self, parent, frame_count: int, default_path: str, follow: bool = True, colours: str = ""):
        super().__init__(parent)
        self.setWindowTitle("Render movie")
        form = QFormLayout(self)
        self.path = QLineEdit(default_path)
        browse = QPushButton("Browse…")
        browse.clicked.connect(self._browse)
        row = QWidget()
        line = QHBoxLayout(row)
        line.setContentsMargins(0, 0, 0, 0)
        line.addWidget(self.path)
        line.addWidget(browse)
        form.addRow("File (.mp4, .gif, or a folder)", row)
        self.first, self.last, self.step = QSpinBox(), QSpinBox(), QSpinBox()
        for box in (self.first, self.last):
            box.setRange(0, max(frame_count - 1, 0))
        self.last.setValue(max(frame_count - 1, 0))
        self.step.setRange(1, max(frame_count, 1))
        form.addRow("First frame", self.first)
        form.addRow("Last frame", self.last)
        form.addRow("Every Nth frame", self.step)
        self.style_box = QComboBox()
        self.style_box.addItems(["surface", "volume"])
        self.style_box.setToolTip("surface: the filled voxels' boundary, fast; volume: ray-cast, slower")
        form.addRow("Style", self.style_box)
        if colours:
            form.addRow("Colours", QLabel(colours))
        self.size_box = QComboBox()
        self.size_box.addItems(SIZES)
        form.addRow("Size", self.size_box)
        self.frame_numbers = QCheckBox("Frame numbers in the corner")
        form.addRow(self.frame_numbers)
        self.follow = QCheckBox("The camera follows the body (this view's direction and distance)")
        self.follow.setChecked(follow)
        form.addRow(self.follow)
        buttons = QDialogButtonBox(QDialogButtonBox.Ok | QDialogButtonBox.Cancel)
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        form.addRow(buttons)

    def _browse(self) -> None:
        path, _ = QFileDialog.getSaveFileName(self, "Movie file", self.path.text(), "Movies (*.mp4 *.gif)")
        if path:
            self.path.setText(path)

    def options(self) -> dict:
        w, h = (int(v) for v in self.size_box.currentText().split("x"))
        return {"out": self.path.text().strip(), "first": self.first.value(), "last": self.last.value(),
                "step": self.step.value(), "style": self.style_box.currentText(), "size": (w, h),
                "frame_numbers": self.frame_numbers.isChecked(), "follow": self.follow.isChecked()}
