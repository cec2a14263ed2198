"""reconstruct() refuses what it cannot do, with a message a user understands, and never hangs.

Each test failed before its guard existed (a wrapped int64, an exabyte
allocation, a walk over a clipped sphere's whole box, out-of-bounds reads).
"""

from __future__ import annotations

import time

import numpy as np
import pytest

from volanim_core.reconstruct.engine import grid_bounds, reconstruct
from volanim_core.rig.connectivity import BoneSegment, Tskel
from volanim_core.skeleton.skeletonize import skeletonize
from volanim_core.volume import Bounds

BONES = [BoneSegment((0, 0, 0), (1, 0, 0), "A")]


def frame(points, dt, matrix=None, metric="euclid") -> Tskel:
    m = np.eye(4) if matrix is None else np.asarray(matrix, np.float64)
    return Tskel(BONES, m[None], points, dt, None, np.zeros(len(dt), np.int32), metric)


@pytest.mark.parametrize("metric", ["euclid", "345"])
def test_clipped_voxels_are_counted_exactly_per_row(metric):
    """Clipped + filled = the whole sphere, for spheres cut by every face of the bounds."""
    rng = np.random.default_rng(3)
    pts = rng.integers(0, 30, (25, 3))
    t = frame(pts, rng.uniform(1, 9, 25), metric=metric)
    whole = reconstruct(t, mode="hotspot")
    for lo, hi in [((5, 0, 0), (40, 40, 40)), ((0, 7, 3), (20, 19, 25)), ((10, 10, 10), (12, 30, 11))]:
        part = reconstruct(t, mode="hotspot", bounds=Bounds(lo, hi))
        assert not part.stats["clipped_estimated"]
        assert int(part.volume.sum()) + part.stats["clipped"] == int(whole.volume.sum())


def test_a_huge_radius_is_refused_with_the_output_size():
    with pytest.raises(ValueError, match=r"output grid would be 2000005x2000005x2000005 = .* voxels \(.*EB\)"):
        reconstruct(frame([[5, 5, 5]], [1e6]))


def test_a_huge_radius_in_small_bounds_finishes_and_estimates_what_it_clipped():
    t0 = time.perf_counter()
    r = reconstruct(frame([[5, 5, 5]], [1e6]), bounds=Bounds((0, 0, 0), (20, 20, 20)))
    assert time.perf_counter() - t0 < 120  # it used to walk 8e18 voxels
    assert r.stats["filled"] == 21**3 and r.stats["clipped_estimated"]
    assert r.stats["clipped"] == pytest.approx(4 / 3 * np.pi * 1e18, rel=1e-3)


@pytest.mark.parametrize("points, dt, message", [
    ([[1e300, 0, 0]], [1.0], "is not a voxel"),
    ([[np.nan, 0, 0]], [1.0], "is not a voxel"),
    ([[3e9, 0, 0]], [1.0], "is not a voxel"),
    (np.array([[0, 2**31 - 1, 0]], np.int32), [1.0], "is not a voxel"),  # integers: found by their min and max
    (np.array([[0, 0, -(2**40)]], np.int64), [1.0], "is not a voxel"),
    (np.array([[0, 0, 2**63 + 5]], np.uint64), [1.0], "is not a voxel"),
    ([[0, 0, 0]], [1e300], "reaches 1e\\+300 voxels"),
    ([[0, 0, 0]], [np.nan], "NaN, infinite or negative"),
    ([[0, 0, 0]], [-2.0], "NaN, infinite or negative"),
])
def test_unplaceable_points_are_refused(points, dt, message):
    """Coordinates are refused when the frame is built (they used to wrap to -2147483648)."""
    with pytest.raises(ValueError, match=message):
        reconstruct(frame(points, dt))


def test_bounds_of_an_unplaceable_sphere_are_refused_not_wrapped():
    with pytest.raises(ValueError, match="reaches"):
        grid_bounds(frame([[5, 5, 5]], [1e300]))


@pytest.mark.parametrize("matrix, message", [
    ([[1, 0, 0, 0.5], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], "not affine"),
    ([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [np.nan, 0, 0, 1]], "NaN or infinite"),
    ([[1, 0, 0, 0], [0, 0, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], "singular"),
    ([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [1e300, 0, 0, 1]], "reaches"),
])
def test_bad_matrices_are_refused_naming_the_bone(matrix, message):
    with pytest.raises(ValueError, match=f"{message}") as info:
        reconstruct(frame([[5, 5, 5]], [2.0], matrix))
    assert "bone 0 (A)" in str(info.value) or message == "reaches"


@pytest.mark.parametrize("neighbours", [np.zeros((2, 3), np.int32), np.full((1, 3), 7, np.int32),
                                        np.zeros(3, np.int32), np.zeros((1, 3), np.float64)])
def test_neighbour_lists_of_the_wrong_shape_or_range_are_refused(neighbours):
    with pytest.raises(ValueError, match="neighbours must be"):
        reconstruct(frame([[5, 5, 5]], [2.0]), neighbours=neighbours)


@pytest.mark.parametrize("dtype", [object, np.complex128])
def test_sampled_mode_refuses_non_numeric_sources(dtype):
    with pytest.raises(ValueError, match="source voxels must be numbers"):
        reconstruct(frame([[5, 5, 5]], [2.0]), mode="sampled", source=np.zeros((9, 9, 9), dtype))


def test_skeletonize_refuses_a_nan_minimum_thinness():
    ball = np.zeros((9, 9, 9), bool)
    ball[2:7, 2:7, 2:7] = True
    with pytest.raises(ValueError, match="min_thinness is NaN"):
        skeletonize(ball, min_thinness=float("nan"))
    assert len(skeletonize(ball, min_thinness=-np.inf)) == int(ball.sum())


@pytest.mark.parametrize("bounds", [None, Bounds((0, 0, 0), (9, 9, 9))])
def test_a_pose_that_carries_a_sphere_out_of_reach_is_refused_with_or_without_bounds(bounds):
    """The posed reach is checked once a call: by grid_bounds when it makes the bounds, by the call
    itself when the caller gives them."""
    far = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [1e300, 0, 0, 1]]
    with pytest.raises(ValueError, match="once posed .* reaches"):
        reconstruct(frame([[5, 5, 5]], [2.0], far), bounds=bounds)
