"""An angle slider that lands on any whole degree: Shift while dragging turns it a degree per FINE_PIXELS.

    press --> as QSlider (the handle follows the mouse: 360 degrees over the slider's width)
    move with Shift held --> the value where Shift was first held + (mouse x since then) / FINE_PIXELS
                             (for the rest of that drag: letting Shift go does not jump back to the mouse)

Why (#85): the Pose tab's sliders are about 190 pixels for 360 degrees, two degrees a pixel, so aiming for 0 or
-90 landed on 1 or -91; the arrow keys and the spin box were the only way to a whole degree.
"""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QSlider

FINE_PIXELS = 5  # pixels of mouse travel per degree with Shift held


class FineSlider(QSlider):
    """A horizontal QSlider whose drag with Shift held moves one step per :data:`FINE_PIXELS` pixels."""

    def __init__(self, parent=None):
        super().__init__(Qt.Horizontal, parent)
        self._anchor: tuple[float, int] | None = None  # (mouse x, value) where the fine drag began
        self.setToolTip("Drag to turn; hold Shift while dragging for one degree per "
                        f"{FINE_PIXELS} pixels; arrow keys: one degree")

    def mousePressEvent(self, event) -> None:  # noqa: N802 (Qt name)
        self._anchor = None
        super().mousePressEvent(event)

    def mouseMoveEvent(self, event) -> None:  # noqa: N802 (Qt name)
        x = event.position().x()
        if self.isSliderDown() and (self._anchor is not None or event.modifiers() & Qt.ShiftModifier):
            if self._anchor is None:
                self._anchor = (x, self.value())
            x0, v0 = self._anchor
            step = int(round((x - x0) / FINE_PIXELS))
            self.setSliderPosition(max(self.minimum(), min(self.maximum(), v0 + step)))
            event.accept()
            return
        super().mouseMoveEvent(event)

    def mouseReleaseEvent(self, event) -> None:  # noqa: N802 (Qt name)
        self._anchor = None
        super().mouseReleaseEvent(event)
