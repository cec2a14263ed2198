"""The Connect tab: working bone, cube and lasso settings, auto-connect options, mirror,
filters. Tool settings are bound both ways to ``doc.settings`` (the +/- keys and the
cube-size slider show the same value)."""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDoubleSpinBox,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSlider,
    QVBoxLayout,
    QWidget,
)

from ..model.attachments import WHOLE_BODY_METHODS
from ..model.document import Document
from ..model.interaction import CubeMode
from ..model.settings import AUTO_METHODS, AUTO_SCOPES, DEPTH_MODES
from .bindings import bind


class ConnectPanel(QWidget):
    def __init__(self, doc: Document, cube: CubeMode, parent=None):
        super().__init__(parent)
        self.doc, self.cube = doc, cube
        self.working = QLabel()
        self.working.setWordWrap(True)
        self.counts = QLabel()

        self.cube_size = QSlider(Qt.Horizontal)
        self.cube_size.setRange(1, 200)
        self.cube_size_label = QLabel()
        self.cube_count = QLabel("click a point to place it")
        self.cube_connect = QPushButton("Connect (C)")
        self.cube_remove = QPushButton("Remove (X)")

        self.depth_mode = QComboBox()
        self.depth_mode.addItems(DEPTH_MODES)
        self.slab = QDoubleSpinBox(decimals=1, minimum=0.5, maximum=1000.0, singleStep=1.0)
        self.lasso_remove = QCheckBox("Remove instead of connect (or hold Ctrl)")

        self.scope = QComboBox()
        self.scope.addItems(AUTO_SCOPES)
        self.overwrite = QCheckBox("Overwrite existing attachments")
        self.method = QComboBox()
        self.method.addItems(AUTO_METHODS)
        self.auto_button = QPushButton("Auto-connect")
        self.mirror_button = QPushButton("Mirror selected L_/R_ bones")
        self.only_unconnected = QCheckBox("Show only unconnected points")
        self.only_working = QCheckBox("Show only the working bone's points")

        working = QGroupBox("Working bone")
        QVBoxLayout(working).addWidget(self.working)
        working.layout().addWidget(self.counts)
        cube_box = QGroupBox("Cube (K)")
        cf = QFormLayout(cube_box)
        row = QHBoxLayout()
        row.addWidget(self.cube_size)
        row.addWidget(self.cube_size_label)
        cf.addRow("Size", row)
        cf.addRow("Inside", self.cube_count)
        buttons = QHBoxLayout()
        buttons.addWidget(self.cube_connect)
        buttons.addWidget(self.cube_remove)
        cf.addRow(buttons)
        lasso_box = QGroupBox("Lasso (L)")
        lf = QFormLayout(lasso_box)
        lf.addRow("Depth", self.depth_mode)
        lf.addRow("Slab depth", self.slab)
        lf.addRow(self.lasso_remove)
        auto_box = QGroupBox("Auto-connect")
        af = QFormLayout(auto_box)
        af.addRow("Points", self.scope)
        af.addRow("Method", self.method)
        af.addRow(self.overwrite)
        af.addRow(self.auto_button)
        af.addRow(self.mirror_button)
        show_box = QGroupBox("Show")
        sf = QVBoxLayout(show_box)
        sf.addWidget(self.only_unconnected)
        sf.addWidget(self.only_working)
        layout = QVBoxLayout(self)
        for w in (working, cube_box, lasso_box, auto_box, show_box):
            layout.addWidget(w)
        layout.addStretch(1)

        st = doc.settings
        for widget, name in ((self.cube_size, "cube_size"), (self.depth_mode, "lasso_depth"),
                             (self.slab, "lasso_slab"), (self.lasso_remove, "lasso_remove"),
                             (self.scope, "auto_scope"), (self.method, "auto_method"),
                             (self.overwrite, "auto_overwrite")):
            bind(widget, st, name, on_error=doc.message)
        st.events.cube_size.connect(self._on_cube_size_changed)
        st.events.auto_method.connect(lambda **_: self._on_method())
        st.events.auto_scope.connect(lambda **_: self._on_method())
        self._on_method()
        st.events.cube_size.connect(self._count_cube)
        for event in (doc.events.cube, doc.events.thinness, doc.events.filter, doc.events.attachments,
                      doc.events.skeleton):
            event.connect(self._count_cube)
        self._on_cube_size_changed(st.cube_size)
        self.cube_connect.clicked.connect(lambda: cube.apply())
        self.cube_remove.clicked.connect(lambda: cube.apply(remove=True))
        self.only_unconnected.toggled.connect(lambda on: doc.set_filter(only_unconnected=on))
        self.only_working.toggled.connect(lambda on: doc.set_filter(only_working=on))
        doc.events.selection.connect(self._refresh)
        doc.events.attachments.connect(self._refresh)
        doc.events.bones.connect(self._refresh)
        doc.events.thinness.connect(self._refresh)
        doc.events.filter.connect(self._on_filter_changed)
        self._refresh()

    def _on_method(self) -> None:
        """A whole-body method takes every shown point and may replace attachments: Overwrite is not asked
        (greyed, with why), and Points offers the choice that matters, all or the selection."""
        st = self.doc.settings
        whole = st.auto_method in WHOLE_BODY_METHODS
        self.overwrite.setEnabled(not whole)
        self.overwrite.setToolTip(f"{st.auto_method} decides every shown point from the whole rig: it replaces "
                                  "attachments whatever this says" if whole else
                                  "auto-connect may replace existing attachments")
        self.scope.setToolTip(f"{st.auto_method}: every shown point unless Points is the selection" if whole
                              else "which points auto-connect considers")

    def _on_cube_size_changed(self, value: float, **_) -> None:
        self.cube_size_label.setText(f"{value:g}")

    def _count_cube(self, **_) -> None:
        """How many shown points the cube holds, and how many of them are connected already."""
        if self.doc.cube_centre is None or self.doc.skeleton is None:
            self.cube_count.setText("click a point to place it")
            return
        inside = self.cube.inside()
        done = int((self.doc.attachments.bone[inside] >= 0).sum())
        self.cube_count.setText(f"{len(inside)} shown points ({done} connected already)")

    def _on_filter_changed(self, **_) -> None:
        for box, on in ((self.only_unconnected, self.doc.only_unconnected), (self.only_working, self.doc.only_working)):
            box.blockSignals(True)
            box.setChecked(on)
            box.blockSignals(False)

    def _refresh(self, **_) -> None:
        w = self.doc.working_bone
        self.working.setText("none — click a bone in the view or the Bones list" if w is None
                             else f"<b>{self.doc.bones.bones[w].label}</b> (root {w})")
        if self.doc.skeleton is None:
            self.counts.setText("")
            return
        per_bone, unconnected = self.doc.attachments.counts()
        on_working = int(per_bone[w]) if w is not None and w < len(per_bone) else 0
        self.counts.setText(f"{on_working} points on it · {unconnected} shown points unconnected")
