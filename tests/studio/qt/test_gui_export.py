"""*File → Export animated glTF…* with real widgets: a keyed wave on the demo mannequin, exported in the
window's worker, read back by pygltflib: the wave's frames, the bones as joints, the hand going up."""

from __future__ import annotations

import pytest

from paths import ASSETS
from their_gltf import load_theirs, their_positions

from ..conftest import JOB_TIMEOUT_MS

pytestmark = pytest.mark.gui


@pytest.fixture
def waving(qtbot, window):
    """The demo mannequin rigged from assets/, its left upper arm keyed from rest to raised over 12 frames."""
    w = window
    assert w.files.open_bones(ASSETS / "mannequin.bones")
    assert w.files.open_connect(ASSETS / "mannequin.0.50.connect")
    tl = w.doc.timeline
    tl.set_options(length=12)
    tl.set_key(0)
    w.doc.settings.current_frame = 11
    w.doc.pose.set_angles(w.doc.bones.index("L_UPPERARM"), (0, -90, 0))
    tl.set_key()
    return w


def test_the_file_menu_exports_the_keyed_wave_as_glb(qtbot, waving, tmp_path):
    w = waving
    entries = [a.text() for a in w.menuBar().actions()[0].menu().actions()]
    assert "Export animated &glTF…" in entries
    out = tmp_path / "wave.glb"
    assert w.exporting.export_gltf(out) is not None  # a worker: the GUI thread stays free
    qtbot.waitUntil(lambda: not w.jobs.running, timeout=JOB_TIMEOUT_MS)
    assert w.last_error is None and out.exists()
    assert "Exported wave.glb:" in w.statusBar().currentMessage()
    g = load_theirs(out)
    assert [n.name for n in g.nodes[1:19]] == [b.name for b in w.doc.pose.tskel().connectivity.bones]
    times = g.accessors[g.animations[0].samplers[0].input]
    assert (times.count, times.max[0]) == (12, pytest.approx(11 / w.doc.timeline.frame_rate))
    hand_rest, hand_raised = (their_positions(g, 0, t)["L_HAND"] for t in (0.0, times.max[0]))
    assert hand_raised[1] - hand_rest[1] > 0.05  # the hand goes up (glTF's +y) by more than 5 cm (of 29)


def test_nothing_to_export_is_said_and_nothing_written(qtbot, window, tmp_path):
    w = window
    assert w.exporting.export_gltf(tmp_path / "x.glb") is None
    assert "nothing to export" in (w.last_error or "") and not any(tmp_path.glob("*.glb"))
