"""Bone colours: at least 24 that a user can tell apart (the old 16 repeated: SPINE and R_SHIN shared red)."""

from __future__ import annotations

import itertools

import numpy as np
from skimage.color import deltaE_ciede2000, rgb2lab

from volanim_core import samples
from volanim_core.render.bone_colours import label_table


def test_the_first_24_bone_colours_are_pairwise_distinct_in_ciede2000():
    lab = rgb2lab(label_table(24)[1:][None].astype(np.float64) / 255.0)[0]
    worst = min(deltaE_ciede2000(lab[i], lab[j]) for i, j in itertools.combinations(range(24), 2))
    assert worst >= 15.0


def test_the_mannequin_spine_and_right_shin_differ():
    bones = samples.mannequin_bones()
    table = label_table(len(bones))
    assert not np.array_equal(table[bones.index("SPINE") + 1], table[bones.index("R_SHIN") + 1])
    assert len({tuple(c) for c in table}) == len(bones) + 1  # and the grey of unconnected points is none of them
