"""The Reconstruct tab: preview settings (bound both ways to ``doc.settings``), compare,
slices, export, and the breakage report of the last full preview."""

from __future__ import annotations

from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDoubleSpinBox,
    QFormLayout,
    QGroupBox,
    QLabel,
    QListWidget,
    QListWidgetItem,
    QPushButton,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from ..model.document import Document
from ..model.live_resolution import CHOICES as LIVE_CHOICES
from ..model.settings import PREVIEW_MODES
from .bindings import bind
from .verdict_label import verdict_html


class ReconstructPanel(QWidget):
    """Preview settings, the compare toggle, export, and the breakage report."""

    joint_clicked = Signal(str)
    fix_lump = Signal(int)  # the lump's place in the shown report's lumps

    def __init__(self, doc: Document, parent=None):
        super().__init__(parent)
        self.doc = doc
        self.mode = QComboBox()
        self.mode.addItems(PREVIEW_MODES)
        self.kernel = QComboBox()
        self.kernel.addItems(["1", "3", "5"])
        self.padding = QSpinBox(minimum=0, maximum=64)
        self.joint_kind = QComboBox()
        self.joint_kind.addItems(["rigid", "smooth"])
        self.joint_kind.setToolTip("rigid: each skeleton point follows its bone (a bent joint may crack);\n"
                                   "smooth: points near a joint blend the two bones' motions (dual quaternions),\n"
                                   "so shoulders, hips, elbows and knees bend without breaking")
        self.body = QComboBox()
        self.body.addItems(["owned", "spheres"])
        self.body.setToolTip("owned: each voxel of the volume moves with the bone that owns it, joints closed by\n"
                             "balls (the default; needs the volume); spheres: the thesis's re-growth from the\n"
                             "skeleton points")
        self.blend = QDoubleSpinBox(minimum=0.1, maximum=10.0, singleStep=0.25, decimals=2)
        self.blend.setToolTip("smooth joints: how far from a joint the blend reaches, times the bones' thickness")
        self.live = QCheckBox("Live preview while posing")
        self.live.setToolTip("A picture as a pose slider moves or the timeline plays: only what moved redone")
        self.live_resolution = QComboBox()
        self.live_resolution.addItems(LIVE_CHOICES)
        self.live_resolution.setToolTip("auto: the resolution that keeps 10 live pictures a second (it says which);\n"
                                        "full, half, quarter: always that one. Releasing draws full size.")
        self.slices = QCheckBox("Orthogonal slices")
        self.show_rest = QCheckBox("Show the rest pose instead (compare)")
        s = doc.settings
        for widget, name, conv in ((self.mode, "preview_mode", None), (self.kernel, "preview_kernel", int),
                                   (self.padding, "preview_padding", None), (self.live, "live_preview", None),
                                   (self.live_resolution, "live_resolution", None),
                                   (self.slices, "slices", None), (self.show_rest, "show_rest", None),
                                   (self.joint_kind, "joints", None), (self.blend, "blend", None),
                                   (self.body, "body", None)):
            bind(widget, s, name, to_value=conv, on_error=doc.message)
        self.metric_label = QLabel("euclid")
        self.metric_label.setToolTip("The distance metric of the skeleton's DT (set when skeletonizing); "
                                     "radii are in it")
        self.preview_button = QPushButton("Preview")
        self.export_button = QPushButton("Export volume…")
        self.report = QLabel("No preview yet.")
        self.report.setWordWrap(True)
        self.joints = QListWidget()
        settings = QGroupBox("Reconstruction")
        form = QFormLayout(settings)
        form.addRow("Body", self.body)
        form.addRow("Mode", self.mode)
        form.addRow("Kernel (sampled)", self.kernel)
        form.addRow("Padding", self.padding)
        form.addRow("Joints", self.joint_kind)
        form.addRow("Blend (× bone thickness)", self.blend)
        form.addRow("Metric (from the skeleton)", self.metric_label)
        form.addRow(self.live)
        form.addRow("Live resolution", self.live_resolution)
        form.addRow(self.preview_button)
        view = QGroupBox("View")
        vl = QVBoxLayout(view)
        vl.addWidget(self.show_rest)
        vl.addWidget(self.slices)
        vl.addWidget(self.export_button)
        report = QGroupBox("Breakage report")
        rl = QVBoxLayout(report)
        rl.addWidget(self.report)
        rl.addWidget(QLabel("Breakage gathers near (click to go there):"))
        rl.addWidget(self.joints)
        self.fix_button = QPushButton("Fix lump: give its flesh to the bone it belongs to")
        self.fix_button.setToolTip("Repaints ownership: the rest voxels the selected lump was made of go to the\n"
                                   "bone whose flesh it is (one undo step), then the preview is made again")
        self.fix_button.setEnabled(False)
        rl.addWidget(self.fix_button)
        layout = QVBoxLayout(self)
        for w in (settings, view, report):
            layout.addWidget(w)
        self.joints.itemClicked.connect(lambda item: self.joint_clicked.emit(item.data(Qt.UserRole)))
        self.joints.currentItemChanged.connect(
            lambda item, _old: self.fix_button.setEnabled(item is not None and item.data(Qt.UserRole + 1) is not None))
        self.fix_button.clicked.connect(self._fix_clicked)
        doc.events.skeleton.connect(
            lambda **_: self.metric_label.setText(doc.skeleton.metric if doc.skeleton is not None else "euclid"))
        doc.events.preview.connect(self._on_preview_changed)
        s.events.joints.connect(lambda value: self.blend.setEnabled(value == "smooth"))
        self.blend.setEnabled(s.joints == "smooth")

    def _fix_clicked(self) -> None:
        item = self.joints.currentItem()
        if item is not None and item.data(Qt.UserRole + 1) is not None:
            self.fix_lump.emit(int(item.data(Qt.UserRole + 1)))

    def _on_preview_changed(self, **_) -> None:
        p = self.doc.preview
        if p is None or p.report is None:
            return
        r = p.report
        self.report.setText(verdict_html(r) + "<br>" + "<br>".join(r.lines()))
        self.joints.clear()
        self.fix_button.setEnabled(False)
        for size, joint, _ in r.pieces:
            item = QListWidgetItem(f"torn-off piece: {size} voxels near {joint}")
            item.setData(Qt.UserRole, joint)
            self.joints.addItem(item)
        for s in r.stumps:
            item = QListWidgetItem(f"stump: {s.points} points of {s.attached} near {s.joint} "
                                   f"(connect them to {s.lies_along})")
            item.setData(Qt.UserRole, s.joint)
            self.joints.addItem(item)
        for k, lump in enumerate(r.lumps):
            item = QListWidgetItem(f"lump: {lump.voxels:,} voxels of {lump.whose} carried off near {lump.near}"
                                   f"{lump.by}{lump.fix}")
            item.setData(Qt.UserRole, lump.near)
            if lump.belongs_to:
                item.setData(Qt.UserRole + 1, k)  # Fix can act on it
            self.joints.addItem(item)
        total = max(sum(j.gap for j in r.joints), 1e-9)
        for j in r.joints:
            item = QListWidgetItem(f"{j.name}: {j.lost} cracks ({100 * j.gap / total:.0f} % of the opening)")
            item.setData(Qt.UserRole, j.name)
            self.joints.addItem(item)
