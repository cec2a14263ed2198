"""The fitted attachment (#60 item 4): flesh a limb's tube cannot hold goes to the bone above -- measured
against the mannequin's true parts and its true posed shape, not against itself."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core import samples
from volanim_core.cli import main
from volanim_core.mannequin_body import _mannequin_parts
from volanim_core.posed_truth import posed_sample
from volanim_core.reconstruct.engine import reconstruct
from volanim_core.reconstruct.shape import compare_shapes
from volanim_core.rig.attach import attach_nearest_bone, connect
from volanim_core.rig.limb_tubes import carry_up, tube_profiles
from volanim_core.rig.pose import pose_matrices
from volanim_core.skeleton.skeletonize import skeletonize

LIMBS = ("L_UPPERARM", "L_FOREARM", "L_THIGH", "L_SHIN", "R_UPPERARM", "R_SHIN")


@pytest.fixture(scope="module")
def mannequin():
    s = samples.mannequin()
    return s, skeletonize(s.mask, min_thinness=0.5)


def true_bone(sample, points) -> np.ndarray:
    """Each point's true part (the capsule it lies deepest in), as a bone index."""
    p = np.round(points).astype(int)
    return np.asarray(sample.part)[p[:, 0], p[:, 1], p[:, 2]].astype(int) - 1


def test_the_tubes_are_the_limbs_own_radii(mannequin):
    """Fitted from the skeleton alone, each limb's tube is its capsule's radius at both joints."""
    s, skel = mannequin
    tubes = tube_profiles(skel.points, skel.dt, s.bones, attach_nearest_bone(skel.points, s.bones))
    capsules = {name: (ra, rb) for name, _a, _b, ra, rb, _squash, _rod in _mannequin_parts(s.bones)}
    for name in LIMBS:
        got = tubes[s.bones.index(name)]
        assert np.allclose(got, capsules[name], atol=2.0), (name, got, capsules[name])


def test_the_armpit_goes_to_the_torso_and_the_arm_keeps_its_own(mannequin):
    s, skel = mannequin
    nearest = attach_nearest_bone(skel.points, s.bones)
    fitted = carry_up(skel.points, skel.dt, s.bones, nearest)
    true = true_bone(s, skel.points)
    arm = s.bones.index("L_UPPERARM")
    wrong_before = int(((nearest == arm) & (true != arm)).sum())
    wrong_after = int(((fitted == arm) & (true != arm)).sum())
    assert wrong_before == 19 and wrong_after <= 5  # torso points the arm carried (measured 19 -> 2)
    own = true == arm
    assert (fitted[own] == arm).mean() >= 0.9  # the arm's own stay on it (measured 0.93: some at the shoulder go up)
    # and on every limb: at least as many points on their true bone as nearest gives
    for name in LIMBS:
        k = s.bones.index(name)
        assert ((fitted == k) == (true == k)).mean() >= ((nearest == k) == (true == k)).mean()


def test_the_raised_arm_carries_no_fist_of_armpit_flesh(mannequin):
    """#60's walkthrough: L_UPPERARM raised 90 degrees, against the capsules posed the same way. Nearest
    connect swings a blob of 6 % of the arm with it; fitted leaves about 1 % (the true parts: 1.0 %)."""
    s, skel = mannequin
    bones = s.bones
    m = pose_matrices(bones, {"L_UPPERARM": (0, -90, 0)})
    truth = posed_sample("mannequin", m)
    limb = int(np.isin(np.asarray(s.part), [bones.index(n) + 1 for n in ("L_UPPERARM", "L_FOREARM", "L_HAND")]).sum())
    blobs = {}
    for method in ("nearest", "fitted"):
        conn, _ = connect(skel, bones, method=method)
        r = reconstruct(conn.posed(m), mode="bone")
        rep = compare_shapes(r.volume, truth.volume, ours_origin=r.origin, truth_origin=truth.origin)
        blobs[method] = 100 * rep.largest_extra.voxels / limb
    assert blobs["nearest"] > 5.0 and blobs["fitted"] < 2.0, blobs


def test_the_command_line_connects_fitted_without_the_scan(tmp_path, capsys):
    from volanim_core import io

    io.write_skeleton(tmp_path / "m.mskel", skeletonize(samples.mannequin().mask, min_thinness=0.5))
    io.write_bones(tmp_path / "m.bones", samples.mannequin_bones())
    assert main(["connect", str(tmp_path / "m.mskel"), str(tmp_path / "m.bones"), "--method", "fitted",
                 "-o", str(tmp_path / "m.connect")]) == 0
    assert "(fitted)" in capsys.readouterr().out
    assert len(io.read_connect(tmp_path / "m.connect")) > 4000


def test_a_hand_or_foot_stays_in_its_limb_on_the_larger_mannequin():
    """mannequin-large: a ball at a limb's far end (a hand's, a foot's) spills past the straight tube of its
    bone and was carried up bone by bone, to the spine (151 hand points a side) and the pelvis (53 foot
    points). Carrying up is for the flesh next to the parent's joint (the armpit, the groin) only."""
    from volanim_core.samples import mannequin_limb

    s = samples.mannequin_large()
    skel = skeletonize(s.mask, min_thinness=0.5)
    conn = connect(skel, s.bones, method="fitted")[0]
    names = [b.label for b in s.bones.bones]
    truth = true_bone(s, conn.points)
    ends = np.isin(truth, [names.index(n) for n in names if n.endswith(("HAND", "FOOT"))])
    assert ends.sum() > 100
    moved = [(names[t], names[b]) for t, b in zip(truth[ends], conn.bone[ends])
             if mannequin_limb(names[t]) != mannequin_limb(names[b])]
    assert moved == []
