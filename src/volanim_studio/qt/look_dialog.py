"""File → View volume or mesh…: a file dialog that takes a sequence's folder as the file it is.

A sequence is a folder (``NAME.zarr``, OME-Zarr). A file dialog in file mode steps into a folder on Open or
on a double-click, so the user had to go inside and pick ``zarr.json`` (#61). Here choosing the folder --
selecting it and pressing Open, or double-clicking it -- chooses the sequence.
"""

from __future__ import annotations

from pathlib import Path

from PySide6.QtWidgets import QDialog, QFileDialog


def is_sequence_folder(path) -> bool:
    """A folder the studio views as one thing: an OME-Zarr sequence (its ``zarr.json`` is inside)."""
    p = Path(path)
    return p.is_dir() and (p / "zarr.json").is_file()


class LookDialog(QFileDialog):
    """Qt's own file dialog (the same on every desktop, and under Xvfb), file mode; ``chosen`` after Open."""

    def __init__(self, parent, title: str, folder: str, filters: str):
        super().__init__(parent, title, folder, filters)
        self.setOption(QFileDialog.DontUseNativeDialog, True)  # a native dialog cannot be told about folders
        self.setFileMode(QFileDialog.ExistingFile)
        self.chosen: str | None = None
        self.directoryEntered.connect(self._entered)

    def _entered(self, folder: str) -> None:
        if is_sequence_folder(folder):  # double-clicked a sequence: that is the choice, not a place to look in
            self._choose(folder)

    def accept(self) -> None:  # the Open button (or Enter)
        picked = self.selectedFiles()
        if picked and is_sequence_folder(picked[0]):
            self._choose(picked[0])
            return
        # chosen is set before QFileDialog.accept, which emits ``finished`` from inside itself: set after it,
        # every listener of finished read None, and View of a plain file did nothing at all (#83)
        self.chosen = picked[0] if picked else None
        super().accept()
        if self.result() != QDialog.Accepted:  # refused (no such file): the dialog stays open
            self.chosen = None

    def _choose(self, path: str) -> None:
        self.chosen = path
        QDialog.accept(self)
