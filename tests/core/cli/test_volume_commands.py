"""The volanim command line on real files, as a subprocess and in-process."""

from __future__ import annotations

import numpy as np
import pytest

from runnable import volanim
from volanim_core import io
from volanim_core.cli import build_parser, main, subcommands

run = volanim  # volanim ARGS as a process


def test_help_lists_every_subcommand_and_each_has_an_example():
    r = run("--help")
    assert r.returncode == 0
    parser = build_parser()
    commands = subcommands(parser)
    assert len(commands) >= 17
    for name, p in commands.items():
        assert name in r.stdout
        assert "examples (" in p.format_help() and f"volanim {name}" in p.format_help()


@pytest.fixture
def vol_file(tmp_path):
    v = np.zeros((12, 10, 8), np.uint8, order="F")
    v[2:9, 2:8, 2:6] = 100
    v[4:6, 4:6, 3:5] = 0  # a cavity
    v[3, 3, 3] = 200
    path = tmp_path / "in.VOL"
    io.write_volume(path, v)
    return path, v


def test_threshold_fill_crop_chain(tmp_path, vol_file, capsys):
    path, v = vol_file
    assert main(["threshold", str(path), str(tmp_path / "m.VOL"), "--range", "50:150"]) == 0
    m = io.read_volume(tmp_path / "m.VOL")
    assert set(np.unique(m)) == {0, 255} and m[3, 3, 3] == 0
    assert main(["fill", str(tmp_path / "m.VOL"), str(tmp_path / "f.VOL"), "--cavities"]) == 0
    assert "filled 9 cavity voxels" in capsys.readouterr().out  # 8 cavity + the 200 voxel
    assert main(["crop", str(tmp_path / "f.VOL"), str(tmp_path / "c.nrrd"), "--pad", "1"]) == 0
    c = io.read_volume(tmp_path / "c.nrrd")
    assert c.shape == (9, 8, 6) and c.sum() == 255 * 7 * 6 * 4


def test_count_streams_and_header_tools(tmp_path, vol_file, capsys):
    path, v = vol_file
    assert main(["rmheader", str(path), str(tmp_path / "r.12x10x8.vol")]) == 0
    assert main(["count", str(tmp_path / "r.12x10x8.vol")]) == 0
    out = capsys.readouterr().out
    assert f"100 {int((v == 100).sum())}" in out and "200 1" in out
    assert main(["addheader", str(tmp_path / "r.12x10x8.vol"), str(tmp_path / "a.VOL")]) == 0
    assert (tmp_path / "a.VOL").read_bytes() == path.read_bytes()


def test_other_tools_run(tmp_path, vol_file, capsys):
    path, v = vol_file
    (tmp_path / "table.txt").write_text("100 7\n200 9\n")
    for args in (["info", path], ["tightbounds", path], ["flip", path, tmp_path / "x.VOL", "--axis", "z"],
                 ["reverse", path, tmp_path / "r.VOL"], ["remap", path, tmp_path / "m.VOL", "--table",
                 tmp_path / "table.txt"], ["fitpow2", path, tmp_path / "p.vti"],
                 ["diff", path, tmp_path / "x.VOL", tmp_path / "d.VOL"],
                 ["convert", path, tmp_path / "c.vti"], ["float2uchar", tmp_path / "c.vti", tmp_path / "u.VOL"]):
        assert main([str(a) for a in args]) == 0, args
    assert set(np.unique(io.read_volume(tmp_path / "m.VOL"))) == {0, 7, 9}
    assert io.read_volume(tmp_path / "p.vti").shape == (16, 16, 8)
    assert "2 2 2 9 8 6" in capsys.readouterr().out  # tight bounds as crop takes them: the stop excluded


