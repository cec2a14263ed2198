"""The slice viewer (#43, View.tcl): ``volanim view VOLUME --slices`` and the picture it shows.

The oracle is the other project's reader: nibabel's own test scan, read by nibabel, sliced and
windowed here with NumPy, against the pixels the VTK window draws (one voxel = k x k pixels).
"""

from __future__ import annotations

from pathlib import Path

import imageio.v3 as iio
import nibabel as nib
import numpy as np
import pytest

from runnable import volanim
from volanim_core import io
from volanim_core.geometry import Geometry
from volanim_core.render.slice_view import SliceView, window_size
from volanim_core.render.slices import slice_picture, voxel_at

ANATOMICAL = Path(nib.__file__).parent / "tests" / "data" / "anatomical.nii"


def voxels_of(picture: np.ndarray, columns: int, rows: int) -> np.ndarray:
    """One pixel from the middle of each voxel's block of a picture showing ``columns x rows`` voxels."""
    h, w = picture.shape[:2]
    r = ((np.arange(rows) + 0.5) * h / rows).astype(int)
    c = ((np.arange(columns) + 0.5) * w / columns).astype(int)
    return picture[np.ix_(r, c)]


def test_a_slice_of_nibabels_scan_is_nibabels_voxels(tmp_path):
    data = np.asanyarray(nib.load(ANATOMICAL).dataobj).astype(np.float64)
    k = 7
    r = volanim("view", ANATOMICAL, "--slices", "z", "--slice", k, "--screenshot", "s.png", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert f"z slice {k} of" in r.stdout
    lo, hi = data.min(), data.max()
    expected = np.round(np.clip((data[:, :, k] - lo) / (hi - lo), 0, 1) * 255)  # [x, y]
    expected = expected.T[::-1]  # x to the right, y up
    shot = iio.imread(tmp_path / "s.png")[..., :3]
    assert shot.shape[:2] == window_size(data.shape, 2, (2, 2, 2))[::-1]
    got = voxels_of(shot, data.shape[0], data.shape[1]).astype(np.int16)
    assert np.abs(got - expected[..., None]).max() <= 1
    assert len(np.unique(expected)) > 50  # a real picture, not one flat grey


@pytest.mark.long("every axis of the slice view against the named 3-D views: one voxel placed, six pictures")
def test_every_axis_puts_a_voxel_where_the_named_views_see_it(tmp_path):
    vol = np.zeros((5, 6, 7), np.uint8)
    vol[1, 2, 3] = 200
    vol[4, 5, 6] = 100
    io.write_volume(tmp_path / "v.nrrd", vol, Geometry((1.0, 1.0, 1.0)))
    # (axis, index) -> the bright voxel's (column, row from the top), worked out from the views by hand
    for axis, index, at in (("z", 3, (1, 6 - 1 - 2)), ("y", 2, (1, 7 - 1 - 3)), ("x", 1, (2, 7 - 1 - 3))):
        r = volanim("view", "v.nrrd", "--slices", axis, "--slice", index, "--screenshot", f"{axis}.png",
                    cwd=tmp_path)
        assert r.returncode == 0, r.stderr
        shot = iio.imread(tmp_path / f"{axis}.png")[..., :3]
        cols, rows = {"z": (5, 6), "y": (5, 7), "x": (6, 7)}[axis]
        got = voxels_of(shot, cols, rows)[..., 0]
        assert np.argwhere(got == 255).tolist() == [[at[1], at[0]]], axis
        assert voxel_at(vol.shape, "xyz".index(axis), index, at[0], at[1]) == (1, 2, 3)


def test_tall_voxels_make_tall_pixels_and_colour_shows_as_it_is(tmp_path):
    vol = np.zeros((10, 8, 5, 3), np.uint8)
    vol[..., 0] = np.arange(10)[:, None, None] * 20  # red grows with x
    vol[..., 2] = np.arange(5)[None, None, :] * 50  # blue with z
    io.write_volume(tmp_path / "c.nrrd", vol, Geometry((1.0, 1.0, 4.0)))
    r = volanim("view", "c.nrrd", "--slices", "y", "--screenshot", "c.png", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    shot = iio.imread(tmp_path / "c.png")[..., :3]
    h, w = shot.shape[:2]
    assert h / w == pytest.approx(5 * 4 / 10, rel=0.02)  # 5 voxels of 4 mm over 10 of 1 mm
    got = voxels_of(shot, 10, 5)
    assert np.array_equal(got, slice_picture(vol, 1, 4))
    assert np.array_equal(got[-1, :, 0], np.arange(10) * 20) and np.array_equal(got[:, 0, 2], [200, 150, 100, 50, 0])


def test_the_windows_slider_moves_through_the_slices(tmp_path):
    vol = np.zeros((6, 6, 9), np.uint8)
    for z in range(9):
        vol[:, :, z] = z * 30  # each slice its own grey
    view = SliceView(vol, axis=2, off_screen=True, slider=True)
    try:
        assert view.index == 4
        widget = view.plotter.widgets.slider_widgets[0]
        for k in (0, 8, 3):
            widget.GetRepresentation().SetValue(k)
            widget.InvokeEvent("EndInteractionEvent")  # what letting go of the slider does
            assert view.index == k
            shot = view.screenshot()
            w, h = window_size(vol.shape, 2, (1, 1, 1))
            picture = voxels_of(shot[:h, :w], 6, 6)  # the slider sits under the picture
            assert np.all(picture == round(k * 30 * 255 / 240)), k
    finally:
        view.close()


def test_slice_refusals_name_what_is_wrong(tmp_path):
    io.write_volume(tmp_path / "v.nrrd", np.ones((4, 5, 6), np.uint8))
    for args, message in ((["--slices", "q"], "a slice is across x, y or z"),
                          (["--slices", "xy"], "a slice is across x, y or z"),  # was taken as x
                          (["--slices", "y", "--slice", "5"], "v.nrrd: --slice 5 is outside the volume: y runs 0..4"),
                          (["--slices", "--window", "9:2"], "--window needs LO:HI with LO < HI"),
                          (["--slice", "2"], "add --slices")):
        r = volanim("view", "v.nrrd", *args, "--screenshot", "x.png", cwd=tmp_path)
        assert r.returncode == 2, (args, r.stderr)
        assert message in r.stderr, (args, r.stderr)
        assert not (tmp_path / "x.png").exists()
