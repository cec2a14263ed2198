"""Alpha maps: InterpolateAlpha, AlphaFactor, MergeMaps, and their files."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core import io
from volanim_core.colour.alpha import alpha_factor, interpolate_alpha, merge_maps
from volanim_core.errors import FormatError
from volanim_core.io.palette_files import read_alpha_map, write_alpha_map


def test_interpolated_maps_fade_evenly_on_the_union_of_indices():
    a = (np.array([0.0, 100.0]), np.array([0.0, 1.0]))
    b = (np.array([0.0, 50.0, 100.0]), np.array([1.0, 1.0, 0.0]))
    maps = interpolate_alpha(a, b, 3)
    assert len(maps) == 3
    for k, (v, alpha) in enumerate(maps, start=1):
        t = k / 4
        assert np.array_equal(v, [0, 50, 100])
        assert alpha == pytest.approx((1 - t) * np.array([0, 0.5, 1]) + t * np.array([1, 1, 0]))


def test_factor_scales_and_clips():
    v, a = alpha_factor((np.array([0.0, 10.0]), np.array([0.2, 0.8])), 2.0)
    assert a == pytest.approx([0.4, 1.0])
    with pytest.raises(ValueError, match="factor"):
        alpha_factor((v, a), -1)


def test_merge_gives_one_point_per_index_with_the_palette_colour():
    palette = np.array([[0, 0, 0], [255, 128, 0], [10, 20, 30]], np.uint8)
    tf = merge_maps(palette, (np.array([0.0, 2.0]), np.array([0.0, 1.0])))
    assert np.array_equal(tf.values, [0, 1, 2])
    assert tf.rgba[:, :3] == pytest.approx(palette / 255)
    assert tf.rgba[:, 3] == pytest.approx([0, 0.5, 1])
    assert tf(1.5)[:3] == pytest.approx((palette[1].astype(float) + palette[2]) / 510)  # linear between indices


def test_the_merged_transfer_function_is_what_render_reads(tmp_path):
    tf = merge_maps(np.array([[1, 2, 3], [200, 100, 50]], np.uint8), (np.array([0.0]), np.array([0.3])))
    io.write_transfer_function(tmp_path / "m.tf", tf)
    assert io.read_transfer_function(tmp_path / "m.tf") == tf


# spec: docs/formats.md#alpha
def test_alpha_map_files_round_trip_and_errors_name_the_line(tmp_path):
    write_alpha_map(tmp_path / "a.alpha", [0, 1, 254], [0, 0.1 * 3, 0.9])
    v, a = read_alpha_map(tmp_path / "a.alpha")
    assert v.tolist() == [0, 1, 254] and a == pytest.approx([0, 0.3, 0.9])
    assert "0.30000000000000004" not in (tmp_path / "a.alpha").read_text()
    (tmp_path / "b.alpha").write_text("0 0\n5 0.5\n3 1\n")
    with pytest.raises(FormatError, match=r"b\.alpha:3: indices must ascend"):
        read_alpha_map(tmp_path / "b.alpha")
    (tmp_path / "c.alpha").write_text("0 1.5\n")
    with pytest.raises(FormatError, match=r"c\.alpha:1: alpha is between 0 and 1"):
        read_alpha_map(tmp_path / "c.alpha")


def test_merge_clears_the_indices_asked_for_and_refuses_ones_past_the_palette():
    from volanim_core.colour.alpha import black_indices

    palette = np.array([[9, 9, 9], [0, 0, 0], [200, 10, 10]], np.uint8)
    assert black_indices(palette).tolist() == [1]
    tf = merge_maps(palette, (np.array([0.0]), np.array([0.7])), black_indices(palette))
    assert tf.rgba[:, 3] == pytest.approx([0.7, 0.0, 0.7])
    with pytest.raises(ValueError, match=r"indices to clear must be 0\.\.2"):
        merge_maps(palette, (np.array([0.0]), np.array([0.7])), [3])
