"""Letter shortcuts (the mode keys B, R, K, L, P, V; M, C, X, S) work wherever the focus is.

Qt first offers a key to the focused widget (a ShortcutOverride event) and a
spin box (for its text field) claims every printable key, letters included,
although a number field cannot take one: B did nothing while the thinness box
had the focus. Installed on spin boxes (the focus widget; their text field is
only its proxy), this filter answers that letters are not theirs. Text fields
(a joint name being typed) keep every key.

Undo and redo (Ctrl+Z, Ctrl+Shift+Z, Ctrl+Y) likewise: a number field claimed
them for its text's own undo, so after typing a frame and Enter, Ctrl+Z did
nothing to the document until the user clicked the view. A field keeps them only
while its text is being edited (the text differs from the value it shows).

It is installed on the spin boxes themselves, not looked up through their
children: ``findChild(QLineEdit)`` returned None once in CI (at window start-up).
"""

from __future__ import annotations

from PySide6.QtCore import QEvent, QObject, Qt
from PySide6.QtGui import QKeySequence
from PySide6.QtWidgets import QAbstractSpinBox

HISTORY_KEYS = (QKeySequence.StandardKey.Undo, QKeySequence.StandardKey.Redo)


def being_edited(spin) -> bool:
    """Whether a number field's text is a pending edit (typed, not yet taken with Enter or focus-out)."""
    text_of = getattr(spin, "textFromValue", None)
    return text_of is not None and spin.cleanText() != text_of(spin.value())


class LettersPastNumberFields(QObject):
    def eventFilter(self, obj, event):  # noqa: N802 (Qt name)
        if event.type() != QEvent.ShortcutOverride:
            return False
        if any(event.matches(k) for k in HISTORY_KEYS) and isinstance(obj, QAbstractSpinBox):
            if being_edited(obj):
                return False  # its own text undo, while the text is being typed
            event.ignore()  # the document's undo (the window's action)
            return True
        if event.modifiers() & ~Qt.ShiftModifier or not event.text().isalpha():
            return False
        if isinstance(obj, QAbstractSpinBox):
            event.ignore()  # not claimed: the window's shortcut gets the key
            return True
        return False
