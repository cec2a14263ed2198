"""The mannequins' true posed shape (posed_truth): the rest sample at identity, each part moved whole."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core import samples
from volanim_core.posed_truth import posed_sample
from volanim_core.rig.pose import pose_matrices, posed_joints


def _cut(volume: np.ndarray, origin, shape) -> np.ndarray:
    return volume[origin[0]:origin[0] + shape[0], origin[1]:origin[1] + shape[1], origin[2]:origin[2] + shape[2]]


def _check_identity(name, sample):
    truth = posed_sample(name, np.tile(np.eye(4), (len(sample.bones), 1, 1)))
    o, n = truth.origin, truth.volume.shape
    assert np.array_equal(_cut(sample.volume, o, n), truth.volume)
    assert np.array_equal(_cut(sample.part, o, n), truth.part)
    assert int((sample.volume > 0).sum()) == int((truth.volume > 0).sum())  # nothing of the body outside the cut


def test_at_identity_the_truth_is_the_mannequin_voxel_for_voxel():
    _check_identity("mannequin", samples.mannequin())


@pytest.mark.slow
def test_at_identity_the_truth_is_mannequin_large_voxel_for_voxel():
    _check_identity("mannequin-large", samples.mannequin_large())


@pytest.mark.slow
def test_mannequin_full_is_the_large_body_on_the_full_visible_human_grid_and_its_truth_at_identity():
    """#87: the thesis's full grid, 580 x 338 x 1880 (368 M voxels), the same body sampled twice as finely along
    each axis as mannequin-large: 8x its voxels (within 1 %), its bones at twice the coordinates."""
    full, large = samples.mannequin_full(), samples.mannequin_large()
    assert full.volume.shape == (580, 338, 1880) and full.volume.dtype == np.uint8
    ratio = np.count_nonzero(full.volume) / np.count_nonzero(large.volume)
    assert abs(ratio - 8) < 0.08, ratio
    for name, at in large.bones.joints.items():
        assert np.allclose(full.bones.joints[name], 2 * at, atol=1.5), name
    del large
    _check_identity("mannequin-full", full)


def test_a_posed_part_is_its_rest_part_moved_whole():
    """A forearm bent 90 degrees about y at the elbow: each of its voxels is a rest forearm voxel turned about
    the elbow, and the hand goes with it; the other side of the body does not move."""
    rest = samples.mannequin()
    bones = rest.bones
    m = pose_matrices(bones, {"L_FOREARM": (0, -90, 0)})
    truth = posed_sample("mannequin", m)
    moved = [bones.index(n) + 1 for n in ("L_FOREARM", "L_HAND")]
    # every posed voxel of the moved parts, taken back through its bone's matrix, is a rest voxel of that part
    for label in moved:
        q = np.argwhere(truth.part == label) + truth.origin
        back = np.c_[q, np.ones(len(q))] @ np.linalg.inv(m[label - 1])
        idx = np.rint(back[:, :3]).astype(int)
        inside = rest.part[idx[:, 0], idx[:, 1], idx[:, 2]] == label
        assert inside.mean() > 0.99, (label, inside.mean())
        # about as many voxels as at rest: at the bent elbow the upper arm's capsule is deepest in a few more
        assert abs(len(q) - int((rest.part == label).sum())) < 0.05 * len(q)
    # the hand now lies beyond the elbow along the turned forearm
    joints = posed_joints(bones, m)
    hand = np.argwhere(truth.part == bones.index("L_HAND") + 1).mean(0) + truth.origin
    assert np.linalg.norm(hand - joints["L_WRIST"]) < np.linalg.norm(hand - joints["L_ELBOW"])
    right = bones.index("R_FOREARM") + 1
    r_truth = np.argwhere(truth.part == right) + truth.origin
    r_rest = np.argwhere(rest.part == right)
    assert np.array_equal(np.unique(r_truth, axis=0), np.unique(r_rest, axis=0))


def test_only_the_mannequins_have_a_truth_and_the_pose_must_fit():
    with pytest.raises(ValueError, match="only the mannequins"):
        posed_sample("frog", np.tile(np.eye(4), (2, 1, 1)))
    with pytest.raises(ValueError, match="18 finite 4x4"):
        posed_sample("mannequin", np.tile(np.eye(4), (3, 1, 1)))
    bad = np.tile(np.eye(4), (18, 1, 1))
    bad[3, 3, 0] = np.nan
    with pytest.raises(ValueError, match="finite"):
        posed_sample("mannequin", bad)
