"""Skeletonization: DT, thinness, .mskel, against brute-force references."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

import naive
from volanim_core import io
from volanim_core.cli import main
from volanim_core.errors import Cancelled
from volanim_core.skeleton.skeletonize import distance_transform, skeletonize


def ball(n=21, r=8.0):
    c = (n - 1) / 2
    g = np.indices((n, n, n)) - c
    return (g**2).sum(0) <= r * r


def random_blob(rng, shape=(12, 11, 10)):
    noise = ndimage.gaussian_filter(rng.random(shape), 1.5)
    return noise > np.quantile(noise, 0.55)


def test_ball_skeleton_is_its_centre_with_dt_radius():
    s = skeletonize(ball())
    assert s.points[0].tolist() == [10, 10, 10]
    # ball = |g| <= 8: the nearest background centre is at offset (8, 1, 0), sqrt(65) away
    assert s.dt[0] == np.sqrt(65.0)
    top = s.at(s.thinness[0] - 0.3)
    assert np.abs(top.points - 10).max() <= 1


def test_cylinder_top_thinness_points_lie_on_axis():
    g = np.indices((40, 21, 21))
    cyl = ((g[1] - 10) ** 2 + (g[2] - 10) ** 2 <= 36) & (g[0] >= 5) & (g[0] < 35)
    s = skeletonize(cyl)
    top = s.points[: 20]
    assert (top[:, 1] == 10).all() and (top[:, 2] == 10).all()


def test_box_skeleton_is_symmetric():
    box = np.zeros((20, 16, 12), bool)
    box[2:18, 2:14, 2:10] = True
    s = skeletonize(box, min_thinness=0.2)
    pts = {tuple(p) for p in s.points.tolist()}
    mirrored = {(19 - x, y, z) for x, y, z in pts}
    assert pts == mirrored
    assert pts == {(x, 15 - y, z) for x, y, z in pts}
    assert pts == {(x, y, 11 - z) for x, y, z in pts}


@pytest.mark.parametrize("metric", ["euclid", "345"])
def test_dt_matches_brute_force_on_random_shapes(rng, metric):
    for _ in range(6):
        m = random_blob(rng)
        got = distance_transform(m, metric=metric).astype(np.float64)
        assert np.allclose(got, naive.distance_transform(m, metric), atol=1e-5)


@pytest.mark.parametrize("metric", ["euclid", "345"])
def test_thinness_matches_definition(rng, metric):
    m = random_blob(rng)
    s = skeletonize(m, metric=metric, min_thinness=-np.inf)
    assert len(s) == m.sum()
    dt = naive.distance_transform(m, metric)
    th = naive.thinness(dt)
    idx = tuple(s.points.T)
    assert np.allclose(s.dt, dt[idx]) and np.allclose(s.thinness, th[idx])


@pytest.mark.parametrize("metric", ["euclid", "345"])
def test_union_of_all_balls_is_exactly_the_mask(rng, metric):
    for _ in range(5):
        m = random_blob(rng)
        s = skeletonize(m, metric=metric, min_thinness=-np.inf)
        assert np.array_equal(naive.union_of_balls(s.points, s.dt, m.shape, metric), m)


def test_object_touching_border_and_all_ones():
    ones = np.ones((5, 7, 9), bool)
    dt = distance_transform(ones)
    assert dt[0, 3, 4] == 1 and dt[2, 3, 4] == 3 and dt.min() == 1  # outside counts as background
    s = skeletonize(ones, min_thinness=-np.inf)
    assert s.dt.max() == 3 and len(s) == ones.size
    assert distance_transform(ones, metric="345")[2, 3, 4] == 9


def test_sorted_ties_in_file_order_and_mskel_round_trip(tmp_path, rng):
    s = skeletonize(random_blob(rng, (20, 18, 16)), min_thinness=0)
    assert s.is_sorted()
    # ties keep file order: among equal thinness, z then y then x increase
    for t in np.unique(s.thinness):
        keys = [(p[2], p[1], p[0]) for p in s.points[s.thinness == t]]
        assert keys == sorted(keys)
    io.write_mskel(tmp_path / "s.mskel", s)
    assert io.read_mskel(tmp_path / "s.mskel") == s


@pytest.mark.parametrize(("mask", "words"), [
    (np.zeros((4, 4, 4), bool), "empty"),
    (np.ones((4, 4), bool), "3-D"),
    (np.array(["a"] * 8).reshape(2, 2, 2), "threshold it first"),
    (np.ones((2, 2, 2), complex), "threshold it first"),
])
def test_bad_masks(mask, words):
    with pytest.raises(ValueError, match=words):
        skeletonize(mask)


def test_progress_and_cancel():
    seen = []
    skeletonize(ball(), progress=lambda d, t: seen.append((d, t)))
    assert seen[0] == (0, 100) and seen[-1] == (100, 100)
    assert [d for d, _ in seen] == sorted(d for d, _ in seen)
    calls = []

    def cancel():
        calls.append(1)
        return len(calls) > 2

    with pytest.raises(Cancelled):
        skeletonize(ball(), cancel=cancel)


def test_cli_skeletonize_and_isosurface(tmp_path, capsys):
    v = (ball(24, 9) * 200).astype(np.uint8)
    v[0:3, 0:3, 0:3] = 50  # below the threshold band
    io.write_volume(tmp_path / "b.VOL", v)
    assert main(["skeletonize", str(tmp_path / "b.VOL"), "--threshold", "100:255", "-o",
                 str(tmp_path / "b.mskel")]) == 0
    s = io.read_mskel(tmp_path / "b.mskel")
    assert len(s) > 0 and s.points.min() > 3
    assert "points from" in capsys.readouterr().out
    assert main(["isosurface", str(tmp_path / "b.VOL"), "-o", str(tmp_path / "h.ply")]) == 0
    import pyvista as pv

    mesh = pv.read(tmp_path / "h.ply")
    assert mesh.n_points > 100 and mesh.is_manifold


def test_chamfer_two_passes_equal_the_brute_force_3_4_5_distance():
    """Each object voxel's distance to the nearest background voxel (outside the volume is
    background), 3a + b + c for offsets a >= b >= c, by brute force over every pair."""
    from volanim_core.skeleton._kernels import chamfer345

    rng = np.random.default_rng(11)
    mask = (rng.random((7, 8, 9)) < 0.8).astype(np.uint8)
    padded = np.pad(mask, 1)
    background = np.argwhere(padded == 0)
    got = chamfer345(mask.copy())
    for p in np.argwhere(mask):
        off = np.sort(np.abs(background - (p + 1)), axis=1)[:, ::-1]
        assert got[tuple(p)] == (3 * off[:, 0] + off[:, 1] + off[:, 2]).min()
    assert (got[mask == 0] == 0).all()


def test_no_euclidean_thinness_reaches_the_thesis_figure_5_17_top_level(rng):
    """Fig 5.17's caption says Euclidean at 1.50: impossible in voxels, so the thesis's units are chamfer's.

    Each neighbour's DT is at least DT(p) minus its step's length, so DT(p) - mean(neighbours' DT) is at most
    the mean step, (6 + 12*sqrt(2) + 8*sqrt(3)) / 26 = 1.416; a single voxel (all neighbours background,
    DT 1) has thinness 1, far below. docs/formats.md and docs/make_thesis_figures.py rely on this bound.
    """
    bound = (6 + 12 * np.sqrt(2) + 8 * np.sqrt(3)) / 26
    shapes = [random_blob(rng) for _ in range(4)] + [np.ones((9, 9, 9), bool), np.pad(np.ones((1, 1, 1), bool), 2)]
    for m in shapes:
        s = skeletonize(m, metric="euclid", min_thinness=-np.inf)
        assert s.thinness.max() <= bound + 1e-9
        assert not (s.thinness >= 1.5).any()
    chamfer = skeletonize(shapes[-2], metric="345", min_thinness=-np.inf)
    assert chamfer.thinness.max() >= 1.5  # in 3-4-5 units the caption's level exists
