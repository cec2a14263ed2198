"""Camera navigation in the real window: buttons, presets, keys (issue #18)."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt

from paths import ASSETS
from volanim_core import samples
from volanim_studio.model.interaction import Mode

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


def _direction(window) -> np.ndarray:
    cam = window.plotter.renderer.GetActiveCamera()
    d = np.subtract(cam.GetFocalPoint(), cam.GetPosition())
    return d / np.linalg.norm(d)


def test_view_presets_frame_and_reset(qtbot, window):
    cam = window.plotter.renderer.GetActiveCamera()
    qtbot.keyClick(window, Qt.Key_7, Qt.ControlModifier)  # top: looking down
    assert np.allclose(_direction(window), [0, 0, -1], atol=1e-6)
    qtbot.keyClick(window, Qt.Key_3, Qt.ControlModifier)  # side: from the figure's left (+x)
    assert np.allclose(_direction(window), [-1, 0, 0], atol=1e-6)
    qtbot.keyClick(window, Qt.Key_1, Qt.ControlModifier)  # front: from -y, z up
    assert np.allclose(_direction(window), [0, 1, 0], atol=1e-6) and np.allclose(cam.GetViewUp(), [0, 0, 1])
    assert window.files.open_bones(ASSETS / "mannequin.bones")
    forearm = window.doc.bones.index("L_FOREARM")
    window.doc.select_bones([forearm])
    far = cam.GetDistance()
    qtbot.keyClick(window, Qt.Key_F)  # frame selected: the forearm's middle, closer
    middle = (J["L_ELBOW"] + J["L_WRIST"]) / 2 * window.scene.spacing
    assert np.allclose(cam.GetFocalPoint(), middle, atol=1.0) and cam.GetDistance() < far / 2
    qtbot.keyClick(window, Qt.Key_F, Qt.ShiftModifier)  # frame all
    assert cam.GetDistance() > far / 2
    qtbot.keyClick(window, Qt.Key_0, Qt.ControlModifier)  # reset: the front view
    assert np.allclose(_direction(window), [0, 1, 0], atol=1e-6)


def test_an_orientation_widget_is_shown(window):
    widget = window.plotter.renderer.axes_widget
    assert widget is not None and widget.GetEnabled()


def test_pyvista_and_vtk_keys_do_nothing(qtbot, window):
    """W turned everything to wireframe, Q snapped the camera, + and - changed the point size."""
    w = window.plotter
    cam = w.renderer.GetActiveCamera()
    before = (cam.GetPosition(), cam.GetFocalPoint())
    hull = w.renderer.actors["hull"].GetProperty()
    cloud = w.renderer.actors["cloud"].GetProperty()
    size = cloud.GetPointSize()
    w.setFocus()
    for key in (Qt.Key_W, Qt.Key_Q, Qt.Key_Plus, Qt.Key_Minus, Qt.Key_E, Qt.Key_3, Qt.Key_J):
        qtbot.keyClick(w, key)
    assert hull.GetRepresentation() == 2 and cloud.GetPointSize() == size  # 2: surface
    assert (cam.GetPosition(), cam.GetFocalPoint()) == before and window.isVisible()


def test_mode_keys_work_while_a_number_field_has_the_focus_and_show_their_tab(qtbot, window):
    """B did nothing while a spin box had the focus (it claimed every printable key)."""
    spin = window.display_panel.thinness_spin
    window.panel_tabs.setCurrentWidget(window.display_panel)
    spin.setFocus()
    qtbot.waitUntil(spin.hasFocus, timeout=2000)
    qtbot.keyClick(spin, Qt.Key_B)
    assert window.mode == Mode.BONES and window.panel_tabs.currentWidget() is window.bone_panel
    window.panel_tabs.setCurrentWidget(window.display_panel)
    spin.setFocus()
    qtbot.keyClick(spin, Qt.Key_K)
    assert window.mode == Mode.CUBE and window.panel_tabs.currentWidget() is window.connect_panel
    spin.selectAll()
    qtbot.keyClicks(spin, "0.6")  # digits are still the box's
    qtbot.keyClick(spin, Qt.Key_Return)
    assert window.doc.thinness == 0.6
