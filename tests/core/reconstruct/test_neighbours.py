"""Neighbour lists are made only where the kernel uses them (spheres of radius >= CUT_MIN_RADIUS)."""

from __future__ import annotations

import numpy as np
from test_engine import random_tskel

from volanim_core.reconstruct.neighbours import CUT_MIN_RADIUS, sphere_neighbours
from volanim_core.reconstruct.radii import radius_squared


def test_only_spheres_the_kernel_clips_get_lists_and_those_lists_are_the_nearest_same_bone_spheres(rng):
    """#65: of any radius -- a smaller neighbour cuts a big sphere at their power plane."""
    t = random_tskel(rng, n=600, size=60, nbones=3)
    t.dt[:] = rng.uniform(1.0, 12.0, len(t.dt))
    nbrs = sphere_neighbours(t, k=4)
    r2 = radius_squared(t.dt)
    small = r2 < CUT_MIN_RADIUS**2
    assert small.any() and (~small).any()
    assert (nbrs[small] == -1).all()  # no work spent on lists the kernel never reads
    for i in np.flatnonzero(~small):
        same = np.flatnonzero((t.bone == t.bone[i]) & (np.arange(len(t)) != i))
        dist = np.linalg.norm(t.points[same] - t.points[i], axis=1)
        got = nbrs[i][nbrs[i] >= 0]
        assert len(got) == min(4, len(same))
        assert np.allclose(np.sort(np.linalg.norm(t.points[got] - t.points[i], axis=1)), np.sort(dist)[:len(got)])
    assert (r2[nbrs[~small][nbrs[~small] >= 0]] < CUT_MIN_RADIUS**2).any()  # small neighbours among them
    every = sphere_neighbours(t, min_radius=0.0)
    assert (every[small] >= 0).any()


def test_lists_are_made_once_per_connectivity_and_remade_when_what_they_depend_on_changes(rng):
    from volanim_core.reconstruct.neighbours import cached_neighbours

    t = random_tskel(rng, n=600, size=60, nbones=3)
    t.dt[:] = rng.uniform(1.0, 12.0, len(t.dt))
    first = cached_neighbours(t)
    assert np.array_equal(first, sphere_neighbours(t)) and not first.flags.writeable
    assert cached_neighbours(t) is first  # a second frame of the same connectivity: no work
    big = np.flatnonzero(radius_squared(t.dt) >= CUT_MIN_RADIUS**2)
    small = np.flatnonzero(radius_squared(t.dt) < CUT_MIN_RADIUS**2)
    t.dt[big[0]] += 0.5  # a radius, the sphere still clipped: the lists (nearest centres) hold
    assert cached_neighbours(t) is first
    t.dt[small[0]] = CUT_MIN_RADIUS + 1  # a sphere that now gets clipped: new lists
    second = cached_neighbours(t)
    assert second is not first and np.array_equal(second, sphere_neighbours(t))
    t.points[small[1]] += 1  # a small sphere moved: it may be a big one's neighbour now
    third = cached_neighbours(t)
    assert third is not second and np.array_equal(third, sphere_neighbours(t))
    t.bone[big[1]] = (t.bone[big[1]] + 1) % 3  # re-attached to another bone: new lists
    assert np.array_equal(cached_neighbours(t), sphere_neighbours(t))


def test_only_planes_that_cut_the_ball_are_kept():
    """A big sphere's power plane against a much smaller close neighbour misses its ball: kept, it cost every
    slice a test and denied the sphere its box sweep (#65). Each kept plane cuts, each dropped one misses:
    checked against the plane's distance from the centre, worked out here in the plain form."""
    from volanim_core.reconstruct._plan_kernels import build_halfspaces

    centres = np.array([[0.0, 0, 0], [1.0, 0, 0], [0, 12.0, 0], [0, 0, 30.0], [0, 0, 0]])
    r2s = np.array([100.0, 4.0, 100.0, 100.0, 100.0], np.float32)  # r = 10, 2, 10, 10 and 10 (coincident)
    neighbours = np.array([[1, 2, 3, 4]] + [[-1] * 4] * 4, np.int32)
    start, planes = build_halfspaces(centres, r2s, neighbours, 36.0)
    kept = []
    for j in (1, 2, 3, 4):
        d = np.linalg.norm(centres[j] - centres[0])
        reach = (d * d + max(0.0, r2s[0] - r2s[j])) / (2 * d) if d else np.inf  # centre -> plane
        kept.append(reach < 10.0)
    assert kept == [False, True, False, False]  # tiny neighbour: power plane at 48.5; bisector at 6; at 15
    assert start[1] - start[0] == 1 and start[-1] == 1
    np.testing.assert_allclose(planes[0, :3], 2 * (centres[2] - centres[0]))
