"""Letter shortcuts (the mode keys B, R, K, L, P, V; M, C, X, S) work wherever the focus is.

Qt first offers a key to the focused widget (a ShortcutOverride event) and a
spin box (for its text field) claims every printable key, letters included,
although a number field cannot take one: B did nothing while the thinness box
had the focus. Installed on spin boxes (the focus widget; their text field is
only its proxy), this filter answers that letters are not theirs. Text fields
(a joint name being typed) keep every key.

It is installed on the spin boxes themselves, not looked up through their
children: ``findChild(QLineEdit)`` returned None once in CI (at window start-up).
"""

from __future__ import annotations

from PySide6.QtCore import QEvent, QObject, Qt
from PySide6.QtWidgets import QAbstractSpinBox


class LettersPastNumberFields(QObject):
    def eventFilter(self, obj, event):  # noqa: N802 (Qt name)
        if event.type() != QEvent.ShortcutOverride:
            return False
        if event.modifiers() & ~Qt.ShiftModifier or not event.text().isalpha():
            return False
        if isinstance(obj, QAbstractSpinBox):
            event.ignore()  # not claimed: the window's shortcut gets the key
            return True
        return False
