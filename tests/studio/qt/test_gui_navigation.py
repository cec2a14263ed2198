"""Camera navigation in the real window: buttons, presets, keys (issue #18)."""

from __future__ import annotations

import pytest
from PySide6.QtCore import QPoint, Qt

from volanim_core import samples
from volanim_studio.model.modes import Mode

from ..conftest import click, clickable_point

pytestmark = pytest.mark.gui
J = samples.mannequin_bones().joints


def _style_state(window) -> int:
    return window.plotter.iren.style.GetState()


def test_right_click_leaves_the_camera_idle_and_the_next_left_click_counts(qtbot, window):
    """The release observer replaced the style's own: the camera stayed in dolly (state 4), zooming on
    every mouse move, and the next joint click was swallowed."""
    w = window.plotter
    cam = window.plotter.renderer.GetActiveCamera()
    window.set_mode(Mode.BONES)
    a = clickable_point(window, J["L_SHOULDER"])
    click(qtbot, window, window.scene.display_of_point(a))
    click(qtbot, window, window.scene.display_of_point(a), button=Qt.RightButton)  # ends the chain
    assert _style_state(window) == 0
    before = cam.GetPosition()
    qtbot.mouseMove(w, QPoint(w.width() // 2, w.height() // 3))
    qtbot.mouseMove(w, QPoint(w.width() // 2, w.height() // 4))
    assert cam.GetPosition() == before, "moving the mouse after a right click must not zoom"
    b, c = clickable_point(window, J["R_SHOULDER"]), clickable_point(window, J["R_ELBOW"])
    click(qtbot, window, window.scene.display_of_point(b))
    click(qtbot, window, window.scene.display_of_point(c))
    assert len(window.doc.bones) == 1, "the first left click after a right click was swallowed"


def test_typing_a_thinness_keeps_every_digit(qtbot, window):
    """Typing 0.75 gave 0.700: the model wrote 0.7 back into the box mid-typing (issue #18)."""
    spin = window.display_panel.thinness_spin
    window.panel_tabs.setCurrentWidget(window.display_panel)
    spin.setFocus()
    spin.selectAll()
    qtbot.keyClicks(spin, "0.75")
    qtbot.keyClick(spin, Qt.Key_Return)
    assert spin.text() == "0.750" and window.doc.thinness == 0.75
