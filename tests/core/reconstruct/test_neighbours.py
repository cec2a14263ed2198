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
