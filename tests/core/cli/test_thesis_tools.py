"""The thesis's small tools as processes (#43): good input, bad input refused with the file named."""

from __future__ import annotations

import numpy as np
import pytest

from runnable import volanim
from volanim_core import io


def _vol(path, v):
    io.write_volume(path, np.asarray(v, np.uint8, order="F"))
    return path


# spec: docs/formats.md#diff
def test_diff_reports_changed_values_and_a_summary(tmp_path):
    a = np.zeros((6, 5, 4), np.uint8)
    a[1:5, 1:4, 1:3] = 100
    b = a // 2  # every value changed, nothing added or removed
    b[0, 0, 0] = 9  # one voxel only in the second
    r = volanim("diff", _vol(tmp_path / "a.VOL", a), _vol(tmp_path / "b.VOL", b), tmp_path / "d.VOL")
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert "200 both, changed  24" in lines and "150 only second    1" in lines
    assert "25 of 120 voxels differ" in r.stdout
    d = io.read_volume(tmp_path / "d.VOL")
    assert np.array_equal(d, np.where(a > 0, 200, 0) + np.pad([[[150]]], ((0, 5), (0, 4), (0, 3))))
    same = volanim("diff", tmp_path / "a.VOL", tmp_path / "a.VOL")
    assert same.returncode == 0 and "identical: all 120 voxels" in same.stdout
    bad = volanim("diff", tmp_path / "a.VOL", _vol(tmp_path / "small.VOL", a[:3]))
    assert bad.returncode == 2 and "6x5x4 voxels but" in bad.stderr and "small.VOL is 3x5x4" in bad.stderr


# spec: docs/formats.md#skel
@pytest.mark.slow
def test_a_thesis_skel_is_written_and_read_by_every_skeleton_tool(skeletonized_mannequin):
    d = skeletonized_mannequin
    r = volanim("skeletonize", d / "mannequin.VOL", "--min-thinness", "0.5", "-o", d / "m.skel")
    assert r.returncode == 0, r.stderr
    rows = [line.split() for line in (d / "m.skel").read_text().splitlines() if not line.startswith("#")]
    assert {len(row) for row in rows} == {4}  # x y z dt: no thinness column
    at = io.read_mskel(d / "m.mskel").at(0.5)
    assert np.array_equal(np.array([[int(v) for v in row[:3]] for row in rows]), at.points)
    assert np.allclose([float(row[3]) for row in rows], at.dt, atol=1e-4)

    # the thesis's own kind of file: bare rows, no header, in another order
    order = np.random.default_rng(3).permutation(len(at))
    (d / "thesis.skel").write_text("".join(f"{x} {y} {z} {r:.4f}\n" for (x, y, z), r in
                                           zip(at.points[order], at.dt[order])))
    a = volanim("connect", d / "thesis.skel", d / "mannequin.bones", "-o", d / "s.connect")
    b = volanim("connect", d / "m.mskel", d / "mannequin.bones", "--thinness", "0.5", "-o", d / "m.connect")
    assert a.returncode == 0 and b.returncode == 0, a.stderr + b.stderr
    cs, cm = io.read_connect(d / "s.connect"), io.read_connect(d / "m.connect")
    bone_s = {tuple(p): cs.bone[i] for i, p in enumerate(cs.points)}
    assert len(cs) == len(cm) == len(at)
    assert all(bone_s[tuple(p)] == cm.bone[i] for i, p in enumerate(cm.points))
    t = volanim("connect2identitytskel", d / "s.connect", "-o", d / "s.tskel")
    rec = volanim("reconstruct", d / "s.tskel", "-o", d / "s.vti")
    assert t.returncode == 0 and rec.returncode == 0, t.stderr + rec.stderr
    assert volanim("autorig", d / "thesis.skel", "-o", d / "a.bones").returncode == 0

    refused = volanim("connect", d / "thesis.skel", d / "mannequin.bones", "--thinness", "1", "-o", d / "x.connect")
    assert refused.returncode == 2 and "thesis.skel: a .skel holds one resolution" in refused.stderr
    assert not (d / "x.connect").exists()
    (d / "bad.skel").write_text("1 2 3 1.5\n4 5 6\n")
    bad = volanim("connect", d / "bad.skel", d / "mannequin.bones", "-o", d / "x.connect")
    assert bad.returncode == 2 and "bad.skel:2" in bad.stderr


