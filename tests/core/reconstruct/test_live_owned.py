"""#85: a live owned frame redoes only the box the moved bones reach, and is the very frame reconstruct_owned makes;
a coarse frame (a live preview at half resolution) moves the rig's ownership pooled, not the thesis's spheres."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core import samples
from volanim_core.reconstruct.engine import reconstruct
from volanim_core.reconstruct.live_owned import LiveOwned
from volanim_core.reconstruct.owned import posed_bounds, reconstruct_owned
from volanim_core.rig._ownership_kernels import pool_labels
from volanim_core.rig.attach import connect
from volanim_core.rig.ownership import ownership
from volanim_core.rig.pose import pose_matrices
from volanim_core.rig.tskel_tools import coarse_tskel
from volanim_core.skeleton.skeletonize import skeletonize

# a forearm dragged, a foot, the spine (everything above it moves), a clavicle, then the whole body walked off
DRAG = ([{"L_FOREARM": (-a, 0, 0)} for a in range(0, 80, 10)] + [{"L_FOREARM": (-70, 0, 0), "R_FOOT": (20, 0, 0)}]
        + [{"L_FOREARM": (-70, 0, 0), "R_FOOT": (20, 0, 0), "SPINE": (0, 0, 30)}]
        + [{"L_FOREARM": (-70, 0, 0), "R_FOOT": (20, 0, 0), "SPINE": (0, 0, 30), "R_CLAVICLE": (0, 0, 20)}])


@pytest.fixture(scope="module")
def rig():
    s = samples.mannequin()
    conn = connect(skeletonize(s.mask, min_thinness=0.5), s.bones)[0]
    return s, ownership(s.mask, conn)


@pytest.mark.parametrize("mode", ["bone", "binary", "hotspot"])
def test_every_update_is_the_frame_reconstruct_owned_makes_and_a_forearm_redoes_its_own_box(rig, mode):
    s, own = rig
    grid = posed_bounds(own, pose_matrices(s.bones, {}), 30)
    live = LiveOwned(own, grid, mode=mode)
    roots = [i for i, parent in enumerate(s.bones.parents()) if parent is None]
    poses = [pose_matrices(s.bones, p) for p in DRAG]
    poses.append(pose_matrices(s.bones, DRAG[-1], {i: (200.0, 0.0, 0.0) for i in roots}))  # off the grid
    redone = []
    for m in poses:
        got = live.update(m)
        want = reconstruct_owned(own, m, mode=mode, bounds=grid)
        assert np.array_equal(got.volume, want.volume)
        assert got.origin == want.origin and got.stats["filled"] == want.stats["filled"]
        assert got.stats["clipped"] == want.stats["clipped"]
        redone.append(live.redone)
    whole = int(np.prod(grid.shape))
    assert redone[0] == whole
    assert all(0 < n < whole // 20 for n in redone[1:8])  # each step of the forearm: its own box
    assert live.update(poses[-1]) is not None and live.redone == 0  # nothing moved: nothing redone


def _pooled(labels: np.ndarray, origin, factor: int = 2) -> tuple[np.ndarray, np.ndarray]:
    lo = np.floor_divide(origin, factor)
    offset = np.asarray(origin) - lo * factor
    out = np.zeros(tuple(-(-(offset + labels.shape) // factor)), labels.dtype, order="F")
    pool_labels(np.asfortranarray(labels), offset.astype(np.int64), factor, out)
    return out, lo


def _on(volume, origin, lo, shape):
    out = np.zeros(shape, volume.dtype)
    at = np.asarray(origin) - lo
    out[tuple(slice(a, a + n) for a, n in zip(at, volume.shape))] = volume
    return out


def test_a_coarse_frame_moves_the_pooled_ownership_and_keeps_the_full_frame_s_body(rig):
    """At rest, the half-size frame is the ownership pooled (each coarse voxel the bone most of its 8 voxels belong
    to, where 4 or more are body) but where a joint's ball fills a voxel the pooling left empty; the raised arm at
    half size is the full frame's raised arm pooled, where the spheres' half-size frame carries the armpit lump."""
    from volanim_core.rig.connectivity import Connectivity

    s, own = rig
    conn: Connectivity = connect(skeletonize(s.mask, min_thinness=0.5), s.bones)[0].with_ownership(own)
    rest = reconstruct(coarse_tskel(conn.posed(pose_matrices(s.bones, {})), 2), mode="bone")
    assert rest.stats["method"] == "owned"
    pooled, lo = _pooled(own.labels, own.origin)
    shape = np.maximum(np.asarray(rest.origin) + rest.volume.shape, lo + pooled.shape) - np.minimum(rest.origin, lo)
    base = np.minimum(rest.origin, lo)
    a, b = _on(rest.volume, rest.origin, base, shape), _on(pooled, lo, base, shape)
    both = (a > 0) & (b > 0)
    assert np.array_equal(a[both], b[both]) and not (b > 0)[a == 0].any()
    assert (a[b == 0] > 0).sum() < 0.005 * both.sum()  # the balls' few

    m = pose_matrices(s.bones, {"L_UPPERARM": (0, -90, 0)})
    full = reconstruct(conn.posed(m), mode="bone")
    pooled, lo = _pooled(np.asarray(full.volume), full.origin)
    dice = {}
    for method in ("owned", "spheres"):
        half = reconstruct(coarse_tskel(conn.posed(m), 2), mode="bone", method=method)
        base = np.minimum(half.origin, lo)
        shape = np.maximum(np.asarray(half.origin) + half.volume.shape, lo + pooled.shape) - base
        a, b = _on(half.volume, half.origin, base, shape) > 0, _on(pooled, lo, base, shape) > 0
        dice[method] = 2 * (a & b).sum() / (a.sum() + b.sum())
    assert dice["owned"] >= 0.995 > dice["spheres"], dice


def test_a_coarse_ownership_is_made_once_and_poses_on_its_own_grid(rig):
    s, own = rig
    half = own.coarse(2)
    assert own.coarse(2) is half and own.coarse(1) is own and half.factor == 2
    assert np.allclose(half.geometry.spacing, np.multiply(own.geometry.spacing, 2))
    m = pose_matrices(s.bones, {"L_FOREARM": (-40, 0, 0)})
    scaled = coarse_tskel(connect(skeletonize(s.mask, min_thinness=0.5), s.bones)[0].posed(m), 2).matrices
    c = half.rest_matrices(scaled)
    # a coarse rest voxel c is the skeleton's voxel 2c: posed by the full matrix, then halved
    p = np.array([31.0, 40.0, 55.0])
    assert np.allclose(np.append(p, 1) @ c, (np.append(2 * p, 1) @ m) / np.array([2, 2, 2, 1]))
