"""Letter shortcuts (the mode keys B, R, K, L, P, V; M, C, X, S) work wherever the focus is.

Qt first offers a key to the focused widget (a ShortcutOverride event) and the
text field inside a spin box claims every printable key, letters included,
although a number field cannot take one: B did nothing while the thinness box
had the focus. This filter answers for spin boxes that letters are not theirs.
Text fields (a joint name being typed) keep every key.
"""

from __future__ import annotations

from PySide6.QtCore import QEvent, QObject, Qt
from PySide6.QtWidgets import QAbstractSpinBox, QLineEdit


class LettersPastNumberFields(QObject):
    def eventFilter(self, obj, event):  # noqa: N802 (Qt name)
        if event.type() != QEvent.ShortcutOverride:
            return False
        if event.modifiers() & ~Qt.ShiftModifier or not event.text().isalpha():
            return False
        field = obj.parent() if isinstance(obj, QLineEdit) else obj
        if isinstance(field, QAbstractSpinBox):
            event.ignore()  # not claimed: the window's shortcut gets the key
            return True
        return False