def test_rmheader_takes_a_header_size_as_the_thesis_rmhdr_did(tmp_path):
    v = np.random.default_rng(5).integers(0, 256, (7, 6, 5), dtype=np.uint8)
    raw = np.ascontiguousarray(v.transpose(2, 1, 0)).tobytes()
    (tmp_path / "scanner.img").write_bytes(b"SCANNER HEADER".ljust(512, b"\0") + raw)  # another header, 512 bytes
    r = volanim("rmheader", tmp_path / "scanner.img", tmp_path / "s.7x6x5.vol", "--header-size", "512",
                "--dims", "7", "6", "5")
    assert r.returncode == 0, r.stderr
    assert "7x6x5, no header" in r.stdout
    assert np.array_equal(io.read_volume(tmp_path / "s.7x6x5.vol"), v)
    bare = volanim("rmheader", tmp_path / "scanner.img", tmp_path / "bare.raw", "--header-size", "512")
    assert bare.returncode == 0 and (tmp_path / "bare.raw").read_bytes() == raw
    wrong = volanim("rmheader", tmp_path / "scanner.img", tmp_path / "w.vol", "--header-size", "500",
                    "--dims", "7", "6", "5")
    assert wrong.returncode == 2 and "scanner.img" in wrong.stderr and "500-byte header" in wrong.stderr
    assert not (tmp_path / "w.vol").exists()
    big = volanim("rmheader", tmp_path / "scanner.img", tmp_path / "w.vol", "--header-size", "99999")
    assert big.returncode == 2 and "leaves no voxels" in big.stderr
    # --dims checks what --header-size leaves; on a .VOL the header sizes it, and --dims was ignored silently
    io.write_volume(tmp_path / "v.VOL", v)
    unchecked = volanim("rmheader", tmp_path / "v.VOL", tmp_path / "w.vol", "--dims", "1", "2", "3")
    assert unchecked.returncode == 2 and "--dims goes with --header-size" in unchecked.stderr
    assert not (tmp_path / "w.vol").exists()


# spec: docs/formats.md#remap
def test_remap_reads_the_thesis_255_line_tables(tmp_path):
    v = np.arange(256, dtype=np.uint8).repeat(2).reshape(8, 8, 8)
    (tmp_path / "t255.txt").write_text("".join(f"{(k * 7) % 256}\n" for k in range(255)))
    r = volanim("remap", _vol(tmp_path / "v.VOL", v), tmp_path / "o.VOL", "--table", tmp_path / "t255.txt")
    assert r.returncode == 0, r.stderr
    expected = np.where(v == 255, 255, (v.astype(int) * 7) % 256)
    assert np.array_equal(io.read_volume(tmp_path / "o.VOL"), expected)
    (tmp_path / "t200.txt").write_text("1\n" * 200)
    bad = volanim("remap", tmp_path / "v.VOL", tmp_path / "x.VOL", "--table", tmp_path / "t200.txt")
    assert bad.returncode == 2 and "t200.txt" in bad.stderr and "got 200" in bad.stderr


# spec: docs/formats.md#alpha
def test_alpha_interpolate_numbers_its_maps_from_a_start_index(tmp_path):
    (tmp_path / "a.alpha").write_text("0 0\n255 1\n")
    (tmp_path / "b.alpha").write_text("0 1\n255 0\n")
    r = volanim("alpha", "interpolate", tmp_path / "a.alpha", tmp_path / "b.alpha", "-n", "3", "--start", "98",
                "-o", tmp_path / "fade")
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in tmp_path.glob("fade-*")) == ["fade-098.alpha", "fade-099.alpha", "fade-100.alpha"]
    # map k of 3 is a quarter, a half, three quarters of the way: at index 0 the alpha goes 0 -> 1
    from volanim_core.io.palette_files import read_alpha_map

    firsts = [read_alpha_map(tmp_path / f"fade-{k:03d}.alpha")[1][0] for k in (98, 99, 100)]
    assert np.allclose(firsts, [0.25, 0.5, 0.75])
    bad = volanim("alpha", "interpolate", tmp_path / "a.alpha", tmp_path / "b.alpha", "-n", "3", "--start", "-1",
                  "-o", tmp_path / "x")
    assert bad.returncode == 2 and "expected 0 or more" in bad.stderr
