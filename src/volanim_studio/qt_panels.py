"""Side panels: display settings and the bone list. Widgets <-> model bindings
block their own signals while writing back, so nothing loops."""

from __future__ import annotations

from PySide6.QtCore import Qt, Signal
from PySide6.QtGui import QColor, QIcon, QPixmap
from PySide6.QtWidgets import (
    QAbstractItemView,
    QCheckBox,
    QComboBox,
    QDoubleSpinBox,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QSlider,
    QTreeWidget,
    QTreeWidgetItem,
    QVBoxLayout,
    QWidget,
)

from .model.document import Document
from .model.palette import bone_colour
from .qt_scene import SceneView

SLIDER_STEPS = 1000


class DisplayPanel(QWidget):
    """Thinness slider, cloud style, hull opacity/visibility and clipping."""

    def __init__(self, doc: Document, scene: SceneView, parent=None):
        super().__init__(parent)
        self.doc, self.scene = doc, scene
        self.thinness_slider = QSlider(Qt.Horizontal)
        self.thinness_slider.setRange(0, SLIDER_STEPS)
        self.thinness_spin = QDoubleSpinBox(decimals=3, singleStep=0.01)
        self.count_label = QLabel("no skeleton")
        self.point_size = QSlider(Qt.Horizontal)
        self.point_size.setRange(1, 30)
        self.point_size.setValue(int(scene.point_size))
        self.colour_by = QComboBox()
        self.colour_by.addItems(["thinness", "dt", "bone"])
        self.spheres = QCheckBox("Points as spheres")
        self.spheres.setChecked(scene.spheres)
        self.hull_visible = QCheckBox("Show hull")
        self.hull_visible.setChecked(True)
        self.hull_opacity = QSlider(Qt.Horizontal)
        self.hull_opacity.setRange(0, 100)
        self.hull_opacity.setValue(int(scene.hull_opacity * 100))
        self.clip_axis = QComboBox()
        self.clip_axis.addItems(["no clipping", "clip x", "clip y", "clip z"])
        self.clip_position = QSlider(Qt.Horizontal)
        self.clip_position.setRange(0, 100)
        self.clip_position.setValue(50)

        box = QGroupBox("Skeleton cloud")
        form = QFormLayout(box)
        row = QHBoxLayout()
        row.addWidget(self.thinness_slider)
        row.addWidget(self.thinness_spin)
        form.addRow("Thinness ≥", row)
        form.addRow("", self.count_label)
        form.addRow("Point size", self.point_size)
        form.addRow("Colour by", self.colour_by)
        form.addRow(self.spheres)
        hull = QGroupBox("Hull")
        hform = QFormLayout(hull)
        hform.addRow(self.hull_visible)
        hform.addRow("Opacity", self.hull_opacity)
        hform.addRow(self.clip_axis, self.clip_position)
        layout = QVBoxLayout(self)
        layout.addWidget(box)
        layout.addWidget(hull)
        layout.addStretch(1)

        self.thinness_slider.valueChanged.connect(self._slider_moved)
        self.thinness_slider.sliderPressed.connect(lambda: scene.set_dragging(True))
        self.thinness_slider.sliderReleased.connect(lambda: scene.set_dragging(False))
        self.thinness_spin.valueChanged.connect(self._spin_changed)
        self.point_size.valueChanged.connect(lambda v: scene.set_cloud_style(point_size=v))
        self.colour_by.currentTextChanged.connect(lambda t: scene.set_cloud_style(colour_by=t))
        self.spheres.toggled.connect(lambda on: scene.set_cloud_style(spheres=on))
        self.hull_visible.toggled.connect(lambda on: scene.set_hull(visible=on))
        self.hull_opacity.valueChanged.connect(lambda v: scene.set_hull(opacity=v / 100))
        self.clip_axis.currentIndexChanged.connect(
            lambda i: scene.set_hull(clip_axis=None if i == 0 else i - 1))
        self.clip_position.valueChanged.connect(lambda v: scene.set_hull(clip_position=v / 100))
        doc.events.skeleton.connect(self._on_skeleton_changed)
        doc.events.thinness.connect(self._on_thinness_changed)

    def _value_of(self, step: int) -> float:
        lo, hi = self.doc.thinness_range
        return lo + (hi - lo) * step / SLIDER_STEPS

    def _step_of(self, value: float) -> int:
        lo, hi = self.doc.thinness_range
        return 0 if hi <= lo else round((value - lo) / (hi - lo) * SLIDER_STEPS)

    def _slider_moved(self, step: int) -> None:
        self.doc.thinness = self._value_of(step)

    def _spin_changed(self, value: float) -> None:
        self.doc.thinness = value

    def _on_skeleton_changed(self, **_) -> None:
        lo, hi = self.doc.thinness_range
        self.thinness_spin.blockSignals(True)
        self.thinness_spin.setRange(lo, hi)
        self.thinness_spin.blockSignals(False)
        self._on_thinness_changed(value=self.doc.thinness)

    def _on_thinness_changed(self, value=None, **_) -> None:
        for w, v in ((self.thinness_slider, self._step_of(self.doc.thinness)), (self.thinness_spin, self.doc.thinness)):
            w.blockSignals(True)
            w.setValue(v)
            w.blockSignals(False)
        total = len(self.doc.skeleton) if self.doc.skeleton is not None else 0
        self.count_label.setText(f"{self.doc.visible_count} of {total} points shown")


