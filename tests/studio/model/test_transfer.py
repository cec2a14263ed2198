"""The user's transfer function in the model (#66, the thesis's Icol): pure edits, undo, project and .tf files."""

from __future__ import annotations

import json

import numpy as np
import pytest

from volanim_core import io
from volanim_core.colour.indexed import through_palette
from volanim_core.errors import FormatError
from volanim_core.render.scene import preset_transfer
from volanim_core.render.volume_style import label_colours
from volanim_core.transfer_function import TransferFunction
from volanim_studio.model import Document
from volanim_studio.model.project import apply_project, read_project
from volanim_studio.model.transfer import moved, recoloured, starting_function, with_point, without

RAMP = TransferFunction([0.0, 100.0, 200.0], [[0, 0, 0, 0], [1, 0, 0, 0.5], [1, 1, 1, 1]])


def test_a_new_point_takes_the_colour_the_function_had_there_and_the_opacity_asked():
    tf, i = with_point(RAMP, 50.0, 0.9)
    assert i == 1 and list(tf.values) == [0, 50, 100, 200]
    assert np.allclose(tf.rgba[1], [0.5, 0, 0, 0.9])  # halfway from black to red; opacity as asked
    assert np.allclose(tf(150.0), RAMP(150.0))  # nothing else moved
    with pytest.raises(ValueError, match="a point at 100 already"):
        with_point(RAMP, 100.0, 0.2)


def test_a_moved_point_stays_between_its_neighbours_and_opacity_in_0_1():
    tf = moved(RAMP, 1, 500.0, 1.7)
    assert tf.values[0] < tf.values[1] < tf.values[2] == 200 and tf.values[1] > 199.99 and tf.rgba[1, 3] == 1
    tf = moved(RAMP, 1, -40.0, -2)
    assert 0 < tf.values[1] < 1e-3 and tf.rgba[1, 3] == 0
    assert moved(RAMP, 2, 900.0, 0.3).values[2] == 900  # the last point may go past the data's top
    assert np.allclose(recoloured(RAMP, 0, (0.2, 0.4, 0.6)).rgba[0], [0.2, 0.4, 0.6, 0])
    assert len(without(RAMP, 1).values) == 2
    with pytest.raises(ValueError, match="at least one point"):
        without(TransferFunction([3.0], [[1, 1, 1, 1]]), 0)


def test_the_first_edit_starts_from_the_mode_s_own_look():
    bone = starting_function("bone", 12, 12)
    colours = label_colours("bone", 12)
    for k in range(1, 13):  # label k is its bone's colour, opaque as the studio draws labels; 0 is clear
        assert np.allclose(bone(float(k))[:3], colours[k - 1]) and np.isclose(bone(float(k))[3], 0.85)
    assert bone(0.0)[3] == 0
    assert starting_function("sampled", 250, 12) == preset_transfer("sampled", 250)
    assert starting_function("hotspot", 9, 12) == preset_transfer("hotspot", 9)


def test_each_edit_is_one_undo_step_a_drag_merges_and_a_project_keeps_the_function(tmp_path, doc):
    seen = []
    doc.events.transfer.connect(lambda function: seen.append(function))
    start = doc.transfer.current("sampled", 250)
    tf, i = with_point(start, 180.0, 0.6)
    doc.transfer.set(tf, "add")
    for v in (170.0, 160.0, 150.0):  # a drag: three steps, one undo step
        doc.transfer.set(moved(doc.transfer.function, i, v, 0.7), "move", merge_key=f"transfer:{i}")
    doc.undo.seal()
    assert doc.transfer.function.values[i] == 150.0 and len(seen) == 4
    assert doc.undo.undo() is not None and doc.transfer.function == tf  # back to before the drag, not mid-way
    assert doc.undo.undo() is not None and doc.transfer.function is None and seen[-1] is None
    doc.undo.redo()
    doc.undo.redo()
    path = doc.save_project(tmp_path / "look.volanim")
    saved = json.loads(path.read_text())
    assert saved["transfer"]["values"] == doc.transfer.function.values.tolist()
    fresh = Document()
    fresh.set_skeleton(doc.skeleton)
    assert apply_project(fresh, read_project(path), path) == [] and fresh.transfer.function == doc.transfer.function
    assert not fresh.undo.can_undo  # reopening is not an edit
    doc.reset()
    assert doc.transfer.function is None  # a new document has the modes' own looks
    saved["transfer"] = {"values": [1, 0], "rgba": [[0, 0, 0, 0], [1, 1, 1, 1]]}
    (tmp_path / "bad.volanim").write_text(json.dumps(saved))
    with pytest.raises(FormatError, match=r"bad\.volanim.*\"transfer\": transfer function values must be strictly"):
        read_project(tmp_path / "bad.volanim")


