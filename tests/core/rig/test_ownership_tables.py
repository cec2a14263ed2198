"""The tables an ownership makes once and every posed frame reads (rig/ownership.py: flags, cells, thin), each
against its definition computed another way (tests/naive.py, numpy): on random labels whose bones touch the
array's faces, and on the rigs of the mannequin and the frog."""

from __future__ import annotations

import numpy as np
import pytest
from tests import naive

from volanim_core import samples
from volanim_core.rig.attach import connect
from volanim_core.rig.connectivity import BoneSegment
from volanim_core.rig.ownership import CELL, THIN, Ownership, ownership
from volanim_core.skeleton.skeletonize import skeletonize


def _random(seed: int) -> Ownership:
    rng = np.random.default_rng(seed)
    labels = rng.integers(0, 4, (23, 17, 11)).astype(np.uint8)
    labels[5:15, 4:12, 2:9] = 2  # a block whose inside is uniform
    labels[rng.random(labels.shape) < 0.3] = 0
    labels[8:12, 6:10, 4:7] = 3
    bones = [BoneSegment((0.0, 0, 0), (1.0, 0, 0), f"B{k}") for k in range(3)]
    return Ownership(np.asfortranarray(labels), (3, -2, 5), bones, [0.0] * 3)


@pytest.fixture(scope="module", params=["random-1", "random-2", "mannequin", "frog"])
def own(request):
    if request.param.startswith("random"):
        return _random(int(request.param[-1]))
    s = samples.load(request.param)
    skel = skeletonize(s.mask, **({} if request.param == "frog" else {"min_thinness": 0.5}))
    return ownership(s.mask, connect(skel, s.bones)[0])


def test_the_flags_are_their_definition(own):
    flags = own.flags()
    assert (flags & 1).any() and (flags & 8).any()
    np.testing.assert_array_equal(flags, naive.voxel_flags(own.labels))


def test_each_bones_cells_are_the_cubes_that_hold_its_voxels(own):
    starts, cells = own.cells()
    for b in range(len(own.bones)):
        voxels = np.argwhere(own.labels == b + 1)
        expect = np.unique(voxels // CELL, axis=0)
        got = np.unique(cells[starts[b]:starts[b + 1]], axis=0)
        assert len(got) == starts[b + 1] - starts[b], b  # each cube once
        np.testing.assert_array_equal(got, expect.reshape(-1, 3))


def test_each_bones_thin_voxels_are_its_voxels_flagged_thin(own):
    starts, voxels = own.thin()
    thin = (own.flags() & THIN) != 0
    for b in range(len(own.bones)):
        expect = np.argwhere((own.labels == b + 1) & thin)
        got = voxels[starts[b]:starts[b + 1]]
        np.testing.assert_array_equal(got[np.lexsort(got.T[::-1])], expect)
