"""Names in the viewport, hover, F2 and Ctrl+F2 with real widgets (issue #18)."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import Qt

from volanim_core import samples
from volanim_studio.model.modes import Mode

from ..conftest import click, clickable_point, qt_pos

pytestmark = pytest.mark.gui
J = samples.mannequin_bones().joints


def test_build_a_chain_with_a_line_to_the_cursor_then_name_it_in_one_line(qtbot, window):
    def actors():  # pyvista builds this dict anew on each access
        return window.plotter.renderer.actors

    qtbot.keyClick(window, Qt.Key_B)
    pts = [clickable_point(window, J[n]) for n in ("L_SHOULDER", "L_ELBOW", "L_WRIST")]
    click(qtbot, window, window.scene.display_of_point(pts[0]))
    target = window.scene.display_of_point(pts[1])
    qtbot.mouseMove(window.plotter, qt_pos(window, target))
    qtbot.waitUntil(lambda: "chain_preview" in actors(), timeout=5000)
    line = actors()["chain_preview"].mapper.GetInput()
    assert line.n_points == 2 and actors()["chain_preview"].GetVisibility()
    start, end = np.asarray(line.points)
    assert np.allclose(start, window.doc.skeleton.points[pts[0]] * window.scene.spacing)
    xy, _ = window.scene.project_world(end[None])
    assert np.linalg.norm(xy[0] - target) < 3  # the line ends under the cursor
    for p in pts[1:]:
        click(qtbot, window, window.scene.display_of_point(p))
    qtbot.keyClick(window, Qt.Key_Escape)
    assert "chain_preview" not in actors()  # the chain ended: no line
    labels = window.scene.names.label_actors
    assert len(window.doc.bones) == 2 and len(labels) == 1 and labels[0] in actors().values()
    qtbot.keyClick(window, Qt.Key_F2, Qt.ControlModifier)  # the selected (last built) bone's chain
    box = window.naming.box
    assert box.isVisible() and "3 joints" in box.labelText()
    box.setTextValue("SHOULDER, ELBOW, WRIST")
    box.accept()
    assert {"L_SHOULDER", "L_ELBOW", "L_WRIST"} == set(window.doc.bones.joints)  # L_ from the side
    assert window.scene.names.shown_names == ["L_SHOULDER", "L_ELBOW", "L_WRIST"]
    qtbot.keyClick(window, Qt.Key_Z, Qt.ControlModifier)  # one undo step
    assert "L_ELBOW" not in window.doc.bones.joints


def test_hover_names_a_joint_click_picks_it_and_f2_renames_it(qtbot, window):
    window.doc.bone_edits.add_bone(J["L_SHOULDER"], J["L_ELBOW"])
    elbow = next(n for n, p in window.doc.bones.joints.items() if np.allclose(p, J["L_ELBOW"]))
    at = window.scene.project_world(window.scene.world(J["L_ELBOW"][None]))[0][0]
    qtbot.mouseMove(window.plotter, qt_pos(window, at))
    qtbot.waitUntil(lambda: window.scene.names.hovered is not None, timeout=5000)
    assert window.scene.names.hovered == ("joint", elbow) and "hover" in window.plotter.renderer.actors
    assert elbow in window.statusBar().currentMessage()
    click(qtbot, window, at)  # View mode: picks the joint
    assert window.doc.picked_joint == elbow and "picked_joint" in window.plotter.renderer.actors
    qtbot.keyClick(window, Qt.Key_F2)
    box = window.naming.box
    assert box.textValue() == elbow
    box.setTextValue("L_ELBOW")
    box.accept()
    assert "L_ELBOW" in window.doc.bones.joints and window.doc.picked_joint == "L_ELBOW"
    window.display_panel.names_visible.setChecked(False)  # the Display tab hides the names
    assert window.scene.names.label_actors == [] and window.scene.names.shown_names == []
    assert not any(type(a).__name__ == "vtkActor2D" and a.GetMapper() is not None and "Label" in
                   a.GetMapper().GetClassName() for a in window.plotter.renderer.actors.values())


def test_f2_with_no_joint_clicked_says_what_to_do(qtbot, window):
    window.set_mode(Mode.VIEW)
    qtbot.keyClick(window, Qt.Key_F2)
    assert "Click a joint first" in window.statusBar().currentMessage()


def test_the_readme_walkthrough_builds_and_names_the_mannequin_in_about_36_actions(qtbot, window):
    """The README's "Build a bone skeleton" with real clicks and keys; every action is counted
    (issue #18: about 100 clicks and keys, 43 of them to name joints)."""
    actions = 0

    def act(n=1):
        nonlocal actions
        actions += n

    window.display_panel.thinness_slider.setValue(window.display_panel._step_of(0.75))
    act()  # one drag of the thinness slider
    qtbot.keyClick(window, Qt.Key_B)
    act()

    def chain(start, names):
        """Click ``start`` (a joint name already there, or a position), then each joint; Esc."""
        for n in [start, *names]:
            if n in window.doc.bones.joints:
                at = window.scene.project_world(window.scene.world(window.doc.bones.joints[n][None]))[0][0]
            else:
                at = window.scene.display_of_point(clickable_point(window, J[n]))
            click(qtbot, window, at)
            act()
        qtbot.keyClick(window, Qt.Key_Escape)
        act()

    def name_chain(preset: str):
        qtbot.keyClick(window, Qt.Key_F2, Qt.ControlModifier)
        box = window.naming.box
        box.setTextValue(preset)  # opening the preset list and clicking the line: two clicks
        box.accept()  # Enter
        act(4)

    chain("PELVIS", ["NECK", "HEAD"])
    name_chain("PELVIS, NECK, HEAD")
    chain("NECK", ["L_SHOULDER", "L_ELBOW", "L_WRIST", "L_FINGERS"])
    name_chain("NECK, SHOULDER, ELBOW, WRIST, FINGERS")
    chain("PELVIS", ["L_HIP", "L_KNEE", "L_ANKLE", "L_TOE"])
    name_chain("PELVIS, HIP, KNEE, ANKLE, TOE")
    tree = window.bone_panel.tree
    left = [i for i, b in enumerate(window.doc.bones.bones) if b.distal.startswith("L_")]
    assert left == list(range(left[0], left[-1] + 1))  # rows next to each other: click, Shift+click
    tree.clearSelection()
    for i in left:
        tree.topLevelItem(i).setSelected(True)
    act(2)
    window.activateWindow()
    qtbot.keyClick(window, Qt.Key_M)
    act()
    want = samples.mannequin_bones()
    assert set(window.doc.bones.joints) == set(want.joints)
    assert {(b.proximal, b.distal) for b in window.doc.bones.bones} == {(b.proximal, b.distal) for b in want.bones}
    for n, p in window.doc.bones.joints.items():
        assert np.linalg.norm(p - want.joints[n]) < 20, n  # near the real joints (a skeleton ends short of a tip)
    act(3)  # Ctrl+S, type a file name, Enter
    assert actions == 36, actions
