"""A body in pieces (#62): each piece's points go to the bones lying in it (rig/pieces.py)."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core.rig.attach import attach_nearest_bone, auto_connect
from volanim_core.rig.bones import Bone, BoneSkeleton
from volanim_core.rig.pieces import attach_by_piece, bone_pieces, pieces


def _body():
    """A trunk (x 2..21) and a leg shell beside its end (x 23..40), a one-voxel gap between them, and a loose
    flake (x 44..46) no bone lies in. The trunk's bone runs to x 21, the leg's starts at x 28."""
    mask = np.zeros((50, 12, 12), bool)
    mask[2:22, 2:10, 2:10] = True
    mask[23:41, 3:9, 3:9] = True
    mask[44:47, 5:7, 5:7] = True
    bones = BoneSkeleton({"A": (4, 6, 6), "B": (21, 6, 6), "C": (28, 6, 6), "D": (39, 6, 6)},
                         [Bone("A", "B", "TRUNK"), Bone("C", "D", "LEG")])
    return mask, bones


def test_a_shell_s_first_points_go_to_its_own_bone_though_the_next_shell_s_is_nearer():
    mask, bones = _body()
    points = np.array([(23, 6, 6), (24, 5, 6), (30, 6, 6), (10, 6, 6), (45, 6, 6)])
    nearest = attach_nearest_bone(points, bones)
    assert nearest.tolist()[:2] == [0, 0]  # x 23, 24: 2-3 voxels from the trunk's end, 4-5 from the leg's start
    got = attach_by_piece(points, bones, mask)
    assert got.tolist() == [1, 1, 1, 0, 1]  # the flake goes whole to the bone nearest it (the leg's end)


def test_each_bone_lies_in_the_piece_most_of_its_segment_crosses():
    mask, bones = _body()
    labels, n = pieces(mask)
    assert n == 3
    pts = np.array([(10, 6, 6), (30, 6, 6)])
    owner = bone_pieces(bones, labels, pts, labels[tuple(pts.T)])
    assert owner.tolist() == [labels[10, 6, 6], labels[30, 6, 6]]


def test_a_body_in_one_piece_is_attached_as_by_the_nearest_bone():
    mask, bones = _body()
    mask[22, 4:8, 4:8] = True  # both gaps closed: one piece
    mask[41:44, 5:7, 5:7] = True
    rng = np.random.default_rng(0)
    points = np.argwhere(mask)[rng.choice(int(mask.sum()), 200, replace=False)]
    assert pieces(mask)[1] == 1
    assert np.array_equal(attach_by_piece(points, bones, mask), attach_nearest_bone(points, bones))


def test_auto_connect_pieces_attaches_every_point():
    mask, bones = _body()
    points = np.argwhere(mask)
    bone, report = auto_connect(points, bones, mask, method="pieces")
    assert report.attached == len(points) and report.unattached == 0
    leg = points[:, 0] >= 23
    assert (bone[leg] == 1).all() and (bone[~leg] == 0).all()


def test_connect_by_pieces_without_the_volume_says_what_it_needs():
    from volanim_core.rig.attach import connect
    from volanim_core.skeleton.skeletonize import skeletonize

    mask, bones = _body()
    with pytest.raises(ValueError, match=r"'pieces' method needs the segmented volume \(its pieces are the body's\)"):
        connect(skeletonize(mask), bones, method="pieces")
