"""peek, onevolume and addskel as processes, checked against the arrays they read (#43)."""

from __future__ import annotations

import numpy as np

from runnable import volanim
from volanim_core import io
from volanim_core.geometry import Geometry
from volanim_core.skeleton.points import Skeleton


def test_peek_prints_the_values_and_where_they_are(tmp_path):
    v = np.arange(4 * 5 * 6, dtype=np.uint8).reshape(4, 5, 6)
    io.write_volume(tmp_path / "v.nrrd", v, Geometry(spacing=(0.5, 0.5, 2.0), origin=(10, 0, -4)))
    r = volanim("peek", tmp_path / "v.nrrd", "1", "2", "3", "3", "4", "5")
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines() == [f"(1, 2, 3) = {v[1, 2, 3]}   at (10.5, 1, 2) mm",
                                     f"(3, 4, 5) = {v[3, 4, 5]}   at (11.5, 2, 6) mm"]
    out = volanim("peek", tmp_path / "v.nrrd", "4", "0", "0")
    assert out.returncode == 2 and "v.nrrd: voxel (4, 0, 0) is outside its 4x5x6 voxels" in out.stderr
    odd = volanim("peek", tmp_path / "v.nrrd", "1", "2")
    assert odd.returncode == 2 and "X Y Z triples" in odd.stderr


def test_onevolume_merges_a_numbered_series_above_a_threshold(tmp_path):
    rng = np.random.default_rng(2)
    parts = [rng.integers(0, 256, (6, 5, 4), dtype=np.uint8) for _ in range(3)]
    for k, p in enumerate(parts, start=1):
        io.write_volume(tmp_path / f"part.{k}.VOL", p)
    names = [tmp_path / f"part.{k}.VOL" for k in (3, 1, 2)]  # any order on the command line: taken by number
    r = volanim("onevolume", *names, "-o", tmp_path / "one.VOL", "--threshold", "200")
    assert r.returncode == 0, r.stderr
    expected = np.zeros_like(parts[0])
    for p in parts:
        expected = np.where(p >= 200, p, expected)  # the thesis: below the threshold is zeroed, equal stays
    assert (parts[1] == 200).any()  # the case that tells the two apart
    assert np.array_equal(io.read_volume(tmp_path / "one.VOL"), expected)
    assert volanim("onevolume", *names, "-o", tmp_path / "lab.VOL", "--threshold", "200", "--label").returncode == 0
    labels = np.zeros_like(parts[0])
    for k, p in enumerate(parts, start=1):
        labels[p >= 200] = k
    assert np.array_equal(io.read_volume(tmp_path / "lab.VOL"), labels)
    io.write_volume(tmp_path / "small.VOL", parts[0][:3])
    bad = volanim("onevolume", tmp_path / "part.1.VOL", tmp_path / "small.VOL", "-o", tmp_path / "x.VOL")
    assert bad.returncode == 2 and "small.VOL is 3x5x4 voxels" in bad.stderr and not (tmp_path / "x.VOL").exists()
    # 256 volumes cannot be labelled in a byte: refused before any is read (it read them all first)
    many = volanim("onevolume", *[tmp_path / f"missing.{k}.VOL" for k in range(256)], "-o", tmp_path / "x.VOL",
                   "--label")
    assert many.returncode == 2 and "--label numbers volumes 1..255" in many.stderr, many.stderr


def test_addskel_burns_points_in_through_physical_space_and_at_half_size(tmp_path):
    v = np.full((20, 16, 12), 10, np.uint8)
    scan = Geometry(spacing=(1.0, 1.0, 2.0), origin=(5, 5, 5))
    io.write_volume(tmp_path / "v.nrrd", v, scan)
    # a skeleton made on 1 mm cubes of that scan (as skeletonize resamples it): z indices are twice the scan's
    cubes = Geometry(spacing=(1.0, 1.0, 1.0), origin=(5, 5, 5))
    pts = np.array([[2, 3, 4], [10, 8, 18], [19, 15, 22]])
    io.write_mskel(tmp_path / "s.mskel", Skeleton(pts, [1.0, 2.0, 1.5], [0.9, 0.8, 0.7], geometry=cubes))
    r = volanim("addskel", tmp_path / "v.nrrd", tmp_path / "s.mskel", "-o", tmp_path / "o.nrrd", "--value", "200")
    assert r.returncode == 0, r.stderr
    o = io.read_volume(tmp_path / "o.nrrd")
    assert set(zip(*np.nonzero(o == 200))) == {(2, 3, 2), (10, 8, 9), (19, 15, 11)}
    assert (o == 10).sum() == v.size - 3
    assert volanim("addskel", tmp_path / "v.nrrd", tmp_path / "s.mskel", "-o", tmp_path / "h.nrrd",
                   "--half-grid").returncode == 0
    h = io.read_scan(tmp_path / "h.nrrd")
    assert h.data.shape == (10, 8, 6) and np.allclose(h.geometry.spacing, (2, 2, 4))
    assert set(zip(*np.nonzero(h.data == 255))) == {(1, 1, 1), (5, 4, 4), (9, 7, 5)}
    # the thesis's Merger (A.28): the scan at half its intensity, the points at 250 over it
    merger = volanim("addskel", tmp_path / "v.nrrd", tmp_path / "s.mskel", "-o", tmp_path / "m.nrrd", "--half")
    assert merger.returncode == 0 and "at half its intensity" in merger.stdout
    m = io.read_volume(tmp_path / "m.nrrd")
    assert m.shape == v.shape and set(zip(*np.nonzero(m == 250))) == {(2, 3, 2), (10, 8, 9), (19, 15, 11)}
    assert (m == 5).sum() == v.size - 3
    io.write_skel(tmp_path / "far.skel", Skeleton(np.array([[500, 500, 500]]), [1.0], None))
    far = volanim("addskel", tmp_path / "v.nrrd", tmp_path / "far.skel", "-o", tmp_path / "x.nrrd")
    assert far.returncode == 2 and "far.skel: none of its 1 points is inside" in far.stderr
