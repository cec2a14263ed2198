"""The Bones tab: the bone list (root order, colour, name, joints, points) and the symmetry plane.

Edits go to ``doc.bone_edits`` (undoable); bone events rebuild the list with
its signals blocked."""

from __future__ import annotations

from PySide6.QtCore import Qt, Signal
from PySide6.QtGui import QColor, QIcon, QPixmap
from PySide6.QtWidgets import (
    QAbstractItemView,
    QDoubleSpinBox,
    QFormLayout,
    QLabel,
    QTreeWidget,
    QTreeWidgetItem,
    QVBoxLayout,
    QWidget,
)

from volanim_core.render.bone_colours import bone_colour

from ..model.document import Document


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
        # an item names its bone (its index in doc.bones when the list was drawn), not its row: a drop moves
        # rows, and selects, before the reorder reaches the model (#61: HEAD became L_UPPERARM)
        self.doc.select_bones([it.data(0, Qt.UserRole) for it in self.tree.selectedItems()])

    def _item_edited(self, item: QTreeWidgetItem, column: int) -> None:
        row = item.data(0, Qt.UserRole)
        bone = self.doc.bones.bones[row]
        text = item.text(column)
        try:
            if column == 1 and text != bone.label:
                self.doc.bone_edits.rename_bone(row, "" if text == f"{bone.proximal}-{bone.distal}" else text)
            elif column in (2, 3):
                old = bone.proximal if column == 2 else bone.distal
                if text != old:
                    self.doc.bone_edits.rename_joint(old, text)
            else:
                self._on_bones_changed()
        except ValueError as exc:
            self.doc.message(str(exc))
            self._on_bones_changed()

    def _reordered(self, order: list) -> None:
        self.doc.bone_edits.set_root_order(order)
        self._on_bones_changed()

    def _symmetry_edited(self, value: float) -> None:
        self.doc.symmetry_x = value

    def _on_symmetry_changed(self, **_) -> None:
        self.symmetry.blockSignals(True)
        self.symmetry.setValue(self.doc.symmetry_x)
        self.symmetry.blockSignals(False)