def test_a_tf_file_is_one_undo_step_and_a_bad_one_changes_nothing(tmp_path):
    doc = Document()
    path = tmp_path / "bones.tf"
    path.write_text("# value r g b opacity\n0 0 0 0 0\n128 0.2 0.8 0.2 0.4\n255 1 1 1 1\n")
    doc.transfer.load(path)
    assert doc.transfer.function == TransferFunction([0, 128, 255], [[0, 0, 0, 0], [0.2, 0.8, 0.2, 0.4], [1, 1, 1, 1]])
    assert doc.undo.can_undo
    doc.transfer.save(tmp_path / "out.tf", "sampled", 255)
    assert io.read_transfer_function(tmp_path / "out.tf") == doc.transfer.function
    (tmp_path / "bad.tf").write_text("0 0 0 0 0\n10 0 0 zero 1\n")
    with pytest.raises(FormatError, match=r"bad\.tf:2"):
        doc.transfer.load(tmp_path / "bad.tf")
    assert doc.transfer.function == io.read_transfer_function(path)
    empty = Document()
    empty.transfer.save(tmp_path / "mode.tf", "hotspot", 20)  # no function of the user's: the mode's look
    assert io.read_transfer_function(tmp_path / "mode.tf") == preset_transfer("hotspot", 20)


def test_through_palette_is_the_function_of_each_colour_s_luminance():
    from volanim_core.volume import to_grey

    palette = np.array([[0, 0, 0], [255, 0, 0], [10, 200, 30], [255, 255, 255]], np.uint8)
    tf = TransferFunction([0.0, 60.0, 255.0], [[0, 0, 0, 0], [0, 1, 0, 0.5], [1, 1, 1, 1]])
    by_index = through_palette(tf, palette)
    for k, colour in enumerate(palette):
        assert np.allclose(by_index(float(k)), tf(float(to_grey(colour[None])[0])))


def test_a_label_step_is_one_handle_and_moves_whole_between_its_neighbours():
    """#83 item 8: each label of the bone look is two points (a flat step); edited one at a time, half a bone
    changed. Handles group them; a step moves with its width kept and never past its neighbours."""
    import numpy as np

    from volanim_core.render.volume_style import LABEL_STEP, label_steps
    from volanim_studio.model.transfer import handle_value, handles, moved_handle, recoloured_handle, without_handle

    tf = label_steps(np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1]], np.float64))
    hs = handles(tf)
    assert hs == [(0,), (1,), (2, 3), (4, 5), (6, 7)]
    assert [handle_value(tf, h) for h in hs[2:]] == [1.0, 2.0, 3.0]
    red = recoloured_handle(tf, hs[3], (1, 1, 0))
    assert np.allclose(red(np.linspace(1.55, 2.45, 5))[:, :3], (1, 1, 0)) and np.allclose(red(1.0), tf(1.0))
    far = moved_handle(tf, hs[3], 99.0, 0.2)  # dragged far right: stopped before label 3's step
    a, b = hs[3]
    assert np.isclose(far.values[b] - far.values[a], 2 * LABEL_STEP) and far.values[b] < tf.values[6]
    assert np.allclose(far.rgba[[a, b], 3], 0.2)
    assert handles(without_handle(tf, hs[2])) == [(0,), (1,), (2, 3), (4, 5)]
