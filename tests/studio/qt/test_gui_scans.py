"""Scans as they arrive, in the studio (#35): a DICOM series, a Slicer segmentation's names, NaN voxels."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core import io
from volanim_core.geometry import Geometry
from volanim_core.io.dicom_files import write_dicom_series

from ..conftest import JOB_TIMEOUT_MS

pytestmark = pytest.mark.gui

CT = Geometry((0.7, 0.7, 2.1), (-56.0, -35.0, -1150.0))


@pytest.fixture
def ct_series(tmp_path):
    hu = np.full((40, 30, 12), -1000, np.int16)
    hu[8:32, 6:24, 2:10] = 40
    hu[16:24, 12:18, 2:10] = 700
    write_dicom_series(tmp_path / "ct", hu, CT)
    return tmp_path / "ct", hu


def test_one_file_of_a_dicom_series_opens_the_series_on_cubes_in_scanner_space(qtbot, ct_series):
    from volanim_studio.qt.main_window import MainWindow

    folder, hu = ct_series
    w = MainWindow()
    qtbot.addWidget(w)
    one_file = sorted(folder.iterdir())[5]
    w.files.open_volume(w.files._dicom_series_folder(str(one_file)),
                        params={"lo": -300, "hi": 3000, "fill": False, "metric": "euclid", "min_thinness": 0.5})
    qtbot.waitUntil(lambda: not w.busy, timeout=JOB_TIMEOUT_MS)
    assert w.last_error is None
    g = w.doc.skeleton.geometry
    assert g.spacing == (0.7, 0.7, 0.7) and np.allclose(g.origin, CT.origin)  # cubes, where the scanner put it
    assert w.doc.volume.shape == (40, 30, 34)  # 12 slices 2.1 mm apart: 34 cubes of 0.7 mm
    assert w.doc.volume.dtype == np.int16 and w.doc.volume.max() == 700  # Hounsfield units, the CT's own
    w.doc.pick_point(0)
    where = g.to_physical(w.doc.skeleton.points[:1])[0]
    assert f"({where[0]:.1f}, {where[1]:.1f}, {where[2]:.1f}) mm" in w.point_label.text()
    assert any(a.text().startswith("Open &DICOM folder") for a in w.menuBar().actions()[0].menu().actions())
    w.close()


def test_the_threshold_dialog_offers_a_segmentations_names(qtbot, tmp_path):
    from volanim_studio import tasks
    from volanim_studio.qt.threshold_dialog import ThresholdDialog

    layers = np.zeros((1, 6, 5, 4), np.uint8)
    layers[0, 1:3] = 1
    layers[0, 3:5] = 2
    header = ("NRRD0004\ntype: uchar\ndimension: 4\nsizes: 1 6 5 4\nkinds: list domain domain domain\n"
              "encoding: raw\nSegment0_Name:=Liver\nSegment0_LabelValue:=1\nSegment1_Name:=Spleen\n"
              "Segment1_LabelValue:=2\n\n")
    path = tmp_path / "organs.seg.nrrd"
    path.write_bytes(header.encode() + np.ascontiguousarray(layers.transpose(3, 2, 1, 0)).tobytes())
    loaded = tasks.load_volume_file(str(path))
    dialog = ThresholdDialog(loaded["grey"], path.name, segments=loaded["segments"])
    qtbot.addWidget(dialog)
    names = [dialog.segment_box.itemText(i) for i in range(dialog.segment_box.count())]
    assert names == ["(a value range)", "Liver (1)", "Spleen (2)"]
    dialog.segment_box.setCurrentIndex(2)
    p = dialog.parameters()
    assert (p["lo"], p["hi"], p["fill"]) == (2.0, 2.0, False)


def test_the_threshold_dialog_on_an_mri_with_nan(qtbot, tmp_path):
    """A resampled MRI's NaN voxels made the dialog's range and histogram NaN."""
    from volanim_studio.qt.threshold_dialog import ThresholdDialog

    vol = np.linspace(0, 100, 6 * 5 * 4, dtype=np.float32).reshape(6, 5, 4)
    vol[0] = np.nan
    io.write_volume(tmp_path / "mri.nii", vol, Geometry((1, 1, 1)))
    dialog = ThresholdDialog(io.read_volume(tmp_path / "mri.nii"), "mri.nii")
    qtbot.addWidget(dialog)
    assert dialog.hi.maximum() == pytest.approx(100.0) and dialog.lo.minimum() > 0
    assert np.isfinite(dialog.histogram.counts).all() and np.count_nonzero(dialog.histogram.counts) > 50


def test_a_folder_of_two_series_asks_which_and_the_project_remembers(qtbot, tmp_path, monkeypatch):
    from PySide6.QtWidgets import QInputDialog

    from volanim_studio.qt.main_window import MainWindow

    hu = np.full((20, 16, 6), -1000, np.int16)
    hu[4:16, 4:12, 1:5] = 40
    write_dicom_series(tmp_path / "two", hu, CT, series_uid="1.2.3.1", description="body")
    write_dicom_series(tmp_path / "two", np.where(hu > 0, 300, hu).astype(np.int16), CT, series_uid="1.2.3.2",
                       description="contrast", names=[f"B{k}.dcm" for k in range(6)])
    offered = []

    def pick_contrast(parent, title, label, items, current, editable):  # Qt's modal dialog, answered
        offered.extend(items)
        return next(i for i in items if "contrast" in i), True

    monkeypatch.setattr(QInputDialog, "getItem", staticmethod(pick_contrast))
    w = MainWindow()
    qtbot.addWidget(w)
    w.files.open_volume(tmp_path / "two", params={"lo": -300, "hi": 3000, "fill": False, "metric": "euclid",
                                                  "min_thinness": 0.5})
    qtbot.waitUntil(lambda: not w.busy, timeout=JOB_TIMEOUT_MS)
    assert len(offered) == 2 and any("body" in i for i in offered)
    assert w.doc.volume.max() == 300 and w.doc.segmentation["series"] == "1.2.3.2"
    w.close()
