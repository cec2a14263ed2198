"""The status bar: the newest message whole, the verdict and the picked point in what is left.

    doc.events.message --showMessage--> the message (15 s)
    messageChanged, a resize --fit--> each permanent label's width: the message's own width first, then the
        verdict, then the point; a label with less room than its text draws it cut with "…" (its tooltip
        and ``text()`` keep all of it)

Why: QStatusBar gives its permanent widgets their full width and the message what is left, so a long
verdict and a picked point's line cut the message the user had to read ("…Then read the breaka", #61).
"""

from __future__ import annotations

import html

from PySide6.QtCore import QEvent, QObject, QSize, Qt
from PySide6.QtGui import QColor, QFontMetrics, QPainter
from PySide6.QtWidgets import QLabel, QStatusBar

GAP = 24  # pixels between the message and the labels (the bar's own margins and grip)


class ElidedLabel(QLabel):
    """A one-line label that may be given less width than its text: it draws the text cut with "…".
    ``set_styled(text, colour, bold)``; ``text()`` stays the whole text (rich text when styled).
    With ``setWordWrap(True)`` (the Pose tab's verdict, which has room below it) it draws the whole text
    wrapped to its width instead (#83: the verdict was cut there too)."""

    def __init__(self, parent=None):
        super().__init__("", parent)
        self._plain, self._colour, self._bold = "", None, False
        self.base_tip = ""  # the tooltip when the whole text shows
        self.changed = lambda: None  # the status line fits the labels again when a text changes

    def set_styled(self, text: str, colour: str | None = None, bold: bool = False) -> None:
        body = html.escape(text)
        if colour:
            body = f"<span style='color:{colour}'>{body}</span>"
        self._show(text, colour, bold, f"<b>{body}</b>" if bold else body)

    def setText(self, text: str) -> None:  # noqa: N802 (Qt name): plain text, as a QLabel takes it
        self._show(text, None, False, text)

    def _show(self, plain: str, colour: str | None, bold: bool, shown: str) -> None:
        self._plain, self._colour, self._bold = plain, colour, bold
        super().setText(shown)
        if self.wordWrap():
            self.updateGeometry()  # its height follows the text
        self.changed()

    @property
    def plain(self) -> str:
        return self._plain

    def _metrics(self) -> QFontMetrics:
        font = self.font()
        font.setBold(self._bold)
        return QFontMetrics(font)

    def natural_width(self) -> int:
        return self._metrics().horizontalAdvance(self._plain) + 8 if self._plain else 0

    def minimumSizeHint(self) -> QSize:  # noqa: N802 (Qt name): may shrink to nothing
        return QSize(0, super().minimumSizeHint().height())

    def sizeHint(self) -> QSize:  # noqa: N802
        if self.wordWrap():
            return QSize(0, self.heightForWidth(max(self.width(), 1)))
        return QSize(self.natural_width(), super().sizeHint().height())

    def hasHeightForWidth(self) -> bool:  # noqa: N802
        return self.wordWrap()

    def heightForWidth(self, width: int) -> int:  # noqa: N802
        rect = self._metrics().boundingRect(0, 0, max(width - 4, 1), 100_000, int(Qt.TextWordWrap), self._plain)
        return rect.height() + 4

    def paintEvent(self, event) -> None:  # noqa: N802
        painter = QPainter(self)
        font = self.font()
        font.setBold(self._bold)
        painter.setFont(font)
        painter.setPen(QColor(self._colour) if self._colour else self.palette().windowText().color())
        if self.wordWrap():
            painter.drawText(self.rect().adjusted(2, 0, -2, 0), int(Qt.TextWordWrap | Qt.AlignTop | Qt.AlignLeft),
                             self._plain)
            return
        shown = painter.fontMetrics().elidedText(self._plain, Qt.ElideRight, max(self.width() - 4, 0))
        painter.drawText(self.rect().adjusted(2, 0, -2, 0), Qt.AlignVCenter | Qt.AlignLeft, shown)

    def shown_text(self) -> str:
        """What is drawn now (the text, cut to the width it has; all of it when wrapped)."""
        if self.wordWrap():
            return self._plain
        return self._metrics().elidedText(self._plain, Qt.ElideRight, max(self.width() - 4, 0))


def fit(bar: QStatusBar, labels: list[ElidedLabel]) -> None:
    """Give the bar's message its whole width, then ``labels`` (in priority order) what is left."""
    message = bar.currentMessage()
    room = bar.width() - GAP
    if message:
        room -= bar.fontMetrics().horizontalAdvance(message) + GAP
    for label in labels:
        want = label.natural_width()
        width = max(0, min(want, room))
        label.setMaximumWidth(width)
        label.setToolTip(label.plain if width < want else label.base_tip)
        room -= width
    bar.setToolTip(message)


class StatusLine(QObject):
    """Keeps ``labels`` (permanent widgets of ``bar``, in priority order) fitted around the message."""

    def __init__(self, bar: QStatusBar, labels: list[ElidedLabel]):
        super().__init__(bar)
        self.bar, self.labels = bar, labels
        for label in labels:
            bar.addPermanentWidget(label)
            label.changed = self.fit
        bar.messageChanged.connect(lambda _: self.fit())
        bar.installEventFilter(self)

    def fit(self) -> None:
        fit(self.bar, self.labels)

    def eventFilter(self, watched, event) -> bool:  # noqa: N802 (Qt name)
        if event.type() == QEvent.Resize:
            self.fit()
        return False
