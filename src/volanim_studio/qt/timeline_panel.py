"""The timeline under the view: scrub, play, step, key. Widgets write the model; model events write them back.

    slider / frame box <--bind--> settings.current_frame
    doc.events.timeline --> range, key marks, labels
    buttons --> the TimelineController (wired by it: loading, playing, scanning, exporting)
"""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtGui import QColor, QPainter
from PySide6.QtWidgets import (
    QCheckBox,
    QDoubleSpinBox,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSlider,
    QSpinBox,
    QStyle,
    QStyleOptionSlider,
    QVBoxLayout,
    QWidget,
)

from ..model.document import Document
from .bindings import bind, write_back


class KeyedSlider(QSlider):
    """A frame slider that marks the keyed frames with small ticks."""

    def __init__(self):
        super().__init__(Qt.Horizontal)
        self.keys: list[int] = []

    def paintEvent(self, event):  # noqa: N802 (Qt name)
        super().paintEvent(event)
        if not self.keys or self.maximum() <= self.minimum():
            return
        opt = QStyleOptionSlider()
        self.initStyleOption(opt)
        groove = self.style().subControlRect(QStyle.CC_Slider, opt, QStyle.SC_SliderGroove, self)
        handle = self.style().subControlRect(QStyle.CC_Slider, opt, QStyle.SC_SliderHandle, self)
        span = groove.width() - handle.width()
        painter = QPainter(self)
        painter.setPen(QColor(230, 140, 20))
        painter.setBrush(QColor(230, 140, 20))
        for k in self.keys:
            x = groove.left() + handle.width() // 2 + QStyle.sliderPositionFromValue(
                self.minimum(), self.maximum(), k, span)
            painter.drawRect(x - 2, groove.bottom() - 3, 4, 6)
        painter.end()


