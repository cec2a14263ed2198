"""Bones -> Propose bones... with real widgets: preview in the scene, accept, undo; discard."""

from __future__ import annotations

import pytest
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QDialogButtonBox

from volanim_core import samples

from ..conftest import JOB_TIMEOUT_MS

pytestmark = pytest.mark.gui

NAMES = [b.name for b in samples.mannequin_bones().bones]


def _propose(qtbot, window, template):
    menu = next(a.menu() for a in window.menuBar().actions() if a.text() == "&Bones")
    action = next(a for a in menu.actions() if a.text().startswith("Propose bones"))
    action.trigger()
    dialog = window.proposing.dialog
    qtbot.waitExposed(dialog)
    dialog.template.setCurrentText(template)
    qtbot.mouseClick(dialog.preview_button, Qt.LeftButton)
    qtbot.waitUntil(lambda: not window.busy, timeout=JOB_TIMEOUT_MS)
    return dialog


def test_propose_preview_accept_and_undo(qtbot, window):
    hand_made = window.doc.bones
    dialog = _propose(qtbot, window, "none")
    assert "ROOT" in window.doc.bones.joints and "(none)" in dialog.summary.text()
    for label in (dialog.hint, dialog.summary):  # wrapped text shown whole (the dialog grows; it was clipped)
        assert label.height() >= label.heightForWidth(label.width()), label.text()
    dialog.template.setCurrentText("humanoid")
    qtbot.mouseClick(dialog.preview_button, Qt.LeftButton)
    qtbot.waitUntil(lambda: not window.busy, timeout=JOB_TIMEOUT_MS)
    assert [b.name for b in window.doc.bones.bones] == NAMES
    assert window.bone_panel.tree.topLevelItemCount() == len(NAMES)  # the panel follows the model
    qtbot.mouseClick(dialog.buttons.button(QDialogButtonBox.Ok), Qt.LeftButton)
    assert not dialog.isVisible() and [b.name for b in window.doc.bones.bones] == NAMES
    window.undo()  # one step takes the accepted proposal back to the hand-made bones
    assert window.doc.bones == hand_made


def test_discard_puts_the_bones_back(qtbot, window):
    hand_made = window.doc.bones
    dialog = _propose(qtbot, window, "humanoid")
    assert window.doc.bones != hand_made
    qtbot.mouseClick(dialog.buttons.button(QDialogButtonBox.Discard), Qt.LeftButton)
    assert window.doc.bones == hand_made and not dialog.isVisible()
