"""The clip's breakage scan: one row per frame, worst first; double-click a row to go there."""

from __future__ import annotations

from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import QDialog, QLabel, QTableWidget, QTableWidgetItem, QVBoxLayout

from volanim_core.reconstruct.scan import scan_summary

COLUMNS = ("frame", "pieces", "detached voxels", "stump points", "lump voxels", "cracks", "gap (voxels)",
           "worst joint")


class ScanDialog(QDialog):
    jump = Signal(int)  # the frame index to show

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setWindowTitle("Breakage across the clip")
        self.setModal(False)
        self.summary = QLabel()
        self.table = QTableWidget(0, len(COLUMNS))
        self.table.setHorizontalHeaderLabels(COLUMNS)
        self.table.setEditTriggers(QTableWidget.NoEditTriggers)
        self.table.setSelectionBehavior(QTableWidget.SelectRows)
        self.table.cellDoubleClicked.connect(lambda row, _: self.jump.emit(self.frames[row]))
        layout = QVBoxLayout(self)
        layout.addWidget(self.summary)
        layout.addWidget(self.table)
        self.frames: list[int] = []
        self.resize(560, 480)

    def show_verdicts(self, verdicts, label=str) -> None:
        """``verdicts`` worst first; ``label(frame)`` is the number shown (the clip's own numbering)."""
        self.frames = [v.frame for v in verdicts]
        self.summary.setText(f"{scan_summary(verdicts)} (half-resolution pieces, exact cracks, lumps as the report "
                             "finds them). Double-click a frame to show it, then F5 for its full report.")
        self.table.setRowCount(len(verdicts))
        for row, v in enumerate(verdicts):
            near = v.worst_joint or v.lump_near or "—"
            cells = (label(v.frame), v.pieces, v.detached, v.stump, v.lump, v.cracks, f"{v.gap:.1f}", near)
            for col, value in enumerate(cells):
                item = QTableWidgetItem(str(value))
                item.setTextAlignment(Qt.AlignRight | Qt.AlignVCenter if col < 7 else Qt.AlignLeft | Qt.AlignVCenter)
                self.table.setItem(row, col, item)
