"""*File → View volume or mesh…*: a window of its own showing any volume, sequence frame or mesh.

The studio's *Open volume* segments and skeletonizes; this only looks (a
reconstruction written by ``volanim reconstruct``, a hull ``.ply``, a frame of a
``.zarr``), drawn exactly as ``volanim view`` and ``volanim render`` draw it.
It does not touch the document.

    file --read_look (the main window's reader thread)--> Look --draw_look (here, the GUI thread)--> window
    doc.events.transfer --> the volume drawn again through the edited function, the user's camera kept
"""

from __future__ import annotations

from pathlib import Path

from PySide6.QtWidgets import QMainWindow
from pyvistaqt import QtInteractor

from volanim_studio.qt.interactor import close_interactor

SIZE = (800, 600)


class QuickLookWindow(QMainWindow):
    def __init__(self, path, look, parent=None, doc=None):
        """``look``: the file as :func:`~volanim_core.render.quicklook.read_look` read it (at ``SIZE``).
        ``doc``: the studio's document, whose transfer function the window follows (#83: an open View window
        kept the function it was opened with)."""
        from volanim_core.render.quicklook import draw_look

        super().__init__(parent)
        self.look, self.doc = look, doc
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
        if doc is not None and look.volume is not None:  # a mesh has no values for a function to colour
            doc.events.transfer.connect(self._on_transfer)

    def _on_transfer(self, function, **_) -> None:
        """Draw the volume again through the edited function, from the camera the user has now."""
        from dataclasses import replace

        from volanim_core.render.quicklook import draw_look
        from volanim_core.render.scene import prepare_frame
        from volanim_core.render.views import Camera

        camera = Camera.of(self.plotter.renderer.GetActiveCamera())
        settings = replace(self.look.settings, transfer=function, camera=camera)
        look = replace(self.look, settings=settings, frame=prepare_frame(settings, self.look.volume, self.look.origin))
        self.plotter.remove_actor("body", render=False)
        self.renderer = draw_look(look, plotter=self.plotter)
        self.plotter.render()

    def closeEvent(self, event) -> None:
        if self.doc is not None:
            self.doc.events.transfer.disconnect(self._on_transfer)  # a second close finds it gone
        close_interactor(self.plotter)
        super().closeEvent(event)
