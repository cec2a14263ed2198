"""The old pipeline's volume utilities as array functions."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core import volume
from volanim_core.volume import Bounds


def test_threshold_band_pass():
    v = np.arange(10, dtype=np.uint8).reshape(10, 1, 1)
    assert volume.threshold(v, 3, 6).ravel().tolist() == [0, 0, 0, 1, 1, 1, 1, 0, 0, 0]
    assert volume.threshold(v, 8, value=255).ravel().tolist()[-3:] == [0, 255, 255]
    with pytest.raises(ValueError, match="empty"):
        volume.threshold(v, 6, 3)
    with pytest.raises(ValueError, match="3-D"):
        volume.threshold(np.zeros((3, 3)), 1)


def test_fill_cavities_fills_enclosed_not_open():
    m = np.zeros((9, 9, 9), np.uint8)
    m[1:8, 1:8, 1:8] = 1
    m[3:6, 3:6, 3:6] = 0  # enclosed cavity
    m[0:2, 4, 4] = 0  # a tunnel from the border is not a cavity... but it ends in the shell
    out = volume.fill_cavities(m)
    assert out[4, 4, 4] == 1 and out[0, 4, 4] == 0 and out[1, 4, 4] == 0
    assert out.sum() == m.sum() + 27


def test_crop_pads_outside_and_tight_bounds():
    v = np.zeros((10, 10, 10), np.uint8)
    v[2:5, 3, 7] = 9
    b = volume.tight_bounds(v)
    assert b == Bounds((2, 3, 7), (4, 3, 7)) and str(b) == "2 3 7 4 3 7"
    c = volume.crop(v, b)
    assert c.shape == (3, 1, 1) and (c == 9).all()
    padded = volume.crop(v, Bounds((-1, -1, -1), (10, 10, 10)))
    assert padded.shape == (12, 12, 12) and padded[3, 4, 8] == 9 and padded.sum() == v.sum()
    assert volume.tight_bounds(np.zeros((2, 2, 2))) is None


def test_box_fill_clips_to_volume():
    v = volume.box_fill(np.zeros((4, 4, 4), np.uint8), Bounds((-3, 2, 2), (1, 9, 2)), 7)
    assert v.sum() == 7 * 2 * 2


def test_flip_reverse_remap_histogram(rng):
    v = rng.integers(0, 256, (4, 5, 6), dtype=np.uint8)
    assert np.array_equal(volume.flip(v, "y")[:, ::-1], v)
    assert np.array_equal(volume.reverse(v), 255 - v)
    table = np.arange(256)[::-1]
    assert np.array_equal(volume.remap(v, table), 255 - v)
    assert volume.histogram(v).sum() == v.size
    with pytest.raises(ValueError, match="256 entries"):
        volume.remap(v, [1, 2])


# spec: docs/formats.md#diff
def test_super_diff_codes_are_the_thesis_codes():
    a = np.array([0, 7, 1, 0, 9, 100], np.uint8).reshape(6, 1, 1)
    b = np.array([0, 7, 0, 5, 3, 50], np.uint8).reshape(6, 1, 1)
    # same (empty), same (non-zero), only first, only second, both with other values (twice)
    assert volume.super_diff(a, b).ravel().tolist() == [0, 0, 100, 150, 200, 200]
    with pytest.raises(ValueError, match="differ in size"):
        volume.super_diff(a, b[:2])


def test_super_diff_sees_a_volume_whose_every_value_changed():
    # The old codes called this "both filled" everywhere: no difference reported.
    a = np.full((3, 4, 5), 100, np.uint8)
    assert (volume.super_diff(a, a // 2) == 200).all()
    assert not volume.super_diff(a, a.copy()).any()


def test_fit_pow2_and_float_to_uint8():
    v = np.ones((5, 8, 3), np.uint8)
    out, off = volume.fit_pow2(v, center=True)
    assert out.shape == (8, 8, 4) and off == (1, 0, 0) and out.sum() == v.sum()
    f = np.array([-1.0, 0.0, 1.0, 3.0]).reshape(4, 1, 1)
    assert volume.float_to_uint8(f, -1, 1).ravel().tolist() == [0, 128, 255, 255]
