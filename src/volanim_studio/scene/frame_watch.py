"""When the view's frames are drawn and on screen: what the last draw took, and calls made once the next frame
is shown (the live thread begins its next picture then, #85)."""

from __future__ import annotations

import time


class FrameWatch:
    """Times each frame the plotter's render window draws (``seconds``: the last one; software GL makes it most
    of a live update's) and calls what :meth:`after_next` was given once the next frame is on screen."""

    def __init__(self, plotter):
        self.seconds = 0.0
        self.clock = time.perf_counter  # times the draws (a test's own: the live resolution they pick)
        self._began = 0.0
        self._after: list = []
        window = plotter.render_window
        window.AddObserver("StartEvent", lambda *_: setattr(self, "_began", self.clock()))
        window.AddObserver("EndEvent", lambda *_: setattr(self, "seconds", self.clock() - self._began))
        if hasattr(plotter, "frameSwapped"):  # Qt's widget: on screen once composed (software GL: read back)
            plotter.frameSwapped.connect(self._shown)

    def after_next(self, call) -> None:
        """``call()`` once the next frame is on screen: drawn, and composed into the window (software GL finishes
        the drawing there). Off screen (no Qt widget): never. A call already waiting is not added again (a hidden
        window's frames never come: its waiting calls would pile up)."""
        if call not in self._after:
            self._after.append(call)

    def _shown(self) -> None:
        calls, self._after = self._after, []
        for call in calls:
            call()
