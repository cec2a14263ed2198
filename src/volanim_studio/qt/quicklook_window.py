"""*File → View volume or mesh…*: a window of its own showing any volume, sequence frame or mesh.

The studio's *Open volume* segments and skeletonizes; this only looks (a
reconstruction written by ``volanim reconstruct``, a hull ``.ply``, a frame of a
``.zarr``), drawn exactly as ``volanim view`` and ``volanim render`` draw it.
It does not touch the document.
"""

from __future__ import annotations

from pathlib import Path

from PySide6.QtWidgets import QMainWindow
from pyvistaqt import QtInteractor

from volanim_studio.qt.interactor import close_interactor


class QuickLookWindow(QMainWindow):
    def __init__(self, path, parent=None):
        from volanim_core.render.quicklook import quick_look

        super().__init__(parent)
        self.setWindowTitle(f"View — {Path(path).name}")
        self.resize(800, 600)
        self.plotter = QtInteractor(self)
        self.setCentralWidget(self.plotter.interactor if hasattr(self.plotter, "interactor") else self.plotter)
        try:
            self.renderer, self.what = quick_look(path, plotter=self.plotter, size=(800, 600))
        except BaseException:
            close_interactor(self.plotter)
            raise
        self.statusBar().showMessage(f"{path}: {self.what}. Drag to turn, wheel to zoom.")

    def closeEvent(self, event) -> None:
        close_interactor(self.plotter)
        super().closeEvent(event)
