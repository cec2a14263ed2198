"""When the view's frames are drawn: what the last draw took, and calls made once the next frame is drawn (the live
thread begins its next picture then, #85).

    after_next(call) --> waiting --StartEvent (a draw begins: it draws what the model holds now)--> in this draw
                                 --EndEvent (that draw is done)--> call()

A call waits for a draw that *begins* after it was given: a draw already under way may not hold what the
caller just put in the scene. It is made when that draw ends, not when Qt has composed the window: composing
(software GL: the picture read back, 15-20 ms on the frog) neither holds Python's lock nor draws, so the live
thread makes its next picture meanwhile (#85: the frog's drag 10.7 -> 15.1 pictures a second in one run).
"""

from __future__ import annotations

import time


class FrameWatch:
    """Times each frame the plotter's render window draws (``seconds``: the last one; software GL makes it most
    of a live update's) and calls what :meth:`after_next` was given once the next frame is drawn; ``before()`` as
    a draw begins after :meth:`changed` (the view fits its clipping planes there, wherever the draw comes from)."""

    def __init__(self, plotter, before=lambda: None):
        self.seconds = 0.0
        self.clock = time.perf_counter  # times the draws (a test's own: the live resolution they pick)
        self._began = 0.0
        self._waiting: list = []  # given since the last draw began
        self._drawing: list = []  # given before the draw under way began: called when it ends
        self._before = before
        self._changed = False
        window = plotter.render_window
        window.AddObserver("StartEvent", lambda *_: self._began_draw())
        window.AddObserver("EndEvent", lambda *_: self._ended_draw())

    def after_next(self, call) -> None:
        """``call()`` once the next draw that begins from now has ended. A call already waiting is not added again
        (a hidden window draws nothing: its waiting calls would pile up)."""
        if call not in self._waiting:
            self._waiting.append(call)

    def changed(self) -> None:
        """The scene changed: the next draw to begin calls ``before()`` first (once for many changes)."""
        self._changed = True

    def prepare(self) -> None:
        """``before()`` now if the scene changed since it was last called (at a draw's start, or for a draw
        pyvista skips: a window not yet shown)."""
        if self._changed:
            self._changed = False
            self._before()

    def _began_draw(self) -> None:
        self.prepare()
        self._began = self.clock()
        self._drawing, self._waiting = self._drawing + self._waiting, []

    def _ended_draw(self) -> None:
        self.seconds = self.clock() - self._began
        calls, self._drawing = self._drawing, []
        for call in calls:
            call()
