"""Neighbour lists are made only where the kernel uses them (spheres of radius >= CUT_MIN_RADIUS)."""

from __future__ import annotations

import numpy as np
from test_engine import random_tskel

from volanim_core.reconstruct.neighbours import CUT_MIN_RADIUS, sphere_neighbours
from volanim_core.reconstruct.radii import radius_squared


def test_only_spheres_the_kernel_clips_get_lists_and_those_lists_are_larger_same_bone_spheres(rng):
    t = random_tskel(rng, n=600, size=60, nbones=3)
    t.dt[:] = rng.uniform(1.0, 12.0, len(t.dt))
    nbrs = sphere_neighbours(t)
    r2 = radius_squared(t.dt)
    small = r2 < CUT_MIN_RADIUS**2
    assert small.any() and (~small).any()
    assert (nbrs[small] == -1).all()  # no work spent on lists the kernel never reads
    assert (nbrs[~small] >= 0).any()
    i, h = np.nonzero(nbrs >= 0)
    j = nbrs[i, h]
    assert (t.bone[j] == t.bone[i]).all() and (r2[j] >= r2[i]).all() and (j != i).all()
    every = sphere_neighbours(t, min_radius=0.0)  # every sphere, as the lists used to be made
    assert (every[small] >= 0).any()


def test_lists_are_made_once_per_connectivity_and_remade_when_what_they_depend_on_changes(rng):
    from volanim_core.reconstruct.neighbours import cached_neighbours

    t = random_tskel(rng, n=600, size=60, nbones=3)
    t.dt[:] = rng.uniform(1.0, 12.0, len(t.dt))
    first = cached_neighbours(t)
    assert np.array_equal(first, sphere_neighbours(t)) and not first.flags.writeable
    assert cached_neighbours(t) is first  # a second frame of the same connectivity: no work
    big = np.flatnonzero(radius_squared(t.dt) >= CUT_MIN_RADIUS**2)
    t.dt[big[0]] += 0.5  # a clipped sphere's radius changed: new lists
    second = cached_neighbours(t)
    assert second is not first and np.array_equal(second, sphere_neighbours(t))
    small = np.flatnonzero(radius_squared(t.dt) < CUT_MIN_RADIUS**2)
    t.dt[small[0]] *= 0.9  # a sphere the kernel never clips: the same lists hold
    assert cached_neighbours(t) is second
    t.bone[big[1]] = (t.bone[big[1]] + 1) % 3  # re-attached to another bone: new lists
    assert np.array_equal(cached_neighbours(t), sphere_neighbours(t))
