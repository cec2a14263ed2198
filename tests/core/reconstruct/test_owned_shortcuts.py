"""The owned warp's shortcuts change no voxel. A turned bone reads only in the output cubes its rest cubes land
near (reconstruct/_owned_kernels.posed_cells): checked against every voxel of the bone moved, each bone of the
mannequin turned and moved at random. And the whole body, with every shortcut off, is the same voxel for voxel."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.spatial.transform import Rotation

from volanim_core import samples
from volanim_core.reconstruct import _owned_kernels as K
from volanim_core.reconstruct.owned import cube_reach, posed_boxes, reconstruct_owned
from volanim_core.rig.attach import connect
from volanim_core.rig.ownership import CELL, ownership
from volanim_core.rig.pose import pose_matrices
from volanim_core.skeleton.skeletonize import skeletonize


def _rig():
    s = samples.mannequin()
    return s, ownership(s.mask, connect(skeletonize(s.mask, min_thinness=0.5), s.bones)[0])


def test_a_bones_cubes_mark_every_output_voxel_within_a_diagonal_of_its_voxels():
    """Every output voxel within a voxel's diagonal of one of the bone's voxels moved (where a read can find the
    bone among the 8 voxels around its point) lies in a marked cube; and the marks are not the whole box."""
    s, own = _rig()
    starts, cells = own.cells()
    rng = np.random.default_rng(85)
    for trial in range(40):
        b = int(rng.integers(len(own.bones)))
        m = np.eye(4)
        m[:3, :3] = Rotation.from_rotvec(rng.normal(size=3)).as_matrix()
        m[3, :3] = rng.uniform(-20, 20, 3)
        boxes = posed_boxes(own, np.repeat(m[None], len(own.bones), 0))
        lo = boxes[b, :3] - 3
        shape = boxes[b, 3:] + 3 - lo + 1
        marks = np.zeros(tuple(-(-shape[::-1] // CELL)), np.uint8)
        K.posed_cells(cells[starts[b]:starts[b + 1]], CELL, np.asarray(own.origin, np.int64), m, cube_reach(m), lo,
                      marks)
        # every output voxel of the box whose rest point has the bone among its 8 voxels
        q = np.argwhere(np.ones(tuple(shape), bool)) + lo
        p = (np.column_stack([q, np.ones(len(q))]) @ np.linalg.inv(m))[:, :3] - own.origin
        base = np.floor(p).astype(int)
        findable = np.zeros(len(q), bool)
        for corner in np.ndindex(2, 2, 2):
            c = base + corner
            ok = (c >= 0).all(1) & (c < own.labels.shape).all(1)
            findable[ok] |= own.labels[tuple(c[ok].T)] == b + 1
        assert findable.sum() > 100, (trial, b)
        cube = (q[findable] - lo) // CELL
        assert marks[cube[:, 2], cube[:, 1], cube[:, 0]].all(), (trial, b)
        assert marks.mean() < 0.9, (trial, b, marks.mean())


def test_the_uniform_shortcut_changes_no_voxel():
    """A read near a voxel whose 26 neighbours hold its label takes that label without interpolating, a read whose
    nearest voxel is outside with no face neighbour in the body is refused at once, and rows skip uniform
    voxels: the same body, voxel for voxel, as with every shortcut off (bit 1 cleared, bit 4 set everywhere)."""
    s, own = _rig()
    slow = replace(own)
    slow._flags = np.asfortranarray((own.flags() & 2) | 4)
    # every bone in every cube of the rest grid: its reads go everywhere in its posed box
    every = np.argwhere(np.ones(tuple(-(-np.asarray(own.labels.shape) // CELL)), bool)).astype(np.int32)
    slow._cells = (np.arange(len(own.bones) + 1) * len(every), np.tile(every, (len(own.bones), 1)))
    rng = np.random.default_rng(84)
    for trial in range(4):
        pose = {b.name: tuple(rng.uniform(-60, 60, 3)) for b in s.bones.bones}
        m = pose_matrices(s.bones, pose)
        a, b = reconstruct_owned(own, m, mode="bone"), reconstruct_owned(slow, m, mode="bone")
        assert a.origin == b.origin and np.array_equal(a.volume, b.volume), trial
