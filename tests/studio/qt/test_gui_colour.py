"""A colour volume in the studio: segmented on its luminance, its hull in its colours, the sampled
preview in colour (real widgets, real VTK)."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import Qt

from paths import ASSETS
from volanim_core import io, samples
from volanim_core.reconstruct.engine import reconstruct
from volanim_studio.model.interaction import Mode

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
    owned = w.doc.ownership.attach(w.doc.pose.tskel())  # the default body (#84)
    want = reconstruct(owned, mode="sampled", source=w.doc.volume).volume
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


# full tier only, so that make test stays under 10 minutes: a colour movie rendered by worker processes
@pytest.mark.slow
def test_the_colour_body_s_movie_is_in_colour(qtbot, window, colour_file, tmp_path):
    """#61 item 7: the movie sampled the colour volume's luminance (grey) while the preview showed colours;
    now the sequence holds palette indices and the movie draws the palette's colours."""
    import imageio.v3 as iio

    w = window
    w.files.open_volume(colour_file, params={"lo": 1, "hi": None, "fill": False})
    qtbot.waitUntil(lambda: not w.busy, timeout=JOB_TIMEOUT_MS)
    assert w.files.open_bones(ASSETS / "mannequin.bones")
    assert w.files.open_connect(ASSETS / "mannequin.0.50.connect")
    w.timeline_panel.length.setValue(2)
    w.timeline_panel.length.editingFinished.emit()
    qtbot.keyClick(w, Qt.Key_S)  # a key at frame 0, and one with the arm raised at frame 1
    w.doc.settings.current_frame = 1
    w.doc.pose.set_angles(w.doc.bones.index("L_UPPERARM"), (0, -60, 0))
    w.timeline_panel.set_key.click()
    w.doc.settings.preview_mode = "sampled"
    w.doc.settings.preview_kernel = 3  # the preview averages colours; the movie's indices cannot be
    worker = w.timeline.render_movie(tmp_path / "pics", first=0, last=1, size=(160, 120), workers=1)
    assert worker is not None
    steps = []
    worker.progressed.connect(lambda done, total: steps.append((done, total)))
    assert "samples the nearest voxel (kernel 1)" in w.statusBar().currentMessage()
    qtbot.waitUntil(lambda: not w.busy, timeout=JOB_TIMEOUT_MS)
    # #83: indexing the colours (a second) moved the bar before any frame: 3 steps of 3 + 2 x 2 frames
    assert {(1, 7), (2, 7), (3, 7)} <= set(steps) and steps[-1] == (7, 7)
    message = w.statusBar().currentMessage()
    assert "Rendered 2 frames" in message and "colour: 255 palette colours, quantised" in message
    pngs = sorted((tmp_path / "pics").glob("*.png"))
    assert len(pngs) == 2
    for png in pngs:
        pic = iio.imread(png)
        body = np.abs(pic.astype(int) - (0x1E, 0x1F, 0x24)).max(axis=2) > 12  # not the studio's background
        assert body.sum() > 500
        assert (pic[..., 0].astype(int) - pic[..., 2] > 40)[body].mean() > 0.5  # warm skin; grey was 0
