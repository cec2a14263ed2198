"""The library's public calls given arrays of the wrong shape or values (#89): each refusal says, in our words,
which argument is wrong, the shape or value it needs and the one it got. They raised numpy's "cannot reshape
array of size 12 into shape (4,4)" and SciPy's "Interpolation times must be within the range"."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core.motion.keyframes import interpolate, keys
from volanim_core.reconstruct.engine import reconstruct
from volanim_core.rig.connectivity import BoneSegment, Tskel
from volanim_core.rig.key_pose import KeyPose
from volanim_core.samples import mannequin_bones

BONE = [BoneSegment((0, 0, 0), (1, 0, 0), "ARM")]
GOOD = dict(matrices=np.eye(4)[None], points=[[5, 5, 5]], dt=[2.0], bone=[0])


def frame(**change):
    a = {**GOOD, **change}
    return Tskel(BONE, a["matrices"], a["points"], a["dt"], None, a["bone"])


@pytest.mark.parametrize(("change", "says"), [
    (dict(matrices=np.eye(4)[:3].T[None]), r"matrices \(one 4 x 4 for each of the 1 bones\) must be an array of "
                                           r"shape \(1 x 4 x 4\), got shape \(1, 4, 3\).*a 3 x 4 affine"),
    (dict(matrices=np.eye(4)[None].repeat(2, 0)), r"matrices .* shape \(1 x 4 x 4\), got shape \(2, 4, 4\)"),
    (dict(points=[[5, 5, 5, 1]]), r"points must be an array of shape \(N x 3\): x, y, z of each voxel, got shape "
                                  r"\(1, 4\)"),
    (dict(dt=[2.0, 3.0]), r"dt \(one radius for each of the 1 points\) must be an array of shape \(1\), got shape "
                          r"\(2,\)"),
    (dict(bone=[0, 0]), r"bone \(one bone index for each of the 1 points\) .* got shape \(2,\)"),
    (dict(bone=[3]), r"bone: point 0's bone index 3 is not one of the 1 bones \(0 to 0, root order\)"),
])
def test_a_frame_of_the_wrong_shape_says_which_argument(change, says):
    with pytest.raises(ValueError, match=says):
        reconstruct(frame(**change))


def test_a_good_frame_and_one_bones_matrix_alone_reconstruct():
    assert (reconstruct(frame(), padding=0).volume > 0).sum() == 27
    assert (reconstruct(frame(matrices=np.eye(4)), padding=0).volume > 0).sum() == 27  # (4, 4) for one bone


def test_a_bone_joint_of_two_numbers_names_the_bone():
    with pytest.raises(ValueError, match=r"bone ARM's proximal joint must be an array of shape \(3\), got shape"):
        BoneSegment((0, 0), (1, 0, 0), "ARM")


@pytest.mark.parametrize("at", [float("nan"), 2.5, -1])
def test_a_key_at_no_whole_frame_is_named(at):
    with pytest.raises(ValueError, match=r"keys: a key at frame (nan|2\.5|-1); keys sit at whole frames 0 to"):
        keys({0: KeyPose(), at: KeyPose()}, mannequin_bones())


def test_a_nan_frame_asked_for_is_named():
    with pytest.raises(ValueError, match=r"frames: item 1 is nan; the frames asked for must be finite numbers"):
        interpolate(mannequin_bones(), {0: KeyPose(), 5: KeyPose()}, [0, float("nan")])
