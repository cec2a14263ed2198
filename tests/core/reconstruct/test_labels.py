"""The breakage report's pieces, found on x-runs: against scipy's voxel labelling and brute force."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage
from tests import naive

from volanim_core.reconstruct import _label_kernels as L
from volanim_core.reconstruct import breakage
from volanim_core.reconstruct.shape import piece_count

SHAPES = [(1, 1, 1), (1, 1, 6), (3, 1, 7), (1, 9, 1), (5, 6, 7), (20, 20, 20), (7, 30, 2), (33, 17, 29)]


def noise(shape, density, seed):
    values = np.random.default_rng(seed).integers(1, 200, shape).astype(np.uint8)
    return np.where(np.random.default_rng(seed + 1).random(shape) < density, values, 0).astype(np.uint8)


@pytest.mark.parametrize("shape", SHAPES)
@pytest.mark.parametrize("density", [0.0, 0.1, 0.35, 0.6, 1.0])
def test_pieces_are_scipys_26_connected_labels_in_the_same_order(shape, density):
    zyx = noise(shape, density, seed=sum(shape) + int(100 * density))
    first, x0, x1, piece, n = L.label_runs(zyx)
    want, m = ndimage.label(zyx, structure=np.ones((3, 3, 3), bool))
    assert n == m
    assert np.array_equal(naive.paint_runs(shape, first, x0, x1, piece), want)


@pytest.mark.parametrize("shape", SHAPES)
@pytest.mark.parametrize("density", [0.0, 0.2, 0.5])
def test_piece_count_is_scipys_for_any_layout_of_mask(shape, density):
    """#83: the studio counts a body's pieces (the rest pose re-grown, the segmented mask) with these kernels
    instead of scipy's label, which held the GIL 0.5 s a call on mannequin-large. ``[x, y, z]`` masks, boolean
    or not, in either memory order: scipy's count every time."""
    mask = noise(shape, density, seed=3 + sum(shape)) > 0
    want = ndimage.label(mask, structure=np.ones((3, 3, 3), bool))[1]
    for m in (mask, np.asfortranarray(mask), mask.astype(np.uint8), np.asfortranarray(mask.astype(np.uint8))):
        assert piece_count(m) == want


def test_runs_that_touch_only_by_a_corner_or_an_edge_join():
    zyx = np.zeros((3, 4, 9), np.uint8)
    zyx[0, 0, 0:2] = 1
    zyx[1, 1, 2] = 1  # corner of the first: 26-connected
    zyx[1, 2, 5:7] = 1  # 2 apart in x from the voxel above it: a second piece
    zyx[2, 2, 7] = 1  # edge-adjacent (dz, dx) to the second
    zyx[0, 3, 4] = 1  # a corner of (1, 2, 5), in a row scanned before it: joins the second
    first, x0, x1, piece, n = L.label_runs(zyx)
    want, m = ndimage.label(zyx, structure=np.ones((3, 3, 3), bool))
    assert n == m == 2 and np.array_equal(naive.paint_runs(zyx.shape, first, x0, x1, piece), want)


@pytest.mark.parametrize("shape", SHAPES)
@pytest.mark.parametrize("density", [0.0, 0.35, 1.0])
def test_runs_by_value_are_the_longest_runs_of_one_label(shape, density):
    """A label grid (a rest volume's bones) cut into runs of one value each: painted back they are the
    grid, and no two runs of a row could be one (they are apart or hold other values)."""
    zyx = noise(shape, density, seed=7 + sum(shape))
    zyx //= 50  # few labels, so neighbours often share one
    first, x0, x1 = L.runs(zyx, True)
    value = L.run_values(zyx, first, x0)
    assert np.array_equal(naive.paint_runs(shape, first, x0, x1, value), zyx)
    for row in range(len(first) - 1):
        z, y = divmod(row, shape[1])
        for r in range(first[row], first[row + 1]):
            assert np.all(zyx[z, y, x0[r]:x1[r] + 1] == value[r]) and value[r] != 0
            if r + 1 < first[row + 1]:
                assert x0[r + 1] > x1[r] + 1 or value[r + 1] != value[r]
    plain = L.runs(zyx)  # without by_value: runs of non-zero voxels, whatever their values
    ones = np.ones(len(plain[1]), np.int64)
    assert np.array_equal(naive.paint_runs(shape, *plain, ones), (zyx != 0).astype(np.int64))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_counts_centroid_sums_voxels_and_boundary_of_every_piece(seed):
    zyx = noise((14, 16, 18), 0.3, seed)
    first, x0, x1, piece, n = L.label_runs(zyx)
    labels = naive.paint_runs(zyx.shape, first, x0, x1, piece)
    counts, sums = L.piece_stats(first, x0, x1, piece, n, zyx.shape[1])
    assert counts.tolist() == [0, *np.bincount(labels.ravel(), minlength=n + 1)[1:].tolist()]
    for k in range(1, n + 1):
        assert np.array_equal(sums[k], np.argwhere(labels == k).sum(0).astype(float))
    main = int(np.argmax(counts))
    start, voxels = L.piece_voxels(first, x0, x1, piece, counts, main, zyx.shape[1])
    for k in range(1, n + 1):
        want = np.argwhere(labels == k) if k != main else np.zeros((0, 3), np.int64)  # scan order
        assert np.array_equal(voxels[start[k]:start[k + 1]], want)
    # boundary: a voxel of the piece with an in-grid 6-neighbour outside it
    inside = labels == main
    edge = np.zeros_like(inside)
    for axis in range(3):
        for step in (1, -1):
            neighbour = np.roll(inside, -step, axis)
            valid = np.ones_like(inside)
            index = [slice(None)] * 3
            index[axis] = -1 if step == 1 else 0  # rolled in from the other side: not in the grid
            valid[tuple(index)] = False
            edge |= inside & valid & ~neighbour
    got = L.boundary_voxels(zyx, first, x0, x1, piece, main)
    assert np.array_equal(got, np.argwhere(edge))


def test_every_kernel_lets_other_threads_run():
    """The studio makes the report on a worker thread while its window draws: none of these may hold
    the GIL (cc3d, used before, froze the window for 0.3 s per frog preview)."""
    kernels = [L.runs, L.run_values, L.label_runs, L.piece_stats, L.group_starts, L.piece_voxels,
               L.boundary_voxels]
    assert all(k.targetoptions.get("nogil") for k in kernels)


def test_no_pieces_and_one_piece():
    assert breakage.components(np.zeros((4, 5, 6), np.uint8)) == []
    v = np.zeros((4, 5, 6), np.uint8)
    v[1:3, 2:4, 0:6] = 9
    got = breakage._components(v)[0]
    assert len(got) == 1 and got[0][0] == 24 and np.allclose(got[0][1], (1.5, 2.5, 2.5))
