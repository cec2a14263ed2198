"""*File → View volume or mesh…*: a window of its own showing any volume, sequence frame or mesh.

The studio's *Open volume* segments and skeletonizes; this only looks (a
reconstruction written by ``volanim reconstruct``, a hull ``.ply``, a frame of a
``.zarr``), drawn exactly as ``volanim view`` and ``volanim render`` draw it.
It does not touch the document.

    file --read_look (the main window's reader thread)--> Look --draw_look (here, the GUI thread)--> window
"""

from __future__ import annotations

from pathlib import Path

from PySide6.QtWidgets import QMainWindow
from pyvistaqt import QtInteractor

from volanim_studio.qt.interactor import close_interactor

SIZE = (800, 600)


class QuickLookWindow(QMainWindow):
    def __init__(self, path, look, parent=None):
        """``look``: the file as :func:`~volanim_core.render.quicklook.read_look` read it (at ``SIZE``)."""
        from volanim_core.render.quicklook import draw_look

        super().__init__(parent)
        self.setWindowTitle(f"View — {Path(path).name}")
        self.resize(*SIZE)
        self.plotter = QtInteractor(self)
        self.setCentralWidget(self.plotter.interactor if hasattr(self.plotter, "interactor") else self.plotter)
        try:
            self.renderer, self.what = draw_look(look, plotter=self.plotter), look.what
        except BaseException:
            close_interactor(self.plotter)
            raise
        self.statusBar().showMessage(f"{path}: {self.what}. Drag to turn, wheel to zoom.")

    def closeEvent(self, event) -> None:
        close_interactor(self.plotter)
        super().closeEvent(event)
