"""Cyclic garbage is collected on the GUI thread only, never in the middle of a drag or a play, and never
through the program's own start-up objects.

Python's automatic collection runs in whichever thread allocates when a generation
fills up. A worker thread reconstructing a frame allocates a lot, so it would also
collect the GUI's garbage; a cycle that holds a Qt widget or a VTK window (a closed
dialog, a replaced actor, a closed window's plotter) is then destroyed off the GUI
thread, which Qt and VTK do not survive (a rare segmentation fault).

So while the studio runs, automatic collection is off and a GUI-thread timer
collects with the same generation thresholds Python would use. This is the
approach of pyqtgraph's ``GarbageCollector``.

A full collection (generation 2) walks every tracked object of the process: the studio's ~380 k after opening
mannequin-large took 140-290 ms of the GUI thread on this machine (which drifts 2x), a visible stop in a drag or a
play (one every ~50 s of activity). Two things keep it out of the user's way:

- :func:`freeze_start_up`: what the program built before any file was read (its modules, classes, the window:
  ~320 k objects) is moved out of every later collection with ``gc.freeze`` -- it lives until the program
  quits, and a full collection then walks ~100 k objects (20-30 ms).
- while a window says it is :meth:`interacting <GuiThreadCollector.hold_full_while>` (a drag, a play), a full
  collection that falls due waits (the young generations, cheap, are still collected), at most
  ``HOLD_MAX_TICKS`` ticks, so a minute-long play cannot grow memory without end.
"""

from __future__ import annotations

import gc
import weakref

from PySide6.QtCore import QCoreApplication, QObject, QTimer

#: How often the GUI thread looks at the generation counts (ms). Cheap when there is nothing to do.
INTERVAL_MS = 500
#: The longest a full collection waits for an interaction to end: 120 ticks, a minute.
HOLD_MAX_TICKS = 120


class GuiThreadCollector(QObject):
    def __init__(self, parent: QObject):
        super().__init__(parent)
        self.thresholds = gc.get_threshold()
        gc.disable()
        self._holders: weakref.WeakSet = weakref.WeakSet()  # windows whose interacting() holds a full collection
        self.held = 0  # ticks a due full collection has waited
        self._timer = QTimer(self)
        self._timer.timeout.connect(self.collect)
        self._timer.start(INTERVAL_MS)

    def hold_full_while(self, holder) -> None:
        """Hold full collections while ``holder.interacting()`` is true (kept weakly: a closed window is
        forgotten with it)."""
        self._holders.add(holder)

    def collect(self) -> None:
        """What the automatic collector would do now, from this (the GUI) thread; a full collection waits
        while a holder is interacting."""
        counts = gc.get_count()
        for generation in (2, 1, 0):  # the oldest generation due, which also collects the younger ones
            if counts[generation] <= self.thresholds[generation]:
                continue
            if generation == 2:
                if self.held < HOLD_MAX_TICKS and any(h.interacting() for h in self._holders):
                    self.held += 1
                    continue  # the young generations as usual: a drag's garbage is young
                self.held = 0
            gc.collect(generation)
            return


def collect_on_gui_thread() -> GuiThreadCollector:
    """Install the collector once per application (idempotent); it lives as long as the QApplication."""
    app = QCoreApplication.instance()
    existing = app.findChild(GuiThreadCollector)
    return existing if existing is not None else GuiThreadCollector(app)


def freeze_start_up() -> int:
    """Move every object alive now out of all later collections (``gc.freeze``), after collecting the garbage
    there is (so none is kept for good): call it once the program is built and before any file is read, when
    everything alive lives until it quits. The number of objects frozen."""
    gc.collect()
    gc.freeze()
    return gc.get_freeze_count()
