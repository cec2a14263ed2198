"""Cyclic garbage is collected on the GUI thread only.

Python's automatic collection runs in whichever thread allocates when a generation
fills up. A worker thread reconstructing a frame allocates a lot, so it would also
collect the GUI's garbage; a cycle that holds a Qt widget or a VTK window (a closed
dialog, a replaced actor, a closed window's plotter) is then destroyed off the GUI
thread, which Qt and VTK do not survive (a rare segmentation fault).

So while the studio runs, automatic collection is off and a GUI-thread timer
collects with the same generation thresholds Python would use. This is the
approach of pyqtgraph's ``GarbageCollector``.
"""

from __future__ import annotations

import gc

from PySide6.QtCore import QCoreApplication, QObject, QTimer

#: How often the GUI thread looks at the generation counts (ms). Cheap when there is nothing to do.
INTERVAL_MS = 500


class GuiThreadCollector(QObject):
    def __init__(self, parent: QObject):
        super().__init__(parent)
        self.thresholds = gc.get_threshold()
        gc.disable()
        self._timer = QTimer(self)
        self._timer.timeout.connect(self.collect)
        self._timer.start(INTERVAL_MS)

    def collect(self) -> None:
        """What the automatic collector would do now, from this (the GUI) thread."""
        counts = gc.get_count()
        for generation in (2, 1, 0):  # the oldest generation due, which also collects the younger ones
            if counts[generation] > self.thresholds[generation]:
                gc.collect(generation)
                return


def collect_on_gui_thread() -> GuiThreadCollector:
    """Install the collector once per application (idempotent); it lives as long as the QApplication."""
    app = QCoreApplication.instance()
    existing = app.findChild(GuiThreadCollector)
    return existing if existing is not None else GuiThreadCollector(app)
