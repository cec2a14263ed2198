"""Keys: the shortcuts dialog, F1's list of every menu shortcut, an empty studio's answers."""

from __future__ import annotations

import pytest
from PySide6.QtCore import Qt

pytestmark = pytest.mark.gui


def test_shortcuts_dialog_lists_them_all_and_fits_the_screen(qtbot, window):
    """#83 item 12: the F1 box was taller than a 1000 px screen (its Close button out of reach)."""
    from PySide6.QtWidgets import QDialogButtonBox, QTextBrowser

    from volanim_studio.qt.main_window import SHORTCUTS

    qtbot.keyClick(window, Qt.Key_F1)
    box = window._shortcut_box
    assert box.isVisible()
    text = box.findChild(QTextBrowser).toPlainText()
    assert "Ctrl+Z" in text and all(k in text for k, _ in SHORTCUTS)
    screen = box.screen().availableGeometry()
    assert box.frameGeometry().height() <= screen.height() and box.height() <= 900
    box.findChild(QDialogButtonBox).button(QDialogButtonBox.Close).click()
    assert not box.isVisible()


def test_f1_lists_every_keyboard_shortcut_of_the_menus(window):
    """The F1 list is typed by hand; every shortcut a menu action has must be in it (it missed
    Ctrl+Shift+S and Ctrl+Q)."""
    import re

    from PySide6.QtGui import QAction, QKeySequence

    from volanim_studio.qt.main_window import SHORTCUTS

    listed = {t for k, _ in SHORTCUTS for t in re.split(r" / |, ", k)}
    keys = {a.shortcut().toString(QKeySequence.PortableText) for a in window.findChildren(QAction)} - {""}
    assert {"Ctrl+Shift+S", "Ctrl+Q", "F1"} <= keys
    assert not sorted(keys - listed), f"shortcuts missing from F1: {sorted(keys - listed)}"


def test_an_empty_studio_answers_f5_and_ctrl_s_in_words_and_writes_nothing(qtbot, tmp_path):
    """F5 on an empty studio printed a traceback; Ctrl+S wrote an empty project (issue #18)."""
    from volanim_studio.qt.main_window import MainWindow

    w = MainWindow()
    qtbot.addWidget(w)
    w.show()
    qtbot.waitExposed(w)
    assert w.previews.preview() is None
    assert "nothing loaded yet: open a volume, a demo or a project first" in w.last_error
    w.last_error = None
    w.previews.live_preview()  # what a timeline frame change asks for: a status message, no dialog
    assert w.last_error is None and "nothing loaded yet" in w.statusBar().currentMessage()
    out = tmp_path / "out"
    out.mkdir()
    assert w.files.save_project(path=out / "empty.volanim") is None
    assert "nothing to save yet" in w.statusBar().currentMessage()  # said, with no dialog (#61)
    assert list(out.iterdir()) == [] and not w.busy
    w.close()
