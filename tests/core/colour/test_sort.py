"""Palette orderings: each is a permutation, the remap round-trips, the scores mean what they say,
and our path ordering beats the thesis's best (SuperGradientSort after intensity)."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core import volume
from volanim_core.colour import sort as S
from volanim_core.colour.palette import NearestColour, build_palette, unique_colours
from volanim_core.colour.space import delta_e


def photo_palette(n=64, picture="coffee"):
    from skimage import data

    img = getattr(data, picture)()
    palette = build_palette(*unique_colours(img), n)
    return palette, NearestColour(palette)(img)[:, :, None]


@pytest.mark.parametrize("keep_first", [False, True])
@pytest.mark.parametrize("method", S.METHODS)
def test_every_ordering_is_a_permutation(rng, method, keep_first):
    for n in (1, 2, 3, 40):
        palette = rng.integers(0, 256, (n, 3)).astype(np.uint8)
        order = S.sort_palette(palette, method, keep_first=keep_first)
        assert sorted(order.tolist()) == list(range(n)), (method, n)
        if keep_first:
            assert order[0] == 0


def test_the_remap_round_trips(rng):
    palette, index = photo_palette()
    shuffled = rng.permutation(len(palette))
    palette = palette[shuffled]
    index = np.argsort(shuffled)[index].astype(np.uint8)  # the same picture through the shuffled palette
    order = S.sort_palette(palette, "path")
    table = S.remap_table(order)
    remapped = volume.remap(index, table)
    assert np.array_equal(palette[order][remapped], palette[index])  # every voxel keeps its colour
    back = np.argsort(table[: len(palette)])  # new -> old
    assert np.array_equal(back[remapped], index)


def test_intensity_and_radix_orders_are_what_they_say(rng):
    from volanim_core.colour.space import to_lab

    palette = rng.integers(0, 256, (30, 3)).astype(np.uint8)
    assert np.all(np.diff(palette[S.sort_palette(palette, "intensity")].astype(int).sum(axis=1)) >= 0)
    assert np.all(np.diff(to_lab(palette[S.sort_palette(palette, "lightness")])[:, 0]) >= 0)
    keys = [tuple(c) for c in palette[S.sort_palette(palette, "rgb-radix")]]
    assert keys == sorted(keys)


def test_intensity_is_the_thesis_s_r_plus_g_plus_b_not_lightness():
    """Section 4.2: intensity is R + G + B. Green (0, 255, 0) sums to 255 and magenta (200, 0, 200) to 400, so
    green comes first; by CIELAB lightness (volanim's `intensity` before #66, now `lightness`) magenta does."""
    palette = np.array([[200, 0, 200], [0, 255, 0]], np.uint8)
    assert S.sort_palette(palette, "intensity").tolist() == [1, 0]
    assert S.sort_palette(palette, "lightness").tolist() == [0, 1]


def test_cluster_sort_by_hand():
    """ClusterSort, counted by hand: intensities 0, 30, 60, 90, 300, 330 -> with a seed every 4 colours the
    seeds are the 1st and 5th (0 and 300); 30, 60 and 90 are nearer seed 0, 330 nearer seed 300; each cell
    follows its seed, nearest first; a seed every 2 colours makes three cells."""
    palette = np.array([[110, 110, 110], [0, 0, 0], [30, 30, 30], [100, 100, 100], [20, 20, 20], [10, 10, 10]],
                       np.uint8)  # intensities 330, 0, 90, 300, 60, 30
    assert S.thesis_cluster(palette, 4).tolist() == [1, 5, 4, 2, 3, 0]
    # seeds every 2: intensity order 1 (0), 5 (30), 4 (60), 2 (90), 3 (300), 0 (330) -> seeds 1, 4, 3
    assert S.thesis_cluster(palette, 2).tolist() == [1, 5, 4, 2, 3, 0]
    with pytest.raises(ValueError, match="interval"):
        S.thesis_cluster(palette, 0)
    # seeds every 3: 0 and 90; 30 is nearer 0, 60 and 95 nearer 90, and in 90's cell 95 (5 away) comes first
    spread = np.array([[0, 0, 0], [30, 0, 0], [60, 0, 0], [90, 0, 0], [95, 0, 0]], np.uint8)
    assert S.thesis_cluster(spread, 3).tolist() == [0, 1, 3, 4, 2]


def test_gradient_sort_penalises_turning_back():
    """GradientSort's D + 2P, counted by hand: from black the walk goes up red to (50, 0, 0) and (100, 0, 0)
    ((92, 30, 0) is 51.6 from (50, 0, 0), not 50). There, (92, 30, 0) is 31.0 away but turns back 8 in R: cost
    31.0 + 2 x 8 = 47.0; (100, 0, 38) is 38 away without turning: cost 38, so it is next. Without the
    penalty the nearer one is."""
    palette = np.array([[0, 0, 0], [50, 0, 0], [100, 0, 0], [92, 30, 0], [100, 0, 38]], np.uint8)
    assert S.thesis_gradient(palette).tolist()[:4] == [0, 1, 2, 4]
    assert S.thesis_gradient(palette, penalty=0.0).tolist()[:4] == [0, 1, 2, 3]


def test_supergradient_follows_the_line_its_last_two_colours_make():
    """SuperGradientSort, counted by hand: after black and (10, 10, 10) the line runs through (20, 20, 20),
    (30, 30, 30), ... with steps of 17.3. (0, 25, 0) is nearer (10, 10, 10) (20.6) than (40, 40, 40) is (52),
    but it is 28.7 from the line's first point; (40, 40, 40) is within a step of its second, so it is next;
    from there the line finds nothing in 20 steps, and the walk takes the nearest colour."""
    palette = np.array([[0, 0, 0], [10, 10, 10], [0, 25, 0], [40, 40, 40], [200, 0, 0]], np.uint8)
    assert S.thesis_supergradient(palette).tolist() == [0, 1, 3, 2, 4]
    # 20 steps along the line at most: a colour 30 steps out is not found by it
    far = np.array([[0, 0, 0], [1, 1, 1], [31, 31, 31], [0, 9, 0]], np.uint8)
    assert S.thesis_supergradient(far).tolist() == [0, 1, 3, 2]


def test_a_colour_ramp_shuffled_is_sorted_back_to_a_ramp(rng):
    ramp = np.stack([np.linspace(0, 250, 40), np.linspace(20, 120, 40), np.linspace(200, 40, 40)], 1).astype(np.uint8)
    shuffled = ramp[rng.permutation(40)]
    order = S.sort_palette(shuffled, "path")
    got = shuffled[order]
    assert np.array_equal(got, ramp) or np.array_equal(got, ramp[::-1])


def test_neighbour_scores_and_midpoint_error_by_hand():
    palette = np.array([[0, 0, 0], [255, 255, 255], [128, 128, 128]], np.uint8)
    order = np.array([0, 2, 1])
    de = S.neighbour_differences(palette, order)
    assert de == pytest.approx(delta_e(palette[[0, 2]], palette[[2, 1]]))
    # black and white touch: halfway the renderer shows index 1 of [black, grey, white] = grey = their blend
    pairs, weights = np.array([[0, 1]]), np.array([1.0])
    assert S.midpoint_error(palette, order, pairs, weights) == pytest.approx(delta_e(
        np.array([[128, 128, 128]], np.uint8), np.array([[127.5, 127.5, 127.5]]))[0], abs=1e-6)
    # unsorted, black (0) and white (1) are neighbours: the blend is shown exactly
    assert S.midpoint_error(palette, np.arange(3), pairs, weights) == pytest.approx(0, abs=1e-9)


def test_colour_pairs_count_face_neighbours():
    vol = np.array([[[0, 1], [1, 1]], [[2, 2], [2, 0]]], np.uint8)
    pairs, counts = S.colour_pairs(vol, 3)
    got = {tuple(p): int(c) for p, c in zip(pairs, counts)}
    # by hand: x-neighbours (0,2) (1,2) (1,2) (1,0); y-neighbours (0,1) (1,1) (2,2) (2,0); z: (0,1) (1,1) (2,2) (2,0)
    assert got == {(0, 1): 3, (0, 2): 3, (1, 2): 2}


@pytest.mark.parametrize("picture", ["coffee", "chelsea", "astronaut"])
def test_ours_beat_supergradient_on_a_photograph(picture):
    """The thesis's best ordering is the baseline: ours make smaller steps between neighbouring indices
    (sum and maximum), and ramp's midpoint error is at most 5 % above it (below it on most data:
    bench_colour)."""
    palette, index = photo_palette(128, picture)
    pairs, weights = S.colour_pairs(index, len(palette))
    scores = {m: S.score(palette, S.sort_palette(palette, m), pairs, weights) for m in ("supergradient", "ramp",
                                                                                       "path")}
    base = scores["supergradient"]
    assert scores["ramp"]["sum"] < base["sum"] and scores["ramp"]["max"] <= base["max"]
    assert scores["ramp"]["midpoint"] < 1.05 * base["midpoint"]
    assert scores["path"]["sum"] < base["sum"] and scores["path"]["max"] <= base["max"]
    unsorted = S.score(palette, np.random.default_rng(3).permutation(len(palette)), pairs, weights)
    assert scores["ramp"]["midpoint"] < unsorted["midpoint"] / 2


def test_an_unknown_method_is_refused():
    with pytest.raises(ValueError, match="sort method must be one of"):
        S.sort_palette(np.zeros((3, 3), np.uint8), "bogus")
