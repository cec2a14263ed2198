"""The measures #42's proof rests on (reconstruct/bend.py), against counts made by hand: the area of a
cylinder's cross-section, and the Dice of a limb's far part taken back through its matrix."""

from __future__ import annotations

import numpy as np

from volanim_core.reconstruct.bend import cross_section, far_limb_dice
from volanim_core.reconstruct.engine import Reconstruction


def test_cross_section_counts_the_disc_a_plane_cuts_from_a_cylinder():
    x, y, z = np.indices((30, 21, 21))
    cylinder = ((y - 10) ** 2 + (z - 10) ** 2 <= 25).astype(np.uint8)  # radius 5 along x
    recon = Reconstruction(cylinder, (100, -10, 7))  # voxel [0, 0, 0] is rest voxel (100, -10, 7)
    disc = sum(1 for a in range(-5, 6) for b in range(-5, 6) if a * a + b * b <= 25)
    assert disc == 81
    axis_point = np.array([115.0, 0.0, 17.0])
    assert cross_section(recon, axis_point, np.array([1.0, 0, 0]), 8.0) == disc
    assert cross_section(recon, axis_point, np.array([-3.0, 0, 0]), 8.0) == disc  # any length, either way
    # along the axis (a plane holding it): one row y = 0 of the cylinder, as long as the radius reaches
    lengthwise = sum(1 for a in range(-8, 9) for b in range(-5, 6) if a * a + b * b <= 64)
    assert cross_section(recon, axis_point, np.array([0, 1.0, 0]), 8.0) == lengthwise
    assert cross_section(recon, axis_point + [0, 0, 30], np.array([1.0, 0, 0]), 8.0) == 0  # beside it: nothing


def _line(xs, label=2, turn=False) -> Reconstruction:
    """A one-voxel line of bone 1 (label 2) at x in ``xs`` along x, or turned to +y (``turn``)."""
    v = np.zeros((25, 25, 3), np.uint8)
    for x in xs:
        v[(0, x, 1) if turn else (x, 0, 1)] = label
    return Reconstruction(v, (0, 0, -1))


def test_far_limb_dice_compares_the_far_part_taken_back_through_the_limbs_matrix():
    joint = np.zeros(3)
    whole, short = range(0, 20), range(0, 15)
    assert far_limb_dice(_line(whole), _line(whole), 1, np.eye(4), joint, 10.0) == 1.0
    # far part: x 11..19 against x 11..14 -> 2 * 4 / (9 + 4)
    assert np.isclose(far_limb_dice(_line(short), _line(whole), 1, np.eye(4), joint, 10.0), 8 / 13)
    # the same limb turned 90 degrees about z ([x y z 1] @ M = [-y x z]): measured in the rest frame
    turn = np.array([[0, 1, 0, 0], [-1, 0, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], float)
    assert np.isclose(far_limb_dice(_line(short, turn=True), _line(whole, turn=True), 1, turn, joint, 10.0), 8 / 13)
    # near the joint nothing counts; another bone's voxels never do
    assert far_limb_dice(_line(short), _line(whole), 1, np.eye(4), joint, 30.0) == 0.0
    assert far_limb_dice(_line(whole, label=3), _line(whole), 1, np.eye(4), joint, 10.0) == 0.0
