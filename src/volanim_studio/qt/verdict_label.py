"""The breakage verdict of the last full preview, shown where the user looks (status bar, Pose tab).

    doc.events.preview (with a report) --> the verdict, coloured
    doc.events.preview (a full preview, its report still being made) --> "Checking for breakage…", greyed
    doc.events.stale --> the same words, greyed, naming what changed since: the pose, the attachments, the
                         bones, the clip or keys, the transfer function, ... (F5 checks again)
"""

from __future__ import annotations

from ..model.document import Document
from .status_line import ElidedLabel

CHECKING = "Checking the pose for breakage…"
COLOURS = {"healthy": "#2e9d4f", "lump": "#d9861a", "broken": "#d33c3c", "stale": "#8a8a8a"}


def verdict_colour(report) -> str:
    """Green when healthy; amber for a lump or a rest pose in more pieces than the volume (#83: both were
    green); red for pieces or a stump."""
    return COLOURS["broken" if not report.healthy else "lump" if report.lumps or report.shredded else "healthy"]


def verdict_html(report) -> str:
    """The report's verdict in its colour."""
    return f"<b style='color:{verdict_colour(report)}'>{report.verdict}</b>"


class VerdictLabel(ElidedLabel):
    def __init__(self, doc: Document, parent=None):
        super().__init__(parent)
        self.doc = doc
        self._report = None
        self._checking = False  # a full preview is shown and its report is being made
        self.base_tip = ("The breakage verdict of the last full preview (F5); the Reconstruct tab has the report.")
        self.setToolTip(self.base_tip)
        doc.events.preview.connect(self._on_preview)
        doc.events.stale.connect(self._on_stale)

    def _on_preview(self, **_) -> None:
        p = self.doc.preview
        if p is None:
            self._report, self._checking = None, False
            self.setText("")
        elif p.report is not None:
            self._report, self._checking = p.report, False
            if self.doc.preview_is_current:
                self.set_styled(p.report.verdict, verdict_colour(p.report), bold=True)
            else:  # a job that ended after a change: its verdict is of what was
                self._show_stale(self.doc.picture_change)
        elif not p.live:  # the picture is shown, its report follows (a background job): no old verdict meanwhile
            self._report, self._checking = None, True
            self.set_styled(CHECKING, COLOURS["stale"])
        elif p.stages is not None:  # dragging or playing: at what resolution, and what each picture costs
            self.set_styled(live_text(p), COLOURS["stale"])

    def _on_stale(self, what: str, **_) -> None:
        if self._checking:  # that check is of what was: cancelled or soon old
            self._checking = False
            self.setText("")
        elif self._report is not None:
            self._show_stale(what)

    def _show_stale(self, what: str | None) -> None:
        self.set_styled(f"{self._report.verdict} (before the last change of {what or 'the session'}: "
                        "F5 checks again)", COLOURS["stale"])


def live_text(p) -> str:
    """What a live picture says while the pose moves (#85): its resolution and its cost by stage, in ms."""
    size = "full size" if p.factor == 1 else f"1/{p.factor}"
    ms = {k: round(1000 * v) for k, v in p.stages.items()}
    parts = [f"pose {ms['pose']}", f"body {ms['body']}", f"surface {ms['surface']}"]
    if "last draw" in ms:
        parts.append(f"draw {ms['last draw']}")
    return f"Live at {size}: " + ", ".join(parts) + " ms (release for the full picture and its verdict)"
