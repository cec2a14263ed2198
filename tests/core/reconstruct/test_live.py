"""Only what moved (#65): a live frame redoes the slices the moved spheres reach, and every update is,
voxel for voxel, the full reconstruction of that frame on the same grid."""

from __future__ import annotations

import numpy as np
import pytest

from paths import ASSETS
from volanim_core import io, samples
from volanim_core.reconstruct.engine import reconstruct
from volanim_core.reconstruct.live import LiveFrame
from volanim_core.reconstruct.plan import grid_bounds
from volanim_core.rig.pose import pose_matrices
from volanim_core.rig.skinning import Joints
from volanim_core.volume import Bounds

# a drag of one forearm, then its hand, the same pose again, a turn at the hip, the body walked along
POSES = [{}, {"L_FOREARM": (0, 0, 30)}, {"L_FOREARM": (0, 0, 60)}, {"L_FOREARM": (0, 0, 60), "L_HAND": (20, 0, 0)},
         {"L_FOREARM": (0, 0, 60), "L_HAND": (20, 0, 0)}, {"R_THIGH": (-40, 0, 0)}]


@pytest.fixture(scope="module")
def mannequin():
    conn = io.read_connect(ASSETS / "mannequin.0.50.connect")
    return conn, samples.mannequin_bones(), samples.load("mannequin")


def _frames(conn, bones):
    yield from (conn.posed(pose_matrices(bones, pose)) for pose in POSES)
    roots = [i for i, parent in enumerate(bones.parents()) if parent is None]
    yield conn.posed(pose_matrices(bones, POSES[-1], {i: (3.0, 0.0, 0.0) for i in roots}))


@pytest.mark.parametrize("mode", ["bone", "sampled", "binary", "mottled", "hotspot"])
def test_every_update_is_the_full_reconstruction_and_redoes_only_the_moved_slices(mannequin, mode):
    conn, bones, sample = mannequin
    frames = list(_frames(conn, bones))
    bounds = grid_bounds(frames, padding=2)  # one grid for the whole drag
    live = LiveFrame(bounds, mode=mode, source=sample.volume)
    redone = []
    for t in frames:
        got = live.update(t)
        want = reconstruct(t, mode=mode, source=sample.volume, bounds=bounds)
        assert got.volume.dtype == want.volume.dtype and np.array_equal(got.volume, want.volume)
        assert got.origin == want.origin and got.stats["filled"] == want.stats["filled"]
        assert got.stats["visits"] == want.stats["visits"] and got.stats["clipped"] == want.stats["clipped"]
        redone.append(got.stats["redone_slices"])
    nz = bounds.shape[2]
    assert redone[0] == nz  # the first frame: every slice
    assert 0 < redone[1] < nz // 2 and 0 < redone[3] < nz // 2  # a forearm, a hand: the slices they reach
    assert redone[4] == 0  # the same pose again: nothing
    assert redone[-1] >= nz - 4  # the whole body moved (all but the padding's empty slices)


@pytest.mark.slow  # the colour mannequin is built (4 s) and the smooth joints' weights made (2 s)
def test_smooth_joints_and_a_colour_source(mannequin):
    """Blended spheres move with either bone; a colour source samples its three channels per slice."""
    conn, bones, _ = mannequin
    colour = samples.load("mannequin-colour").volume
    frames = list(_frames(conn.with_joints(Joints("smooth")), bones))[1:4]  # one set of blend weights for all
    bounds = grid_bounds(frames, padding=2)
    for mode, source in (("bone", None), ("sampled", colour)):  # a forearm, then its hand
        live = LiveFrame(bounds, mode=mode, source=source)
        for t in frames:
            got = live.update(t, copy=False)
            want = reconstruct(t, mode=mode, source=source, bounds=bounds)
            assert np.array_equal(got.volume, want.volume)


def test_spheres_carried_out_of_the_grid_are_clipped_and_other_spheres_start_afresh(mannequin, rng):
    conn, bones, sample = mannequin
    rest = conn.posed(pose_matrices(bones))
    bounds = grid_bounds(rest, padding=0)
    small = Bounds(bounds.lo, (bounds.hi[0], bounds.hi[1], bounds.lo[2] + 150))  # the legs only
    live = LiveFrame(small, mode="bone")
    for t in (rest, conn.posed(pose_matrices(bones, {"R_THIGH": (-70, 0, 0)}))):
        got, want = live.update(t), reconstruct(t, mode="bone", bounds=small)
        assert np.array_equal(got.volume, want.volume) and got.stats["clipped"] == want.stats["clipped"] > 0
    fewer = conn.take(np.flatnonzero(rng.random(len(conn)) < 0.7))  # other spheres: every slice again
    got = live.update(fewer.posed(pose_matrices(bones)))
    assert got.stats["redone_slices"] == small.shape[2]
    assert np.array_equal(got.volume, reconstruct(fewer.posed(pose_matrices(bones)), mode="bone",
                                                  bounds=small).volume)
