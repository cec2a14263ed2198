"""The rows a turned bone's reads visit (reconstruct/_owned_kernels.posed_row_spans) come from its surface
voxels alone: a voxel whose 26 neighbours are its bone's lands among theirs. Checked on the mannequin's rig,
each bone turned and moved at random: the spans hold every span of all the bone's own voxels."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from volanim_core import samples
from volanim_core.reconstruct import _owned_kernels as K
from volanim_core.reconstruct.owned import posed_boxes
from volanim_core.rig.attach import connect
from volanim_core.rig.ownership import ownership
from volanim_core.skeleton.skeletonize import skeletonize


def _spans(own, m, lo, shape_zy, flags, b):
    out = np.empty((*shape_zy, 2), np.int32)
    out[..., 0], out[..., 1] = 2**30, -(2**30)
    K.posed_row_spans(flags, own.spans()[b], np.asarray(own.origin, np.int64), m, lo, out)
    return out


def test_a_bones_surface_gives_the_spans_of_all_its_voxels():
    s = samples.mannequin()
    own = ownership(s.mask, connect(skeletonize(s.mask, min_thinness=0.5), s.bones)[0])
    rng = np.random.default_rng(85)
    assert (own.flags() & 1).any()
    for trial in range(40):
        b = int(rng.integers(len(own.bones)))
        m = np.eye(4)
        m[:3, :3] = Rotation.from_rotvec(rng.normal(size=3)).as_matrix()
        m[3, :3] = rng.uniform(-20, 20, 3)
        boxes = posed_boxes(own, np.repeat(m[None], len(own.bones), 0))
        lo = boxes[b, :3] - 3
        shape = boxes[b, 3:] + 3 - lo + 1
        fast = _spans(own, m, lo, (shape[2], shape[1]), own.flags(), b)
        others = np.asfortranarray((own.labels != b + 1).astype(np.uint8))  # bit 1 set: skipped; the bone's own read
        every = _spans(own, m, lo, (shape[2], shape[1]), others, b)
        rows = every[..., 1] >= every[..., 0]
        assert rows.sum() > 100, (trial, b)
        assert (fast[rows, 0] <= every[rows, 0]).all() and (fast[rows, 1] >= every[rows, 1]).all(), (trial, b)


def test_the_uniform_shortcut_changes_no_voxel():
    """A read near a voxel whose 26 neighbours hold its label takes that label without interpolating, a read whose
    nearest voxel is outside with no face neighbour in the body is refused at once, and rows skip uniform
    voxels: the same body, voxel for voxel, as with every shortcut off (bit 1 cleared, bit 4 set everywhere)."""
    from dataclasses import replace

    from volanim_core.reconstruct.owned import reconstruct_owned
    from volanim_core.rig.pose import pose_matrices

    s = samples.mannequin()
    own = ownership(s.mask, connect(skeletonize(s.mask, min_thinness=0.5), s.bones)[0])
    slow = replace(own)
    slow._flags = np.asfortranarray((own.flags() & 2) | 4)
    rng = np.random.default_rng(84)
    for trial in range(4):
        pose = {b.name: tuple(rng.uniform(-60, 60, 3)) for b in s.bones.bones}
        m = pose_matrices(s.bones, pose)
        a, b = reconstruct_owned(own, m, mode="bone"), reconstruct_owned(slow, m, mode="bone")
        assert a.origin == b.origin and np.array_equal(a.volume, b.volume), trial
