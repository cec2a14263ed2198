"""The breakage verdict of the last full preview, shown where the user looks (status bar, Pose tab).

    doc.events.preview (with a report) --> the verdict, coloured
    doc.events.preview (a full preview, its report still being made) --> "Checking for breakage…", greyed
    doc.events.pose --> the same words, greyed: the pose changed since (F5 checks again)
"""

from __future__ import annotations

from ..model.document import Document
from .status_line import ElidedLabel

CHECKING = "Checking the pose for breakage…"
COLOURS = {"healthy": "#2e9d4f", "broken": "#d33c3c", "stale": "#8a8a8a"}


def verdict_html(report) -> str:
    """The report's verdict in colour: green when healthy, red for pieces or a stump."""
    colour = COLOURS["healthy" if report.healthy else "broken"]
    return f"<b style='color:{colour}'>{report.verdict}</b>"


class VerdictLabel(ElidedLabel):
    def __init__(self, doc: Document, parent=None):
        super().__init__(parent)
        self.doc = doc
        self._report = None
        self._checking = False  # a full preview is shown and its report is being made
        self.base_tip = ("The breakage verdict of the last full preview (F5); the Reconstruct tab has the report.")
        self.setToolTip(self.base_tip)
        doc.events.preview.connect(self._on_preview)
        doc.events.pose.connect(self._on_pose)

    def _on_preview(self, **_) -> None:
        p = self.doc.preview
        if p is None:
            self._report, self._checking = None, False
            self.setText("")
        elif p.report is not None:
            self._report, self._checking = p.report, False
            self.set_styled(p.report.verdict, COLOURS["healthy" if p.report.healthy else "broken"], bold=True)
        elif not p.live:  # the picture is shown, its report follows (a background job): no old verdict meanwhile
            self._report, self._checking = None, True
            self.set_styled(CHECKING, COLOURS["stale"])

    def _on_pose(self, **_) -> None:
        if self._checking:  # that check is cancelled: the pose it was of is gone
            self._checking = False
            self.setText("")
        elif self._report is not None:
            self.set_styled(f"{self._report.verdict} (before the last pose change: F5 checks again)",
                            COLOURS["stale"])
