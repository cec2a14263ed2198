"""The question at a start after a crash: which autosave to restore, each said with what it holds.

    RecoveryDialog(paths, descriptions) --exec()--> accepted: .chosen (a path); rejected: none restored

One autosave is asked about in a sentence; several are listed newest first, the
newest selected, so a session killed with nothing in it can never stand in front
of the one with the work (#83).
"""

from __future__ import annotations

from pathlib import Path

from PySide6.QtWidgets import QDialog, QDialogButtonBox, QLabel, QListWidget, QVBoxLayout


class RecoveryDialog(QDialog):
    def __init__(self, paths: list[Path], descriptions: list[str], parent=None):
        super().__init__(parent)
        self.setWindowTitle("Restore unsaved work?")
        self.paths = list(paths)
        self.chosen: Path | None = None
        several = len(paths) > 1
        text = ("volanim studio did not close properly last time. " + (
            f"{len(paths)} sessions left autosaves; choose one to restore (the others are kept):" if several
            else f"Restore the session autosaved {descriptions[0]}?"))
        label = QLabel(text)
        label.setWordWrap(True)
        layout = QVBoxLayout(self)
        layout.addWidget(label)
        self.list = QListWidget()
        self.list.addItems(descriptions)
        self.list.setCurrentRow(0)
        self.list.setVisible(several)
        self.list.itemDoubleClicked.connect(lambda _item: self.accept())
        layout.addWidget(self.list)
        note = QLabel("Not restored: kept a week in the autosave folder, where it can be opened as a project.")
        note.setWordWrap(True)
        layout.addWidget(note)
        buttons = QDialogButtonBox()
        self.restore_button = buttons.addButton("Restore", QDialogButtonBox.AcceptRole)
        self.skip_button = buttons.addButton("Don't restore", QDialogButtonBox.RejectRole)
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        layout.addWidget(buttons)
        self.restore_button.setDefault(True)

    def accept(self) -> None:
        row = self.list.currentRow()
        self.chosen = self.paths[row if row >= 0 else 0]  # before finished is emitted: listeners read it
        super().accept()