def test_crop_and_fill_exclude_the_stop_as_the_thesis_does(tmp_path, capsys):
    """The thesis's CropVolume and Fill (A.13) run "up to, but not including" the stop; volanim included it, so
    ``fill --box 0 0 0 2 2 2`` set 27 voxels, not 8, and the one-slice form gave two slices (#66)."""
    io.write_volume(tmp_path / "z.VOL", np.zeros((6, 5, 8), np.uint8))
    boxes = {"8": ["0", "0", "0", "2", "2", "2"], "slice": ["0", "0", "5", "6", "5", "6"]}
    assert main(["fill", str(tmp_path / "z.VOL"), str(tmp_path / "b.VOL"), "--box", *boxes["8"]]) == 0
    assert np.count_nonzero(io.read_volume(tmp_path / "b.VOL")) == 8  # counted by hand: 2 x 2 x 2
    assert main(["fill", str(tmp_path / "z.VOL"), str(tmp_path / "s.VOL"), "--box", *boxes["slice"]]) == 0
    s = io.read_volume(tmp_path / "s.VOL")
    assert np.count_nonzero(s) == 6 * 5 and np.flatnonzero(s.any(axis=(0, 1))).tolist() == [5]  # one slice
    assert main(["fill", str(tmp_path / "z.VOL"), str(tmp_path / "i.VOL"), "--box", *boxes["8"], "--inclusive"]) == 0
    assert np.count_nonzero(io.read_volume(tmp_path / "i.VOL")) == 27  # the old meaning, asked for
    v = np.arange(6 * 5 * 8, dtype=np.uint8).reshape(6, 5, 8)
    io.write_volume(tmp_path / "v.VOL", v)
    assert main(["crop", str(tmp_path / "v.VOL"), str(tmp_path / "c.nrrd"), "--bounds", *"1 1 1 3 3 3".split()]) == 0
    assert np.array_equal(io.read_volume(tmp_path / "c.nrrd"), v[1:3, 1:3, 1:3])  # numpy's slices mean the same
    capsys.readouterr()
    bad = run("fill", tmp_path / "z.VOL", tmp_path / "x.VOL", "--box", "0", "0", "0", "2", "0", "2")
    assert bad.returncode == 2 and "--box 0 0 0 2 0 2: the stop x1 y1 z1 is excluded" in bad.stderr
    assert not (tmp_path / "x.VOL").exists()
    # what tightbounds prints, crop takes: the chain crops to the tight box
    body = np.zeros((9, 9, 9), np.uint8)
    body[2:5, 3:7, 1:8] = 9
    io.write_volume(tmp_path / "t.VOL", body)
    assert main(["tightbounds", str(tmp_path / "t.VOL")]) == 0
    printed = capsys.readouterr().out.split()
    assert printed == ["2", "3", "1", "5", "7", "8"]
    assert main(["crop", str(tmp_path / "t.VOL"), str(tmp_path / "tc.nrrd"), "--bounds", *printed]) == 0
    assert np.array_equal(io.read_volume(tmp_path / "tc.nrrd"), body[2:5, 3:7, 1:8])


def test_bad_input_is_one_line_error_not_traceback(tmp_path):
    (tmp_path / "bad.VOL").write_bytes(b"12 10 8".ljust(100) + b"\0" * 5)
    r = run("info", tmp_path / "bad.VOL")
    assert r.returncode == 2
    assert "Traceback" not in r.stderr
    assert "bad.VOL" in r.stderr and "expected 1060" in r.stderr


def test_samples_command_writes_files(tmp_path):
    assert main(["samples", "aliascube", "-o", str(tmp_path)]) == 0
    counts = io.histogram_file(tmp_path / "aliascube.VOL")
    assert (counts[0], counts[50], counts[250]) == (872109, 612521, 612522)


# spec: docs/formats.md#remap
def test_remap_pairs_on_the_command_line_equal_the_table_file(tmp_path, vol_file):
    path, _ = vol_file
    (tmp_path / "table.txt").write_text("100 7\n200 9\n")
    assert main(["remap", str(path), str(tmp_path / "t.VOL"), "--table", str(tmp_path / "table.txt")]) == 0
    assert main(["remap", str(path), str(tmp_path / "p.VOL"), "--pairs", "100:7", "200:9"]) == 0
    assert np.array_equal(io.read_volume(tmp_path / "t.VOL"), io.read_volume(tmp_path / "p.VOL"))
    r = run("remap", path, tmp_path / "q.VOL", "--pairs", "300:1")
    assert r.returncode == 2 and "FROM:TO with values 0..255" in r.stderr


