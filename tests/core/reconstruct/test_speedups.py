"""Each optimisation switched off changes the time, never a voxel (what Fig 5.5's timings rely on)."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from volanim_core import samples
from volanim_core.reconstruct.engine import reconstruct
from volanim_core.reconstruct.speedups import Speedups
from volanim_core.rig.attach import connect_nearest
from volanim_core.rig.connectivity import Trans
from volanim_core.rig.pose import pose_matrices, root_bones
from volanim_core.rig.tskel_tools import connect_to_tskel
from volanim_core.skeleton.skeletonize import skeletonize


@pytest.fixture(scope="module")
def posed():
    """The mannequin at thinness >= 0.25 (large spheres with planes, and many small ones without) with its
    left arm raised: every path of the kernel runs."""
    s = samples.load("mannequin")
    conn = connect_nearest(skeletonize(s.mask, min_thinness=0.25), s.bones)
    return s, connect_to_tskel(conn, Trans(root_bones(s.bones), pose_matrices(s.bones, {"L_UPPERARM": (0, -45, 0)})))


@pytest.mark.parametrize("mode", ["binary", "mottled", "bone", "sampled"])
def test_every_combination_of_speedups_gives_the_same_voxels(posed, mode):
    s, tskel = posed
    ref = reconstruct(tskel, mode=mode, source=s.volume)
    assert ref.stats["filled"] > 100_000
    visits = {}
    for flags in itertools.product([True, False], repeat=len(Speedups.names())):
        switches = Speedups(**dict(zip(Speedups.names(), flags)))
        r = reconstruct(tskel, mode=mode, source=s.volume, speedups=switches)
        assert r.origin == ref.origin and np.array_equal(r.volume, ref.volume), switches
        assert r.stats["filled"] == ref.stats["filled"]
        visits[flags] = r.stats["visits"]
    if mode != "binary":  # the switches do switch: without the cut, spheres visit more voxels
        assert visits[(False, True, True)] > 1.5 * visits[(True, True, True)]
