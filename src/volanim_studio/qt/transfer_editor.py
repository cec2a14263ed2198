"""*View → Transfer function…*: the thesis's Icol, points on a histogram, colour and opacity, saved as ``.tf``.

    canvas (x: value over the histogram of what is shown, y: opacity; a dot per handle in its colour: a
            label's flat step, two points, is one dot -- model.transfer.handles)
        drag a dot --> doc.transfer.set(moved_handle(...), merge_key)   one undo step per drag (sealed on release)
        double-click empty --> with_point          double-click a dot / Colour… --> recoloured_handle
        right-click a dot / Delete / Remove point --> without_handle
        Open .tf… / Save .tf… / Mode's look (None: each mode draws as it did)
    doc.events.transfer --> redrawn (an undo from the main window shows here too)
    doc.events.preview --> the histogram of the new preview

Not modal: the preview follows every edit (``scene/pose_layer``), a View window opened after it and
*Render movie* use it. The histogram is of the full preview when there is one (a colour preview by its
luminance, as the function reads it), else of the scan.
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QPointF, QRectF, Qt
from PySide6.QtGui import QBrush, QColor, QPainter, QPen, QPolygonF
from PySide6.QtWidgets import (
    QColorDialog,
    QDialog,
    QFileDialog,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from volanim_core.volume import to_grey
from volanim_studio.model.transfer import (
    handle_of,
    handle_value,
    handles,
    moved_handle,
    recoloured_handle,
    with_point,
    without_handle,
)

MARGIN = 10  # pixels around the plot, so a dot at either end is whole
HIT = 8  # pixels: how near a click must be to take a dot
BINS = 256


def histogram(volume: np.ndarray | None) -> tuple[np.ndarray, float]:
    """Counts over ``BINS`` equal bins from 0 to the volume's maximum, and that maximum (255 with no volume)."""
    if volume is None or volume.size == 0:
        return np.zeros(BINS), 255.0
    if volume.ndim == 4:
        volume = to_grey(volume)
    top = max(float(volume.max()), 1.0)
    if volume.dtype.kind in "ub" and top < 65536:  # unsigned integers: bincount is 10x faster than histogram
        counts = np.bincount(volume.ravel(), minlength=int(top) + 1).astype(np.float64)
        bins = np.minimum(np.arange(len(counts)) * BINS // int(top), BINS - 1)  # numpy's bins, exactly
        return np.bincount(bins, weights=counts, minlength=BINS), top
    return np.histogram(volume, bins=BINS, range=(0.0, top))[0].astype(np.float64), top


class TransferCanvas(QWidget):
    """The function drawn over the histogram; mouse edits go to the editor."""

    def __init__(self, editor):
        super().__init__(editor)
        self.editor = editor
        self.setMinimumSize(480, 220)
        self.setFocusPolicy(Qt.StrongFocus)
        self._dragging: int | None = None

    # value / opacity <-> pixels
    def span(self) -> tuple[float, float]:
        tf, top = self.editor.function(), self.editor.top
        return min(0.0, float(tf.values[0])), max(top, float(tf.values[-1]))

    def to_pixel(self, value: float, opacity: float) -> QPointF:
        lo, hi = self.span()
        w, h = self.width() - 2 * MARGIN, self.height() - 2 * MARGIN
        return QPointF(MARGIN + (value - lo) / max(hi - lo, 1e-9) * w, MARGIN + (1 - opacity) * h)

    def to_value(self, x: float, y: float) -> tuple[float, float]:
        lo, hi = self.span()
        w, h = self.width() - 2 * MARGIN, self.height() - 2 * MARGIN
        return lo + (x - MARGIN) / max(w, 1) * (hi - lo), float(np.clip(1 - (y - MARGIN) / max(h, 1), 0, 1))

    def dots(self) -> list[QPointF]:
        """Where each handle (:func:`~volanim_studio.model.transfer.handles`) is drawn: a label's step as one."""
        tf = self.editor.function()
        return [self.to_pixel(handle_value(tf, h), tf.rgba[h[0], 3]) for h in handles(tf)]

    def point_at(self, x: float, y: float) -> int | None:
        """The handle under the pixel (x, y), or None."""
        d = [np.hypot(p.x() - x, p.y() - y) for p in self.dots()]
        i = int(np.argmin(d))
        return i if d[i] <= HIT else None

    def paintEvent(self, _event) -> None:
        tf, counts = self.editor.function(), self.editor.counts
        p = QPainter(self)
        p.setRenderHint(QPainter.Antialiasing)
        p.fillRect(self.rect(), QColor(30, 31, 36))
        w, h = self.width() - 2 * MARGIN, self.height() - 2 * MARGIN
        lo, hi = self.span()
        if counts.any():  # log counts: a few bright voxels still show beside a large background
            heights = np.log1p(counts) / np.log1p(counts.max())
            bar = w * self.editor.top / max(hi - lo, 1e-9) / len(counts)
            x0 = self.to_pixel(0.0, 0).x()
            p.setPen(Qt.NoPen)
            p.setBrush(QColor(90, 92, 100))
            for k, f in enumerate(heights):
                if f > 0:
                    p.drawRect(QRectF(x0 + k * bar, MARGIN + h * (1 - f), max(bar, 1.0), h * f))
        xs = np.linspace(lo, hi, max(w, 2))  # the colour strip along the bottom, at the function's opacity
        rgba = tf(xs)
        for k, c in enumerate(rgba):
            p.setPen(QColor.fromRgbF(c[0], c[1], c[2], max(c[3], 0.15)))
            px = MARGIN + k
            p.drawLine(QPointF(px, MARGIN + h + 2), QPointF(px, MARGIN + h + MARGIN - 1))
        line = [self.to_pixel(v, a) for v, a in zip(tf.values, tf.rgba[:, 3])]
        p.setPen(QPen(QColor(230, 230, 230), 1.5))
        p.drawPolyline(QPolygonF([self.to_pixel(lo, tf.rgba[0, 3])] + line + [self.to_pixel(hi, tf.rgba[-1, 3])]))
        for k, (dot, h) in enumerate(zip(self.dots(), handles(tf))):
            r, g, b = tf.rgba[h[0], :3]
            selected = k == self.editor.selected
            p.setPen(QPen(QColor(255, 210, 80) if selected else QColor(240, 240, 240), 2.5 if selected else 1.2))
            p.setBrush(QBrush(QColor.fromRgbF(r, g, b)))
            p.drawEllipse(dot, 5.5, 5.5)
        p.end()

    def mousePressEvent(self, event) -> None:
        pos = event.position()
        i = self.point_at(pos.x(), pos.y())
        self.editor.select(i)
        if i is not None and event.button() == Qt.RightButton:
            self.editor.remove()
        elif i is not None and event.button() == Qt.LeftButton:
            self._dragging = i

    def mouseMoveEvent(self, event) -> None:
        if self._dragging is not None:
            pos = event.position()
            self.editor.move(self._dragging, *self.to_value(pos.x(), pos.y()))

    def mouseReleaseEvent(self, _event) -> None:
        if self._dragging is not None:
            self._dragging = None
            self.editor.doc.undo.seal()  # the next drag is another undo step

    def mouseDoubleClickEvent(self, event) -> None:
        pos = event.position()
        i = self.point_at(pos.x(), pos.y())
        if i is None:
            self.editor.add(*self.to_value(pos.x(), pos.y()))
        else:
            self.editor.select(i)
            self.editor.choose_colour()

    def keyPressEvent(self, event) -> None:
        if event.key() in (Qt.Key_Delete, Qt.Key_Backspace):
            self.editor.remove()
        else:
            super().keyPressEvent(event)


class TransferEditor(QDialog):
    """The editor window; every edit is one undo step of the document (``doc.transfer``)."""

    def __init__(self, window):
        super().__init__(window)
        self.window_, self.doc = window, window.doc
        self.setWindowTitle("Transfer function")
        self.selected: int | None = None
        self.counts, self.top, self.mode = np.zeros(BINS), 255.0, "sampled"
        self.canvas = TransferCanvas(self)
        self.info = QLabel()
        buttons = QHBoxLayout()
        for text, slot, tip in (
                ("Colour…", self.choose_colour, "the colour of the selected point (or double-click it)"),
                ("Remove point", self.remove, "remove the selected point (or right-click it, or Delete)"),
                ("Open .tf…", self.open_dialog, "a transfer function file (volanim render --tf reads it too)"),
                ("Save .tf…", self.save_dialog, "this function as a .tf file"),
                ("Mode's look", self.reset, "no function of yours: each mode draws as it does by itself")):
            b = QPushButton(text)
            b.setToolTip(tip)
            b.clicked.connect(slot)
            buttons.addWidget(b)
        layout = QVBoxLayout(self)
        layout.addWidget(QLabel("Double-click to add a point, drag one to move it (up: more opaque), "
                                "double-click it for its colour, right-click to remove it."))
        layout.addWidget(self.canvas, 1)
        layout.addWidget(self.info)
        layout.addLayout(buttons)
        self.doc.events.transfer.connect(self._on_changed)
        self.doc.events.preview.connect(self._on_preview)

    # ---------------------------------------------------------------- state
    def function(self):
        return self.doc.transfer.current(self.mode, self.top)

    def _on_preview(self, **_) -> None:
        """The histogram (and the look a first edit starts from) of what is shown: the full preview, or the
        scan. Not while the editor is closed (it is counted again when shown), and not for a live preview
        (a drag's half-resolution stand-in, many a second: the full one follows its release)."""
        p = self.doc.preview
        if not self.isVisible() or (p is not None and p.live):
            return
        volume, self.mode = (p.reconstruction.volume, p.mode) if p is not None else (self.doc.volume, "sampled")
        self.counts, self.top = histogram(volume)
        self._on_changed()

    def showEvent(self, event) -> None:
        super().showEvent(event)
        self._on_preview()

    def _handle(self) -> tuple[int, ...] | None:
        """The selected handle's points (a label's step: both), or None."""
        hs = handles(self.function())
        return hs[self.selected] if self.selected is not None and self.selected < len(hs) else None

    def _on_changed(self, **_) -> None:
        tf = self.function()
        h = self._handle()
        if h is None:
            self.selected = None
            mine = ("yours" if self.doc.transfer.function is not None
                    else f"the {self.mode} look; edit it to make it yours")
            self.info.setText(f"{len(handles(tf))} points ({mine}); values 0..{self.top:g} shown")
        else:
            v, (r, g, b, a) = handle_value(tf, h), tf.rgba[h[0]]
            what = f"label {v:.4g}" if len(h) == 2 else f"value {v:.4g}"
            self.info.setText(f"point {self.selected + 1}: {what}, opacity {a:.2f}, "
                              f"colour {QColor.fromRgbF(r, g, b).name()}")
        self.canvas.update()

    def _set(self, tf, label: str, merge_key: str | None = None) -> None:
        self.doc.transfer.set(tf, label, merge_key)

    # ---------------------------------------------------------------- edits
    def select(self, i: int | None) -> None:
        self.selected = i
        self._on_changed()

    def add(self, value: float, opacity: float) -> None:
        try:
            tf, i = with_point(self.function(), value, opacity)
        except ValueError as exc:
            self.doc.message(str(exc))
            return
        self.selected = handle_of(tf, i)
        self._set(tf, "Add a transfer function point")

    def move(self, k: int, value: float, opacity: float) -> None:
        """Handle ``k`` to ``value`` and ``opacity`` (a label's step: both its points)."""
        self.selected = k
        h = self._handle()
        self._set(moved_handle(self.function(), h, value, opacity), "Move a transfer function point",
                  f"transfer:{k}")

    def remove(self) -> None:
        h = self._handle()
        if h is None:
            return
        try:
            tf = without_handle(self.function(), h)
        except ValueError as exc:
            self.doc.message(str(exc))
            return
        self.selected = None
        self._set(tf, "Remove a transfer function point")

    def colour(self, rgb) -> None:
        """Colour the selected handle ``rgb`` (0..1): a label's step, both its points."""
        h = self._handle()
        if h is not None:
            self._set(recoloured_handle(self.function(), h, rgb), "Colour a transfer function point")

    def choose_colour(self) -> None:
        h = self._handle()
        if h is None:
            self.doc.message("Click a point first, then choose its colour.")
            return
        r, g, b = self.function().rgba[h[0], :3]
        dialog = QColorDialog(QColor.fromRgbF(r, g, b), self)
        dialog.setOption(QColorDialog.DontUseNativeDialog, True)
        dialog.colorSelected.connect(lambda c: self.colour((c.redF(), c.greenF(), c.blueF())))
        self.colour_dialog = dialog
        dialog.open()

    def reset(self) -> None:
        self.selected = None
        self._set(None, "Transfer function: the mode's look")

    # ---------------------------------------------------------------- files
    def open_file(self, path) -> None:
        self.window_.files.attempt("Open transfer function", lambda: self.doc.transfer.load(path),
                                   f"Opened the transfer function {path}.")

    def save_file(self, path) -> None:
        self.window_.files.attempt("Save transfer function",
                                   lambda: self.doc.transfer.save(path, self.mode, self.top),
                                   f"Saved the transfer function to {path}.")

    def open_dialog(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self, "Open transfer function", self.window_.files.folder(),
                                              "Transfer functions (*.tf);;All files (*)")
        if path:
            self.open_file(path)

    def save_dialog(self) -> None:
        path, _ = QFileDialog.getSaveFileName(self, "Save transfer function", self.window_.files.folder("look.tf"),
                                              "Transfer functions (*.tf)")
        if path:
            self.save_file(path)
