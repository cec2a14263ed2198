"""Colour volumes in every format: raw RGB .vol/.VOL (3 bytes a voxel), RGB .vti, RGB NRRD and
RGB slice folders round-trip; grey readers see luminance; sizes that fit neither are refused."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core import io
from volanim_core.errors import FormatError
from volanim_core.volume import to_grey


@pytest.fixture
def rgb(rng):
    return rng.integers(0, 256, (7, 5, 4, 3)).astype(np.uint8)


@pytest.mark.parametrize("name", ["c.VOL", "c.7x5x4.vol", "c.vti", "c.nrrd"])
# spec: docs/formats.md#colour-volumes
def test_colour_round_trips(tmp_path, rgb, name):
    io.write_volume(tmp_path / name, rgb)
    assert np.array_equal(io.read_volume(tmp_path / name, colour=True), rgb)
    grey = io.read_volume(tmp_path / name)
    assert grey.shape == (7, 5, 4) and np.array_equal(grey, to_grey(rgb))


# spec: docs/formats.md#colour-volumes
def test_raw_rgb_bytes_are_r_g_b_per_voxel_x_fastest(tmp_path, rgb):
    io.write_volume(tmp_path / "c.7x5x4.vol", rgb)
    data = np.frombuffer((tmp_path / "c.7x5x4.vol").read_bytes(), np.uint8)
    assert data.size == 7 * 5 * 4 * 3
    assert data[:3].tolist() == rgb[0, 0, 0].tolist() and data[3:6].tolist() == rgb[1, 0, 0].tolist()
    assert data[3 * 7:3 * 8].tolist() == rgb[0, 1, 0].tolist()


def test_header_files_carry_rgb_through_rmheader_and_addheader(tmp_path, rgb):
    io.write_volume(tmp_path / "c.VOL", rgb)
    io.remove_header(tmp_path / "c.VOL", tmp_path / "c.7x5x4.vol")
    io.add_header(tmp_path / "c.7x5x4.vol", tmp_path / "d.VOL")
    assert np.array_equal(io.read_volume(tmp_path / "d.VOL", colour=True), rgb)


def test_a_raw_file_of_neither_one_nor_three_bytes_a_voxel_is_refused(tmp_path):
    (tmp_path / "c.4x4x4.vol").write_bytes(bytes(64 * 2))
    with pytest.raises(FormatError, match=r"c\.4x4x4\.vol.*128 bytes, expected 64.*or 192 in RGB"):
        io.read_volume(tmp_path / "c.4x4x4.vol")


def test_counting_a_colour_file_says_why_not(tmp_path, rgb):
    io.write_volume(tmp_path / "c.VOL", rgb)
    with pytest.raises(FormatError, match="RGB volume"):
        io.histogram_file(tmp_path / "c.VOL")


def _rgba_vti(path, rgb, alpha):
    import pyvista as pv

    img = pv.ImageData(dimensions=(7, 5, 4))
    rgba = np.concatenate([rgb, np.broadcast_to(np.asarray(alpha, np.uint8), (7, 5, 4))[..., None]], axis=3)
    img.point_data["rgba"] = np.ascontiguousarray(rgba.transpose(2, 1, 0, 3)).reshape(-1, 4)
    img.save(path)


# spec: docs/formats.md (colour volumes, alpha)
def test_an_opaque_4_component_vti_reads_as_rgb(tmp_path, rgb):
    _rgba_vti(tmp_path / "a.vti", rgb, 255)
    assert np.array_equal(io.read_volume(tmp_path / "a.vti", colour=True), rgb)


# spec: docs/formats.md (colour volumes, alpha)
def test_a_vti_with_transparent_voxels_is_refused(tmp_path, rgb):
    alpha = np.full((7, 5, 4), 255, np.uint8)
    alpha[1, 2, 3] = alpha[0, 0, 0] = 0
    _rgba_vti(tmp_path / "a.vti", rgb, alpha)
    with pytest.raises(FormatError, match=r"a\.vti.*2 of 140 pixels are transparent"):
        io.read_volume(tmp_path / "a.vti", colour=True)


# spec: docs/formats.md (colour volumes, alpha)
@pytest.mark.parametrize("colour", [True, False])
def test_rgba_slice_folders_opaque_read_transparent_refused(tmp_path, rgb, colour):
    from PIL import Image  # the images a paint program writes, not our own writer

    for name, alpha in (("opaque", 255), ("masked", 0)):
        folder = tmp_path / name
        folder.mkdir()
        for z in range(rgb.shape[2]):
            a = np.full(rgb.shape[:2], 255, np.uint8)
            a[:2, :2] = alpha  # a corner masked out, its colour left as painted
            rgba = np.concatenate([rgb[:, :, z], a[..., None]], axis=2).swapaxes(0, 1)
            Image.fromarray(np.ascontiguousarray(rgba), "RGBA").save(folder / f"s{z}.png")
    got = io.read_volume(tmp_path / "opaque", colour=colour)
    luma = np.rint(rgb @ [0.2125, 0.7154, 0.0721]).astype(np.uint8)  # docs/formats.md: Rec. 709
    assert np.array_equal(got, rgb if colour else luma)
    with pytest.raises(FormatError, match=r"s0\.png: 4 of 35 pixels are transparent"):
        io.read_volume(tmp_path / "masked", colour=colour)


def test_a_grey_and_alpha_slice_4_rows_high_reads_as_grey_when_opaque(tmp_path):
    from PIL import Image

    grey = np.arange(20, dtype=np.uint8).reshape(4, 5)
    for z in range(2):
        Image.fromarray(np.stack([grey, np.full_like(grey, 255)], axis=2), "LA").save(tmp_path / f"s{z}.png")
    assert np.array_equal(io.read_volume(tmp_path), np.stack([grey.T, grey.T], axis=2))


def test_a_palette_png_with_a_transparent_index_is_not_read_as_opaque(tmp_path):
    """#64: PIL converts a palette PNG to RGB without its tRNS chunk: a mask's transparent background came in
    as white. Transparency keyed in the palette is now alpha: refused where a pixel uses it, as RGBA is."""
    from PIL import Image

    from volanim_core.io.volume_files import read_slice

    a = np.zeros((4, 5), np.uint8)
    a[1:3, 1:4] = 1
    im = Image.fromarray(a, mode="P")
    im.putpalette([255, 255, 255, 200, 50, 50] + [0] * 762)
    im.save(tmp_path / "keyed.png", transparency=0)  # index 0, the white background, transparent
    im.save(tmp_path / "unused.png", transparency=7)  # a transparent index no pixel uses
    with pytest.raises(FormatError, match=r"keyed\.png: 14 of 20 pixels are transparent"):
        read_slice(tmp_path / "keyed.png")
    opaque = read_slice(tmp_path / "unused.png")
    assert opaque.shape == (5, 4) and opaque[0, 0] == 255 and opaque[2, 1] < 255
