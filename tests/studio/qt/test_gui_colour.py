"""A colour volume in the studio: segmented on its luminance, its hull in its colours, the sampled
preview in colour (real widgets, real VTK)."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import Qt

from paths import ASSETS
from volanim_core import io, samples
from volanim_core.reconstruct.engine import reconstruct
from volanim_studio.model.modes import Mode

from ..conftest import JOB_TIMEOUT_MS

pytestmark = pytest.mark.gui


@pytest.fixture(scope="module")
def colour_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("colour") / "mannequin-colour.VOL"
    io.write_volume(path, samples.mannequin_colour().volume)
    return path


def test_a_colour_scan_is_posed_and_previewed_in_colour(qtbot, window, colour_file):
    w = window
    w.files.open_volume(colour_file, params={"lo": 1, "hi": None, "fill": False})
    qtbot.waitUntil(lambda: not w.busy, timeout=JOB_TIMEOUT_MS)
    assert w.doc.volume.shape == (*samples.MANNEQUIN_SHAPE, 3) and w.doc.shape == samples.MANNEQUIN_SHAPE
    assert np.array_equal(w.doc.mask, samples.mannequin().mask)  # segmented on luminance: the same body
    hull = w.scene.hull.actor.GetMapper().GetInput()
    rgb = np.asarray(hull.GetPointData().GetArray("rgb"))
    assert rgb.shape == (hull.GetNumberOfPoints(), 3)
    assert (rgb[:, 0].astype(int) - rgb[:, 2] > 40).mean() > 0.9  # warm skin, not the grey hull colour

    assert w.files.open_bones(ASSETS / "mannequin.bones")
    assert w.files.open_connect(ASSETS / "mannequin.0.50.connect")
    qtbot.keyClick(w, Qt.Key_P)
    assert w.mode == Mode.POSE
    w.doc.pose.set_angles(w.doc.bones.index("L_UPPERARM"), (0, -40, 0), merge=False)
    w.reconstruct_panel.mode.setCurrentText("sampled")
    w.previews.preview(report=False)
    qtbot.waitUntil(lambda: not w.busy and w.doc.preview is not None and w.doc.preview.mode == "sampled",
                    timeout=JOB_TIMEOUT_MS)
    got = w.doc.preview.reconstruction.volume
    want = reconstruct(w.doc.pose.tskel(), mode="sampled", source=w.doc.volume).volume
    assert got.shape[3] == 3 and np.array_equal(got, want)
    actor = w.scene.pose_layer.preview_actor
    assert actor is not None and actor.GetVisibility()
    assert not actor.GetProperty().GetIndependentComponents()  # RGB drawn as it is
    assert actor.GetMapper().GetInput().GetPointData().GetScalars().GetNumberOfComponents() == 4
    w.reconstruct_panel.slices.setChecked(True)
    assert "slices" in w.plotter.renderer.actors


def test_the_threshold_is_chosen_on_the_luminance(colour_file):
    from volanim_studio import tasks

    loaded = tasks.load_volume_file(str(colour_file))
    assert loaded["volume"].ndim == 4 and loaded["grey"].shape == samples.MANNEQUIN_SHAPE
    assert loaded["grey"].dtype == np.uint8 and loaded["grey"].max() > 100
