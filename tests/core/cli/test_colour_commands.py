"""The colour commands end to end, as a user runs them: a colour scan -> palette -> index volume ->
sorted palette + remap -> transfer function -> picture, and their refusals."""

from __future__ import annotations

import numpy as np
import pytest

from runnable import volanim
from volanim_core import io, samples
from volanim_core.colour.palette import NearestColour
from volanim_core.io.palette_files import read_alpha_map, read_palette

run = volanim  # volanim ARGS as a process


@pytest.fixture(scope="module")
def scan(tmp_path_factory):
    """A small colour scan: the colour mannequin's chest, a raw RGB .VOL."""
    folder = tmp_path_factory.mktemp("colour")
    vol = samples.mannequin_colour().volume[40:120, 20:80, 150:200]
    io.write_volume(folder / "chest.VOL", vol)
    return folder, vol


@pytest.mark.slow
def test_build_apply_sort_remap_merge_render(scan):
    folder, vol = scan
    steps = [
        ("palette", "build", "chest.VOL", "-o", "p.txt", "--colours", "64"),
        ("palette", "apply", "chest.VOL", "p.txt", "-o", "index.VOL"),
        ("palette", "sort", "p.txt", "-o", "sorted.txt", "--remap", "remap.txt", "--volume", "index.VOL"),
        ("remap", "index.VOL", "sorted.VOL", "--table", "remap.txt"),
        ("alpha", "ramp", "0:0", "63:0.8", "-o", "ramp.alpha"),
        ("alpha", "merge", "sorted.txt", "ramp.alpha", "--clear-black", "-o", "body.tf"),
    ]
    out = {}
    for step in steps:
        r = run(*step, cwd=folder)
        assert r.returncode == 0, (step, r.stderr)
        out[step[:2]] = r.stdout
    assert "mean" in out[("palette", "build")] and "95th percentile" in out[("palette", "build")]
    before, after = (line.split() for line in out[("palette", "sort")].splitlines() if line.startswith(("before",
                                                                                                         "after")))
    assert float(after[1]) < float(before[1]) and float(after[3]) < float(before[3])  # sum and midpoint improve

    palette, sorted_palette = read_palette(folder / "p.txt"), read_palette(folder / "sorted.txt")
    index, remapped = io.read_volume(folder / "index.VOL"), io.read_volume(folder / "sorted.VOL")
    assert len(palette) <= 64 and sorted(map(tuple, palette)) == sorted(map(tuple, sorted_palette))
    assert np.array_equal(index, NearestColour(palette)(vol))
    assert np.array_equal(read_palette(folder / "index.palette.txt"), palette)  # the index volume's palette beside it
    assert np.array_equal(sorted_palette[remapped], palette[index])  # every voxel keeps its colour

    tf = io.read_transfer_function(folder / "body.tf")
    assert len(tf.values) == len(palette) and np.allclose(tf.rgba[:, :3] * 255, sorted_palette)
    black = np.flatnonzero(~sorted_palette.any(axis=1))
    assert black.size and np.all(tf.rgba[black, 3] == 0)

    r = run("render", "sorted.VOL", "-o", "body.png", "--tf", "body.tf", "--style", "volume", "--size", "160x120",
            cwd=folder)
    assert r.returncode == 0, r.stderr
    assert np.asarray(io_image(folder / "body.png"))[..., :3].max() > 50


def io_image(path):
    import imageio.v3 as iio

    return iio.imread(path)


def test_alpha_factor_and_interpolate(tmp_path):
    assert run("alpha", "ramp", "0:0", "10:1", "-o", tmp_path / "a.alpha").returncode == 0
    assert run("alpha", "factor", tmp_path / "a.alpha", "0.5", "-o", tmp_path / "b.alpha").returncode == 0
    assert read_alpha_map(tmp_path / "b.alpha")[1].tolist() == [0, 0.5]
    r = run("alpha", "interpolate", tmp_path / "a.alpha", tmp_path / "b.alpha", "-n", "3", "-o", tmp_path / "fade")
    assert r.returncode == 0, r.stderr
    assert [read_alpha_map(tmp_path / f"fade-{k}.alpha")[1][1] for k in (1, 2, 3)] == pytest.approx([0.875, 0.75,
                                                                                                      0.625])


def test_refusals_name_the_file(tmp_path):
    io.write_volume(tmp_path / "grey.VOL", np.zeros((4, 4, 4), np.uint8))
    r = run("palette", "build", tmp_path / "grey.VOL", "-o", tmp_path / "p.txt")
    assert r.returncode == 2 and "grey.VOL" in r.stderr and "colour" in r.stderr and "Traceback" not in r.stderr
    (tmp_path / "bad.txt").write_text("0 0 0\n1 2\n")
    r = run("palette", "sort", tmp_path / "bad.txt", "-o", tmp_path / "s.txt", "--remap", tmp_path / "r.txt")
    assert r.returncode == 2 and "bad.txt:2" in r.stderr
    assert not (tmp_path / "s.txt").exists() and not (tmp_path / "p.txt").exists()
    (tmp_path / "p.txt").write_text("0 0 0\n9 9 9\n")
    io.write_volume(tmp_path / "idx.VOL", np.full((3, 3, 3), 7, np.uint8))
    r = run("palette", "sort", tmp_path / "p.txt", "-o", tmp_path / "s.txt", "--remap", tmp_path / "r.txt",
            "--volume", tmp_path / "idx.VOL")
    assert r.returncode == 2 and "not an index volume of this 2-colour palette" in r.stderr
    r = run("alpha", "ramp", "0:2", "-o", tmp_path / "x.alpha")
    assert r.returncode == 2 and "INDEX:ALPHA" in r.stderr
    r = run("alpha", "merge", tmp_path / "p.txt", "nonsense", "-o", tmp_path / "x.tf")
    assert r.returncode == 2 and "neither an alpha map file nor an opacity" in r.stderr
