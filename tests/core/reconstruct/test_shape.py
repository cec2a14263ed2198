"""The shape measures (reconstruct/shape.py) on volumes whose answers are counted by hand."""

from __future__ import annotations

import numpy as np

from volanim_core.reconstruct.shape import compare_shapes


def _capsule_pair() -> np.ndarray:
    """Two boxes meeting at a joint at (20, 10, 30): a trunk along z below it, a limb along x beside it."""
    v = np.zeros((60, 21, 61), np.uint8)
    v[12:29, 3:18, 0:31] = 1  # the trunk, x 12..28, z 0..30
    v[29:56, 6:15, 24:33] = 2  # the limb, x 29..55, z 24..32
    return v


JOINTS = {"HIP": np.array([20.0, 10, 0]), "SHOULDER": np.array([29.0, 10, 28]), "HAND": np.array([55.0, 10, 28])}
SEGMENTS = {"TRUNK": (JOINTS["HIP"], np.array([20.0, 10, 30])), "LIMB": (JOINTS["SHOULDER"], JOINTS["HAND"])}


def test_a_lump_under_the_limb_is_found_with_its_size_place_and_bone():
    truth = _capsule_pair()
    ours = truth.copy()
    ours[30:35, 7:12, 19:24] = 2  # a 5x5x5 lump hanging under the limb, next to the joint: 125 voxels
    ours[40:50, 5, 24:33] = 2  # and a one-voxel rim along the limb's side: not a blob
    r = compare_shapes(ours, truth, joints=JOINTS, segments=SEGMENTS)
    assert r.extra == 125 + 90 and r.missing == 0
    # opened by a one-voxel ball (6 neighbours): the cube keeps its 3x3x3 core and its six faces' 3x3 middles
    assert r.largest_extra.voxels == 27 + 6 * 9 and r.largest_missing is None
    assert r.largest_extra.centre == (32.0, 9.0, 21.0)
    assert r.largest_extra.near == "SHOULDER" and r.largest_extra.bone == "LIMB"
    # the limb's part: the truth's voxels nearer the limb's segment (x 29..55 on the line y 10, z 28) than the trunk's
    x, y, z = np.argwhere(truth > 0).T
    to_limb = (np.clip(x, 29, 55) - x) ** 2 + (y - 10) ** 2 + (z - 28) ** 2
    to_trunk = (x - 20) ** 2 + (y - 10) ** 2 + (np.clip(z, 0, 30) - z) ** 2
    assert r.largest_extra.share == 81 / int((to_limb < to_trunk).sum())
    assert 0.98 < r.dice < 1


def test_a_missing_piece_and_an_offset_grid():
    """The same volumes on grids with other origins compare as placed; a notch cut out is a missing blob."""
    truth = _capsule_pair()
    ours = truth[5:, 2:, :].copy()  # ours starts at voxel (5, 2, 0) of the frame
    ours[40:46, 4:10, 24:30] = 0  # a 6x6x6 notch out of the limb's corner: frame x 45..50, y 6..11, z 24..29
    r = compare_shapes(ours, truth, ours_origin=(5, 2, 0), joints=JOINTS, segments=SEGMENTS)
    notch = int(truth[45:51, 6:12, 24:30].astype(bool).sum())  # the limb starts at y 6: all 216 are body
    assert notch == 216 and r.missing == notch and r.extra == 0 and r.largest_extra is None
    assert r.largest_missing.voxels == 4 ** 3 + 6 * 4 ** 2 and r.largest_missing.bone == "LIMB"  # opened
    assert r.largest_missing.centre == (47.5, 8.5, 26.5) and r.largest_missing.near == "HAND"


def test_surface_distance_of_two_concentric_balls_is_their_radii_apart():
    g = np.indices((61, 61, 61)) - 30
    d = np.sqrt((g ** 2).sum(0))
    r = compare_shapes((d < 20).astype(np.uint8), (d < 17).astype(np.uint8), spacing=(0.5, 0.5, 0.5))
    assert 2.5 < r.surface_mean < 3.5 and 2.5 < r.surface_p95 < 4.0  # 3 voxels apart
    assert abs(r.surface_mean_mm - r.surface_mean / 2) < 0.01
    assert r.extra == int(((d < 20) & (d >= 17)).sum()) and r.missing == 0
    same = compare_shapes((d < 17).astype(np.uint8), (d < 17).astype(np.uint8))
    assert same.dice == 1 and same.surface_p95 == 0 and same.largest_extra is None


def test_tissue_agreement_counts_the_shared_voxels_with_the_truth_s_value():
    truth = _capsule_pair() * 100
    ours = truth.copy()
    ours[12:29, 3:18, 0:10] = 50  # 17 * 15 * 10 of the trunk's 17 * 15 * 31 shared voxels: another tissue
    r = compare_shapes(ours, truth, tissue=True)
    shared = int((truth > 0).sum())
    assert abs(r.tissue - (1 - 17 * 15 * 10 / shared)) < 1e-12 and r.dice == 1
    assert compare_shapes(ours, truth).tissue is None


def test_progress_counts_every_step_and_cancel_stops_it():
    """compare_shapes takes seconds on a large body: it reports each step and can be stopped (#60)."""
    import pytest

    from volanim_core.errors import Cancelled

    body = _capsule_pair()
    seen = []
    compare_shapes(body, body, progress=lambda done, total: seen.append((done, total)))
    assert seen == [(0, 5), (1, 5), (2, 5), (3, 5), (4, 5), (5, 5)]
    calls = []

    def cancel():
        calls.append(1)
        return len(calls) > 2  # after the grid and the first blob

    with pytest.raises(Cancelled):
        compare_shapes(body, body, cancel=cancel)