class BoneTree(QTreeWidget):
    """Bones in root order: drag to reorder, double-click a name to rename."""

    reordered = Signal(list)

    def dropEvent(self, event):  # noqa: N802 (Qt name)
        super().dropEvent(event)
        order = [self.topLevelItem(i).data(0, Qt.UserRole) for i in range(self.topLevelItemCount())]
        self.reordered.emit(order)


class BonePanel(QWidget):
    """The bone list (root order, colour, name, joints) and the symmetry plane."""

    COLUMNS = ["#", "Bone", "Proximal", "Distal", "Points"]

    def __init__(self, doc: Document, parent=None):
        super().__init__(parent)
        self.doc = doc
        self.tree = BoneTree()
        self.tree.setColumnCount(len(self.COLUMNS))
        self.tree.setHeaderLabels(self.COLUMNS)
        self.tree.setRootIsDecorated(False)
        self.tree.setSelectionMode(QAbstractItemView.ExtendedSelection)
        self.tree.setDragDropMode(QAbstractItemView.InternalMove)
        self.tree.setEditTriggers(QAbstractItemView.DoubleClicked | QAbstractItemView.EditKeyPressed)
        self.tree.invisibleRootItem().setFlags(Qt.ItemIsDropEnabled | Qt.ItemIsEnabled)
        self.symmetry = QDoubleSpinBox(decimals=1, minimum=-1e5, maximum=1e5)
        self.unconnected = QLabel("")
        hint = QLabel("Name joints L_… / R_… so Symmetrize can mirror them. Drag rows to set the root order.")
        hint.setWordWrap(True)
        layout = QVBoxLayout(self)
        layout.addWidget(self.tree)
        layout.addWidget(self.unconnected)
        form = QFormLayout()
        form.addRow("Symmetry plane x =", self.symmetry)
        layout.addLayout(form)
        layout.addWidget(hint)
        self.tree.itemChanged.connect(self._item_edited)
        self.tree.itemSelectionChanged.connect(self._selection_edited)
        self.tree.reordered.connect(self._reordered)
        self.symmetry.valueChanged.connect(self._symmetry_edited)
        doc.events.bones.connect(self._on_bones_changed)
        doc.events.selection.connect(self._on_selection_changed)
        doc.events.symmetry.connect(self._on_symmetry_changed)
        doc.events.skeleton.connect(self._on_symmetry_changed)
        doc.events.attachments.connect(self._on_counts_changed)
        doc.events.thinness.connect(self._on_counts_changed)

    def _on_bones_changed(self, **_) -> None:
        self.tree.blockSignals(True)
        self.tree.clear()
        for i, b in enumerate(self.doc.bones.bones):
            item = QTreeWidgetItem([str(i), b.label, b.proximal, b.distal, ""])
            pix = QPixmap(14, 14)
            pix.fill(QColor(bone_colour(i)))
            item.setIcon(1, QIcon(pix))
            item.setData(0, Qt.UserRole, i)
            item.setFlags(Qt.ItemIsSelectable | Qt.ItemIsEnabled | Qt.ItemIsEditable | Qt.ItemIsDragEnabled)
            self.tree.addTopLevelItem(item)
        self.tree.blockSignals(False)
        self._on_counts_changed()
        for c in range(len(self.COLUMNS)):
            self.tree.resizeColumnToContents(c)
        self._on_selection_changed()

    def _on_counts_changed(self, **_) -> None:
        """Points attached per bone, and how many shown points are still unconnected."""
        if self.doc.skeleton is None:
            self.unconnected.setText("")
            return
        per_bone, unconnected = self.doc.attachments.counts()
        self.tree.blockSignals(True)
        for i in range(min(self.tree.topLevelItemCount(), len(per_bone))):
            self.tree.topLevelItem(i).setText(4, str(int(per_bone[i])))
        self.tree.blockSignals(False)
        self.unconnected.setText(f"{unconnected} of {self.doc.visible_count} shown points unconnected")

    def _on_selection_changed(self, **_) -> None:
        self.tree.blockSignals(True)
        for i in range(self.tree.topLevelItemCount()):
            self.tree.topLevelItem(i).setSelected(i in self.doc.selected_bones)
        self.tree.blockSignals(False)

    def _selection_edited(self) -> None:
        rows = [self.tree.indexOfTopLevelItem(it) for it in self.tree.selectedItems()]
        self.doc.select_bones(rows)

    def _item_edited(self, item: QTreeWidgetItem, column: int) -> None:
        row = self.tree.indexOfTopLevelItem(item)
        bone = self.doc.bones.bones[row]
        text = item.text(column)
        try:
            if column == 1 and text != bone.label:
                self.doc.rename_bone(row, "" if text == f"{bone.proximal}-{bone.distal}" else text)
            elif column in (2, 3):
                old = bone.proximal if column == 2 else bone.distal
                if text != old:
                    self.doc.rename_joint(old, text)
            else:
                self._on_bones_changed()
        except ValueError as exc:
            self.doc.message(str(exc))
            self._on_bones_changed()

    def _reordered(self, order: list) -> None:
        self.doc.set_root_order(order)
        self._on_bones_changed()

    def _symmetry_edited(self, value: float) -> None:
        self.doc.symmetry_x = value

    def _on_symmetry_changed(self, **_) -> None:
        self.symmetry.blockSignals(True)
        self.symmetry.setValue(self.doc.symmetry_x)
        self.symmetry.blockSignals(False)
