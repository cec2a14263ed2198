"""Auto-connect: attachments must run inside the object; never silent, never overwriting by surprise."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core import samples
from volanim_core.rig.attach import auto_connect
from volanim_core.rig.bones import Bone, BoneSkeleton
from volanim_core.skeleton.skeletonize import skeletonize


@pytest.fixture
def two_limbs():
    """Two limbs side by side, joined at the top: limb A (x 1..9) has a short bone near its
    top; limb B (x 14..22) a long bone. Low in limb A, limb B's bone is nearer -- across the gap."""
    mask = np.zeros((24, 8, 44), bool)
    mask[1:10, 1:7, 1:43] = True
    mask[14:23, 1:7, 1:43] = True
    mask[1:23, 1:7, 36:43] = True  # the bridge at the top
    bones = BoneSkeleton({"TOP": (11.5, 4, 40), "A": (3, 4, 32), "B": (17, 4, 2)},
                         [Bone("TOP", "A", "LIMB_A"), Bone("TOP", "B", "LIMB_B")])
    return mask, bones


def test_limb_crossing_path_is_rejected(two_limbs):
    mask, bones = two_limbs
    p = np.array([[8, 4, 8]])  # in limb A, 9 voxels from bone B, 24 from bone A
    nearest, _ = auto_connect(p, bones, mask, method="nearest")
    path, report = auto_connect(p, bones, mask, method="path")
    assert nearest.tolist() == [1] and path.tolist() == [0]
    assert report.attached == 1 and report.unattached == 0


def test_keeps_manual_attachments_unless_asked(two_limbs):
    mask, bones = two_limbs
    pts = np.array([[8, 4, 8], [18, 4, 10], [5, 4, 20]])
    current = np.array([1, -1, -1])  # the user put the first point on LIMB_B by hand
    out, report = auto_connect(pts, bones, mask, current=current)
    assert out.tolist() == [1, 1, 0] and report.kept == 1 and report.attached == 2
    out, report = auto_connect(pts, bones, mask, current=current, overwrite=True)
    assert out.tolist() == [0, 1, 0] and report.kept == 0
    out, _ = auto_connect(pts, bones, mask, which=np.array([False, True, False]))
    assert out.tolist() == [-1, 1, -1]


def test_reports_what_it_could_not_attach(two_limbs):
    mask, bones = two_limbs
    pts = np.array([[11, 4, 5], [5, 4, 20]])  # the first lies in the gap, outside the object
    out, report = auto_connect(pts, bones, mask)
    assert out.tolist() == [-1, 0] and report.unattached == 1
    assert "outside the segmented volume" in str(report) and "left 1 unattached" in str(report)
    from volanim_core.rig.attach import attach_nearest_bone

    lone = np.array([[5, 4, 20]])
    out, report = auto_connect(lone, bones, mask & False, method="path-or-nearest")
    assert out.tolist() == attach_nearest_bone(lone, bones).tolist()
    assert report.fallback == 1 and "went to the nearest bone" in str(report)
    with pytest.raises(ValueError, match="method"):
        auto_connect(pts, bones, mask, method="heat")
    with pytest.raises(ValueError, match="no bones"):
        auto_connect(pts, BoneSkeleton(), mask)


def test_path_method_on_mannequin_limbs():
    s = samples.mannequin()
    sk = skeletonize(s.mask, min_thinness=0.25)
    truth = s.part[tuple(sk.points.T)] - 1
    lab = np.array([samples.mannequin_limb(b.label) for b in s.bones.bones])
    assert len(set(lab)) == 6
    errors = {}
    for m in ("nearest", "path"):
        out, report = auto_connect(sk.points, s.bones, s.mask, method=m)
        assert report.unattached == 0
        errors[m] = (lab[out] != lab[truth]).mean()
    assert errors["path"] < errors["nearest"]  # measured: 4.7 % vs 6.6 % of points on the wrong limb
