"""Colour is never dropped silently (#66): every volume tool run on the colour mannequin writes colour, or
refuses in words (naming the file and the way to a grey copy), or -- for tools whose output is no volume
(a skeleton, a surface, bounds) -- says it reads the luminance. resample, crop and flip made grey of it."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core import io, samples, volume
from volanim_core.cli import build_parser, main, subcommands
from volanim_core.geometry import Geometry

# tools whose input is no volume, or that are not run here, and why
NOT_VOLUME_TOOLS = {
    "rmheader": "bytes of a raw file, never decoded",
    "addheader": "bytes of a raw file, never decoded",
    "voxelize": "reads a mesh",
    "render": "colour movies: tests/core/render (a colour sequence renders in colour)",
    "view": "the studio's viewer: tests/studio (colour volumes open in colour)",
    "compare": "a shape comparison of non-black voxels (read in colour): tests/core/reconstruct/test_shape.py",
}


@pytest.fixture(scope="module")
def colour(tmp_path_factory):
    folder = tmp_path_factory.mktemp("colour")
    rgb = np.asfortranarray(samples.mannequin_colour().volume[::4, ::4, ::4])
    geometry = Geometry(spacing=(1.5, 1.5, 2.0), origin=(10.0, -5.0, 3.0))
    io.write_volume(folder / "c.vti", rgb, geometry)
    return folder, rgb, geometry


def run(args, capsys):
    code = main([str(a) for a in args])
    out = capsys.readouterr()
    return code, out.out, out.err


def kept(path, expected):
    data = io.read_scan(path, colour=True).data
    assert data.ndim == 4 and data.shape[3] == 3, f"{path}: colour dropped"
    assert np.array_equal(data, expected)


def test_every_volume_tool_keeps_colour_or_says_why_not(colour, tmp_path, capsys):
    folder, rgb, g = colour
    c = folder / "c.vti"
    out = tmp_path
    (tmp_path / "table.txt").write_text("100 7\n")
    keeps = {
        "crop": (["crop", c, out / "crop.vti", "--bounds", 2, 3, 4, 20, 18, 60], rgb[2:20, 3:18, 4:60]),
        "flip": (["flip", c, out / "flip.vti", "--axis", "x"], rgb[::-1]),
        "reverse": (["reverse", c, out / "rev.vti"], 255 - rgb),
        "fitpow2": (["fitpow2", c, out / "p2.vti"], volume.each_channel(rgb, lambda v: volume.fit_pow2(v)[0])),
        "resample": (["resample", c, out / "rs.vti", "--factor", "2"],
                     volume.each_channel(rgb, lambda v: volume.resample(v, g, np.multiply(g.spacing, 2))[0])),
        "convert": (["convert", c, out / "cv.nrrd"], rgb),
    }
    for name, (args, expected) in keeps.items():
        code, _, err = run(args, capsys)
        assert code == 0, (name, err)
        kept(args[2], expected)
    # channel by channel is what a colour resample means: each channel as a grey volume of its own
    assert keeps["resample"][1].shape[:3] == volume.resample(rgb[..., 0], g, np.multiply(g.spacing, 2))[0].shape
    refused = {
        "threshold": ["threshold", c, out / "t.vti", "--range", "1:255"],
        "fill": ["fill", c, out / "f.vti", "--cavities"],
        "count": ["count", c],
        "diff": ["diff", c, c],
        "remap": ["remap", c, out / "r.vti", "--table", tmp_path / "table.txt"],
        "float2uchar": ["float2uchar", c, out / "u.vti"],
        "onevolume": ["onevolume", c, "-o", out / "o.vti"],
        "crumble": ["crumble", c, "-o", out / "cr%02d.vti", "-n", 2],
    }
    for name, args in refused.items():
        before = set(out.iterdir())
        code, text, err = run(args, capsys)
        assert code == 2, (name, text, err)
        assert f"{c} is a colour (RGB) volume, and `volanim {name}` works on one value a voxel" in err, (name, err)
        assert "volanim convert" in err and "--grey" in err
        assert set(out.iterdir()) == before, name  # nothing written
    # tools whose output is no volume: what they read is said
    mask = rgb.any(axis=3)
    code, text, err = run(["tightbounds", c], capsys)
    assert code == 0 and text.split() == [str(v) for v in (*np.argwhere(mask).min(0), *(np.argwhere(mask).max(0) + 1))]
    code, text, err = run(["info", c], capsys)
    assert code == 0 and "uint8 RGB" in text
    code, text, err = run(["peek", c, 20, 12, 37], capsys)
    assert code == 0 and text.startswith(f"(20, 12, 37) = {' '.join(str(int(v)) for v in rgb[20, 12, 37])}")
    code, text, err = run(["skeletonize", c, "-o", out / "c.mskel"], capsys)
    assert code == 0 and "is a colour volume; read as its luminance" in text, err
    code, text, err = run(["isosurface", c, "-o", out / "c.ply"], capsys)
    assert code == 0 and "is a colour volume; read as its luminance" in text, err
    code, text, err = run(["addskel", c, out / "c.mskel", "-o", out / "as.vti", "--half"], capsys)
    assert code == 0, err
    merged = io.read_scan(out / "as.vti", colour=True).data
    assert merged.ndim == 4 and np.count_nonzero(np.all(merged == 250, axis=3)) > 0
    assert np.array_equal(merged[~np.all(merged == 250, axis=3)], (rgb // 2)[~np.all(merged == 250, axis=3)])
    # every tool that reads a volume is in one of the lists above
    covered = {*keeps, *refused, "tightbounds", "info", "peek", "skeletonize", "isosurface", "addskel",
               *NOT_VOLUME_TOOLS}
    volume_tools = {name for name, p in subcommands(build_parser()).items()
                    if any("volume" in (a.help or "").lower() for a in p._actions if not a.option_strings)}
    assert volume_tools <= covered, volume_tools - covered


def test_a_dark_colour_is_part_of_the_object_when_read_as_luminance(tmp_path, capsys):
    """(0, 0, 2) has luminance 0.23, which rounds to 0: read as grey it fell out of the body."""
    rgb = np.zeros((8, 8, 8, 3), np.uint8)
    rgb[2:6, 2:6, 2:6] = (0, 0, 2)
    io.write_volume(tmp_path / "dark.vti", rgb)
    code, text, err = run(["isosurface", tmp_path / "dark.vti", "-o", tmp_path / "d.ply"], capsys)
    assert code == 0, err
    assert not text.startswith("0 vertices")


def test_a_real_photograph_s_slices_stay_colour_through_crop_flip_and_resample(tmp_path, capsys):
    """Real colour data nobody here made (scikit-image's astronaut photograph, four shifted crops as a slice
    folder), read back with Pillow, not with our reader: crop and flip keep every RGB value where Pillow puts
    it, and a colour resample is each channel resampled alone."""
    from PIL import Image
    from skimage import data

    photo = data.astronaut()  # (512, 512, 3) uint8
    folder = tmp_path / "slices"
    folder.mkdir()
    for k in range(4):
        Image.fromarray(np.ascontiguousarray(photo[40 + 10 * k:200 + 10 * k, 100:260])).save(folder / f"s{k}.png")
    pillow = np.stack([np.asarray(Image.open(folder / f"s{k}.png").convert("RGB")) for k in range(4)], axis=2)
    as_read = np.transpose(pillow, (1, 0, 2, 3))  # rows are y, columns x (docs/formats.md): [x, y, z, c]
    code, _, err = run(["crop", folder, tmp_path / "c.vti", "--bounds", 10, 20, 1, 90, 70, 3], capsys)
    assert code == 0, err
    kept(tmp_path / "c.vti", as_read[10:90, 20:70, 1:3])
    code, _, err = run(["flip", folder, tmp_path / "f.vti", "--axis", "y"], capsys)
    assert code == 0, err
    kept(tmp_path / "f.vti", as_read[:, ::-1])
    code, _, err = run(["resample", folder, tmp_path / "r.vti", "--factor", "2"], capsys)
    assert code == 0, err
    got = io.read_scan(tmp_path / "r.vti", colour=True).data
    one = io.read_scan(folder, colour=True).geometry
    for c in range(3):
        alone, _ = volume.resample(np.asfortranarray(as_read[..., c]), one, np.multiply(one.spacing, 2))
        assert np.array_equal(got[..., c], alone)