class TimelinePanel(QWidget):

    def __init__(self, doc: Document, parent=None):
        super().__init__(parent)
        self.doc = doc
        tl = doc.timeline
        self.load_bvh = QPushButton("Load clip…")
        self.load_trans = QPushButton("Load .trans frames…")
        self.unload = QPushButton("Unload clip")
        self.first = QPushButton("|◀")
        self.back = QPushButton("◀")
        self.play = QPushButton("▶ Play")
        self.play.setCheckable(True)
        self.forward = QPushButton("▶")
        self.last = QPushButton("▶|")
        for b in (self.first, self.back, self.forward, self.last):
            b.setMaximumWidth(36)
        for b, tip in ((self.first, "First frame (Home)"), (self.back, "Previous frame (Left)"),
                       (self.play, "Play / pause at the clip's frame rate (Space)"),
                       (self.forward, "Next frame (Right)"), (self.last, "Last frame (End)")):
            b.setToolTip(tip)
        self.slider = KeyedSlider()
        self.frame = QSpinBox()
        self.info = QLabel()
        self.set_key = QPushButton("Set key")
        self.set_key.setToolTip("Key the current pose at this frame (S); undo with Ctrl+Z")
        self.delete_key = QPushButton("Delete key")
        self.delete_key.setToolTip("Delete the key at this frame (Shift+S)")
        self.keys_label = QLabel()
        self.ease = QCheckBox("Ease in/out")
        self.length = QSpinBox(minimum=1, maximum=100_000)
        self.length.setToolTip("Frames of the keyed animation")
        self.fps = QDoubleSpinBox(minimum=1.0, maximum=1000.0, decimals=1)
        self.fps.setToolTip("Frame rate of the keyed animation")
        self.scan = QPushButton("Scan clip for breakage…")
        self.export = QPushButton("Export frames (.trans)…")
        self.follow = QCheckBox("Follow the body")
        self.follow.setToolTip("As the clip plays or steps, the camera moves with the body (its direction and "
                               "distance kept), so a walk never leaves the view; movies do the same")
        self.movie = QPushButton("Render movie…")
        self.movie.setToolTip("Reconstruct the frames in the preview's mode and render them with this view's camera")

        top = QHBoxLayout()
        for w in (self.load_bvh, self.load_trans, self.unload, self.first, self.back, self.play, self.forward,
                  self.last):
            top.addWidget(w)
        top.addWidget(self.slider, 1)
        top.addWidget(self.frame)
        top.addWidget(self.info)
        bottom = QHBoxLayout()
        for w in (self.set_key, self.delete_key, self.keys_label):
            bottom.addWidget(w)
        bottom.addStretch(1)
        for w in (self.ease, QLabel("length"), self.length, QLabel("fps"), self.fps, self.follow, self.scan,
                  self.export, self.movie):
            bottom.addWidget(w)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(4, 2, 4, 2)
        layout.addLayout(top)
        layout.addLayout(bottom)

        bind(self.slider, doc.settings, "current_frame", on_error=doc.message)
        bind(self.frame, doc.settings, "current_frame", on_error=doc.message)
        bind(self.follow, doc.settings, "follow_body", on_error=doc.message)
        self.slider.sliderPressed.connect(lambda: setattr(doc.settings, "dragging", True))
        self.slider.sliderReleased.connect(lambda: setattr(doc.settings, "dragging", False))
        self.ease.toggled.connect(lambda on: self._option(ease=on))
        self.length.editingFinished.connect(lambda: self._option(length=self.length.value()))
        self.fps.editingFinished.connect(lambda: self._option(fps=self.fps.value()))
        self.unload.clicked.connect(tl.unload)
        doc.events.timeline.connect(lambda **_: self.refresh())
        doc.events.bones.connect(lambda **_: self.refresh())
        doc.settings.events.current_frame.connect(lambda **_: self._show_info())
        doc.events.preview.connect(lambda **_: self._show_info())  # playing: the frame the body shows
        self.refresh()

    def _option(self, **option) -> None:
        try:
            self.doc.timeline.set_options(**option)
        except ValueError as exc:
            self.doc.message(str(exc))
            self.refresh()

    def refresh(self) -> None:
        tl = self.doc.timeline
        last = max(tl.frame_count - 1, 0)
        for w in (self.slider, self.frame):
            write_back(w, lambda w=w: (w.setRange(0, last), w.setValue(min(self.doc.settings.current_frame, last))))
        self.slider.keys = sorted(tl.keys)
        self.slider.update()
        keyed = tl.clip is None
        for w in (self.set_key, self.delete_key, self.ease, self.length, self.fps):
            w.setEnabled(keyed and len(self.doc.bones) > 0)
        self.unload.setEnabled(tl.clip is not None)
        for w in (self.scan, self.export, self.play):
            w.setEnabled(tl.active)
        write_back(self.ease, lambda: self.ease.setChecked(tl.ease))
        write_back(self.length, lambda: self.length.setValue(tl.length))
        write_back(self.fps, lambda: self.fps.setValue(tl.fps))
        keys = sorted(tl.keys)
        self.keys_label.setText("keys: " + (", ".join(map(str, keys[:12])) + (" …" if len(keys) > 12 else "")
                                            if keys else "none (pose the bones, then Set key)"))
        self._show_info()

    def _show_info(self) -> None:
        tl = self.doc.timeline
        f = self.doc.settings.current_frame
        if tl.clip is not None:
            text = f"{tl.clip.name}: frame {tl.frame_number(f)} · {tl.frame_count} frames · {tl.frame_rate:.4g} fps"
        elif tl.keys:
            text = f"keyed: {tl.frame_count} frames · {tl.frame_rate:.4g} fps" + (" · key" if f in tl.keys else "")
        else:
            text = "no animation: load a clip (BVH, glTF, FBX) or .trans frames, or set keys"
        p = self.doc.preview
        if self.doc.settings.playing and p is not None and p.frame is not None and p.frame != f:
            # frames are dropped to keep up; the body and its bones are the same frame, which is said
            text += f" · body at {tl.frame_number(p.frame) if tl.clip is not None else p.frame}"
        self.info.setText(text)