# spec: docs/formats.md#vol (a .vol cannot carry its size, so its name does)
def test_a_headerless_vol_output_is_named_by_its_size(tmp_path, vol_file, capsys):
    path, v = vol_file
    assert main(["flip", str(path), str(tmp_path / "out.vol"), "--axis", "x"]) == 0
    named = tmp_path / f"out.{v.shape[0]}x{v.shape[1]}x{v.shape[2]}.vol"
    assert named.is_file() and not (tmp_path / "out.vol").exists() and str(named) in capsys.readouterr().out
    assert np.array_equal(io.read_volume(named), v[::-1])  # readable with no --dims
    assert main(["flip", str(path), str(named), "--axis", "x"]) == 0  # a matching name is kept
    r = run("flip", path, tmp_path / "wrong.1x2x3.vol", "--axis", "x")
    assert r.returncode == 2 and "the name says 1x2x3" in r.stderr and not (tmp_path / "wrong.1x2x3.vol").exists()


def test_samples_walk_copies_the_clip_and_its_licence(tmp_path):
    from volanim_core.io.bvh_files import read_bvh

    assert main(["samples", "walk", "-o", str(tmp_path)]) == 0
    assert read_bvh(tmp_path / "walk.bvh").frames == 1064
    assert "MIT" in (tmp_path / "walk.bvh.LICENSE").read_text()


@pytest.mark.parametrize("name, licence, points", [("rabbit", "MIT", 644), ("spot", "CC0", 2930), ("bob", "CC0", 250)])
def test_the_creature_samples_are_closed_meshes_with_their_licences(tmp_path, name, licence, points):
    """#62's creatures nobody templated: copies of other projects' meshes, read by pyvista (VTK's reader, not
    ours), each closed -- so voxelize fills it -- and beside it the licence naming where it came from."""
    import pyvista as pv

    assert main(["samples", name, "-o", str(tmp_path)]) == 0
    mesh = pv.read(tmp_path / f"{name}.ply")
    assert mesh.n_points == points and mesh.n_open_edges == 0 and mesh.is_manifold
    text = (tmp_path / f"{name}.ply.LICENSE").read_text()
    assert licence in text and ("trimesh" in text if name == "rabbit" else "potpourri3d" in text)
    assert main(["voxelize", str(tmp_path / f"{name}.ply"), str(tmp_path / f"{name}.nrrd"), "--size", "64"]) == 0
    assert io.read_volume(tmp_path / f"{name}.nrrd").any()


def test_view_writes_a_picture_of_a_volume_and_of_a_mesh(tmp_path, vol_file, capsys):
    import imageio.v3 as iio

    path, _ = vol_file
    assert main(["view", str(path), "--screenshot", str(tmp_path / "v.png"), "--size", "160x120"]) == 0
    assert main(["isosurface", str(path), "-o", str(tmp_path / "hull.ply")]) == 0
    assert main(["view", str(tmp_path / "hull.ply"), "--screenshot", str(tmp_path / "m.png")]) == 0
    for png, size in (("v.png", (120, 160)), ("m.png", (600, 800))):
        image = iio.imread(tmp_path / png)
        assert image.shape[:2] == size and image[..., :3].max() > 100  # something drawn on black
    (tmp_path / "bad.ply").write_text("ply\nformat ascii 1.0\nelement vertex 2\nend_header\n1 2\n")
    r = run("view", tmp_path / "bad.ply", "--screenshot", tmp_path / "b.png")
    assert r.returncode == 2 and "bad.ply" in r.stderr and not (tmp_path / "b.png").exists()
