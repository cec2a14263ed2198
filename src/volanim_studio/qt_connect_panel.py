"""The Connect tab: working bone, cube and lasso settings, auto-connect, mirror,
filters, and .connect save / reload."""

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

from .model.document import Document
from .model.modes import CubeMode, LassoMode
from .model.selection import DEPTH_MODES


class ConnectPanel(QWidget):
    def __init__(self, doc: Document, cube: CubeMode, lasso: LassoMode, parent=None):
        super().__init__(parent)
        self.doc, self.cube, self.lasso = doc, cube, lasso
        self.working = QLabel()
        self.working.setWordWrap(True)
        self.counts = QLabel()

        self.cube_size = QSlider(Qt.Horizontal)
        self.cube_size.setRange(1, 80)
        self.cube_size.setValue(int(doc.cube_size))
        self.cube_size_label = QLabel(f"{doc.cube_size:g}")
        self.cube_connect = QPushButton("Connect (C)")
        self.cube_remove = QPushButton("Remove (X)")

        self.depth_mode = QComboBox()
        self.depth_mode.addItems(DEPTH_MODES)
        self.depth_mode.setCurrentText(lasso.depth_mode)
        self.slab = QDoubleSpinBox(decimals=1, minimum=0.5, maximum=1000.0, singleStep=1.0)
        self.slab.setValue(lasso.slab)
        self.lasso_remove = QCheckBox("Remove instead of connect (or hold Ctrl)")

        self.scope = QComboBox()
        self.scope.addItems(["unconnected", "all", "selection"])
        self.overwrite = QCheckBox("Overwrite existing attachments")
        self.method = QComboBox()
        self.method.addItems(["path", "path-or-nearest", "nearest", "geodesic"])
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

        self.cube_size.valueChanged.connect(self._cube_size_changed)
        self.cube_connect.clicked.connect(lambda: cube.apply())
        self.cube_remove.clicked.connect(lambda: cube.apply(remove=True))
        self.depth_mode.currentTextChanged.connect(lambda t: setattr(lasso, "depth_mode", t))
        self.slab.valueChanged.connect(lambda v: setattr(lasso, "slab", v))
        self.lasso_remove.toggled.connect(lambda on: setattr(lasso, "remove", on))
        self.only_unconnected.toggled.connect(lambda on: doc.set_filter(only_unconnected=on))
        self.only_working.toggled.connect(lambda on: doc.set_filter(only_working=on))
        doc.events.selection.connect(self._refresh)
        doc.events.attachments.connect(self._refresh)
        doc.events.bones.connect(self._refresh)
        doc.events.thinness.connect(self._refresh)
        doc.events.filter.connect(self._on_filter_changed)
        self._refresh()

    def _cube_size_changed(self, value: int) -> None:
        self.cube_size_label.setText(str(value))
        self.doc.set_cube(self.doc.cube_centre, float(value))

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
