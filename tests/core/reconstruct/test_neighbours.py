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
