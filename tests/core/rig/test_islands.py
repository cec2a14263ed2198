"""Each bone's flesh in one piece (rig/islands.py): a ball that touches only another bone's balls goes to it."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core.rig.islands import links, one_piece_each


def test_a_small_ball_inside_a_big_one_is_linked_to_it():
    # by centre distance the small ball's nearest are the other small balls, 20 voxels off; the big ball
    # it lies in is 14 away: the size classes find it
    points = np.array([[0.0, 0, 0], [14.0, 0, 0]] + [[34.0 + k, 0, 0] for k in range(12)])
    radius = np.array([15.0, 1.0] + [1.0] * 12)
    i, j = links(points, radius, k=4)
    assert set(j[i == 1].tolist()) == {0}  # the big ball it lies in, and not the chain 20 voxels off


def test_an_island_goes_to_the_bone_it_touches_and_the_main_piece_stays():
    # bone 0: a row of balls; bone 1: another row, far along; one ball of bone 1 sits in bone 0's row
    row0 = [[float(x), 0, 0] for x in range(0, 20, 2)]
    row1 = [[float(x), 0, 0] for x in range(40, 60, 2)]
    points = np.array(row0 + row1 + [[8.0, 3.0, 0]])
    radius = np.full(len(points), 1.5)
    bone = np.array([0] * 10 + [1] * 10 + [1])
    out = one_piece_each(points, radius, bone)
    assert out[-1] == 0 and (out[:20] == bone[:20]).all()


def test_islands_are_the_painted_voxels_own_not_a_guess_from_distances():
    # a radius-1 ball paints its centre voxel only; 12 voxels from a radius-10 ball of its bone (which
    # paints up to x = 9) it is apart from it, however near the two radii and a slack put it -- and it
    # shares its voxel with the other bone's ball: a pose of either would float it off, so it goes there
    points = np.array([[0.0, 0, 0], [12.0, 0, 0], [14.0, 0, 0]])
    radius = np.array([10.0, 1.0, 2.5])
    out = one_piece_each(points, radius, np.array([0, 0, 1]))
    assert out.tolist() == [0, 1, 1]


def test_an_island_touching_no_other_bone_stays_and_the_input_is_not_changed():
    points = np.array([[0.0, 0, 0], [2.0, 0, 0], [50.0, 0, 0]])
    bone = np.array([0, 0, 0])
    out = one_piece_each(points, np.ones(3), bone)
    assert (out == 0).all() and out is not bone


# full tier only, so that make test stays under 10 minutes: Spot the cow voxelized, skeletonized, proposed,
# connected and each leaf bent twice
@pytest.mark.slow
def test_every_leaf_of_spot_bends_without_tearing_a_speck(tmp_path):
    """Spot's front leg bent 45 degrees tore off an 8-voxel speck: one ball of radius 1 at the knee, given
    to the shin by its distance to the bone, touching 43 balls of the thigh and trunk and none of the
    shin's. With each bone's flesh in one piece, every leaf bends healthy with rigid joints."""
    from leaf_bends import leaf_bends
    from volanim_core import samples
    from volanim_core.io.mesh_files import read_mesh, voxelize
    from volanim_core.rig.autorig import autorig
    from volanim_core.skeleton.skeletonize import skeletonize

    samples.write_sample("spot", tmp_path)
    vol, _ = voxelize(read_mesh(tmp_path / "spot.ply"), size=160)
    skel = skeletonize(vol > 0)
    bones = autorig(skel).bones
    assert len(bones.leaves()) >= 6  # four legs, the horns or the tail at least
    assert leaf_bends(skel, bones) == []


def test_an_island_goes_where_its_voxels_join_a_bone_and_does_not_swing_back():
    """A stray ball of bone 0 lies between two chains, of bone 0 and of bone 1, each 3 voxels off: near
    enough for the slack, not for their voxels to touch. It touches most the chain of bone 1, so it went
    there, was a stray of bone 1 the next round and came back, round after round: the frog's 5931 points
    swung between two bones and the four rounds left them where they began. Given to the bone whose
    flesh its voxels join (bone 2's ball beside it), it stays."""
    main0 = [[float(x), -3.0, 0] for x in range(0, 56)]  # bone 0's flesh: a chain passing the stray at y = -3
    chain1 = [[float(x), 3.0, 0] for x in range(40, 61)]  # bone 1's: a chain at y = +3
    stray = [[50.0, 0, 0]]  # bone 0, radius 2: its voxels reach y = +-1, a voxel short of either chain
    beside = [[53.5, 0, 0]]  # bone 2, radius 2: its voxels and the stray's are neighbours
    points = np.array(main0 + chain1 + stray + beside)
    radius = np.r_[np.full(len(main0) + len(chain1), 1.0), 2.0, 2.0]
    bone = np.r_[np.zeros(len(main0), int), np.ones(len(chain1), int), 0, 2]
    out = one_piece_each(points, radius, bone)
    assert out[len(main0) + len(chain1)] == 2
    assert (out[:len(main0) + len(chain1)] == bone[:len(main0) + len(chain1)]).all() and out[-1] == 2
