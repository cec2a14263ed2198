"""Palettes: building (exact for few colours, error bounded for many), mapping voxels (the nearest
colour, by brute force), streaming slab by slab, and the palette file format."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core import io
from volanim_core.colour import slabs as S
from volanim_core.colour.palette import NearestColour, build_palette, quantisation_error, unique_colours
from volanim_core.colour.space import delta_e, from_linear, to_lab, to_linear
from volanim_core.errors import FormatError
from volanim_core.io.palette_files import read_palette, write_palette


def volume_of_colours(rng, colours, shape=(20, 16, 12)):
    """A colour volume whose voxels are drawn from ``colours`` (each used)."""
    pick = rng.integers(0, len(colours), shape)
    pick.ravel()[: len(colours)] = np.arange(len(colours))
    return np.asarray(colours, np.uint8)[pick]


@pytest.mark.parametrize("method", ["kmeans", "median-cut"])
@pytest.mark.parametrize("n", [1, 7, 255])
def test_a_volume_of_at_most_n_colours_is_reproduced_exactly(rng, method, n):
    colours = np.unique(rng.integers(0, 256, (n, 3)).astype(np.uint8), axis=0)
    vol = volume_of_colours(rng, colours)
    palette = build_palette(*unique_colours(vol), 255, method=method)
    assert len(palette) == len(colours)
    index = NearestColour(palette)(vol)
    assert np.array_equal(palette[index], vol)
    assert quantisation_error(*unique_colours(vol), palette) == (0.0, 0.0)


@pytest.mark.parametrize("method", ["kmeans", "median-cut"])
def test_many_colours_quantise_within_a_bound_and_kmeans_beats_median_cut(rng, method):
    # 40 colour families, each a cloud of near colours (a tissue with grain): 255 colours serve them well
    centres = rng.integers(30, 226, (40, 3))
    vol = np.clip(centres[rng.integers(0, 40, (24, 24, 24))] + rng.normal(0, 6, (24, 24, 24, 3)), 0, 255)
    colours, counts = unique_colours(vol.astype(np.uint8))
    assert len(colours) > 5000
    errors = {m: quantisation_error(colours, counts, build_palette(colours, counts, 255, method=m))
              for m in ("kmeans", "median-cut")}
    mean, p95 = errors[method]
    assert mean < (2.0 if method == "kmeans" else 3.0) and p95 < 2 * mean + 2.0
    assert errors["kmeans"][0] < errors["median-cut"][0]


def test_the_palette_is_deterministic_and_at_most_n(rng):
    vol = rng.integers(0, 256, (16, 16, 16, 3)).astype(np.uint8)
    a = build_palette(*unique_colours(vol), 32)
    b = build_palette(*unique_colours(vol), 32)
    assert np.array_equal(a, b) and len(a) <= 32


def test_mapping_equals_the_brute_force_nearest_colour(rng):
    palette = np.unique(rng.integers(0, 256, (60, 3)).astype(np.uint8), axis=0)
    vol = rng.integers(0, 256, (30, 20, 10, 3)).astype(np.uint8)
    lab_v, lab_p = to_lab(vol.reshape(-1, 3)), to_lab(palette)
    dist = ((lab_v[:, None, :] - lab_p[None, :, :]) ** 2).sum(axis=2)
    want = dist.argmin(axis=1)
    mapper = NearestColour(palette)
    for got in (mapper(vol).ravel(), mapper.per_voxel(vol).ravel(), mapper(vol).ravel()):  # twice: the table
        chosen = dist[np.arange(len(want)), got]
        assert np.allclose(chosen, dist.min(axis=1))  # as near as the nearest (a tie may pick either)
        assert (got == want).mean() > 0.999


def test_the_table_remembers_colours_between_calls(rng):
    palette = rng.integers(0, 256, (20, 3)).astype(np.uint8)
    mapper = NearestColour(palette)
    vol = rng.integers(0, 256, (8, 8, 8, 3)).astype(np.uint8)
    first = mapper(vol)
    assert np.count_nonzero(mapper.table >= 0) == len(unique_colours(vol)[0])
    assert np.array_equal(mapper(vol), first)


def test_ciede2000_matches_the_published_pair():
    # Sharma, Wu & Dalal (2005), pair 1: L*a*b* (50, 2.6772, -79.7751) vs (50, 0, -82.7485) -> 2.0425
    from volanim_core.colour.space import delta_e_lab

    assert delta_e_lab(np.array([50, 2.6772, -79.7751]), np.array([50, 0, -82.7485])) == pytest.approx(2.0425, abs=1e-4)
    assert delta_e(np.array([[10, 20, 30]], np.uint8), np.array([[10, 20, 30]], np.uint8))[0] == 0


def test_linear_light_round_trips_every_byte():
    values = np.arange(256)
    assert np.array_equal(from_linear(to_linear(values)), values)


def test_streamed_apply_of_a_raw_file_equals_mapping_in_memory(rng, tmp_path, monkeypatch):
    monkeypatch.setattr(S, "SLAB_VOXELS", 40 * 30 * 3)  # slabs of 3 slices: many slabs, a short last one
    vol = rng.integers(0, 256, (40, 30, 11, 3)).astype(np.uint8)
    io.write_volume(tmp_path / "c.VOL", vol)
    palette = build_palette(*unique_colours(vol), 64)
    slabs = S.ColourSlabs.open(tmp_path / "c.VOL")
    assert slabs.shape == (40, 30, 11) and slabs.depth == 3
    for name in ("i.VOL", "i.vol", "i.nrrd"):
        path, counts = S.apply_palette(slabs, palette, tmp_path / name)
        got = io.read_volume(path)
        assert np.array_equal(got, NearestColour(palette)(vol)), name
        assert counts.sum() == 40 * 30 * 11
    assert (tmp_path / "i.40x30x11.vol").is_file()


def test_a_slice_folder_is_read_one_slice_at_a_time(rng, tmp_path):
    from skimage import io as skio

    vol = rng.integers(0, 256, (12, 9, 5, 3)).astype(np.uint8)
    for z in range(5):
        skio.imsave(tmp_path / f"s{z + 1}.png", vol[:, :, z].swapaxes(0, 1), check_contrast=False)
    slabs = S.ColourSlabs.open(tmp_path)
    assert slabs.shape == (12, 9, 5)
    assert np.array_equal(slabs.slab(1, 4), vol[:, :, 1:4])
    colours, counts = S.sample_colours(slabs)
    assert counts.sum() == vol[..., 0].size
    assert np.array_equal(io.read_volume(tmp_path, colour=True), vol)
    assert io.read_volume(tmp_path).shape == (12, 9, 5)  # grey unless colour is asked for


def test_a_grey_volume_is_refused_by_name(tmp_path):
    io.write_volume(tmp_path / "g.VOL", np.zeros((4, 4, 4), np.uint8))
    with pytest.raises(FormatError, match=r"g\.VOL.*grey volume"):
        S.ColourSlabs.open(tmp_path / "g.VOL")


# spec: docs/formats.md#palette
def test_palette_files_round_trip_and_bad_lines_are_named(tmp_path, rng):
    palette = rng.integers(0, 256, (17, 3)).astype(np.uint8)
    write_palette(tmp_path / "p.txt", palette, "a comment")
    assert np.array_equal(read_palette(tmp_path / "p.txt"), palette)
    (tmp_path / "bad.txt").write_text("# header\n1 2 3\n\n4 5 256\n")
    with pytest.raises(FormatError, match=r"bad\.txt:4: blue must be 0\.\.255"):
        read_palette(tmp_path / "bad.txt")
    (tmp_path / "two.txt").write_text("1 2\n")
    with pytest.raises(FormatError, match=r"two\.txt:1: .*R G B"):
        read_palette(tmp_path / "two.txt")
    (tmp_path / "long.txt").write_text("1 2 3\n" * 257)
    with pytest.raises(FormatError, match=r"long\.txt:257: .*at most 256"):
        read_palette(tmp_path / "long.txt")
