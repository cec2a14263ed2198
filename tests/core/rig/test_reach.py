"""Flesh its chain cannot reach (rig/reach.py): on a body drawn by hand, and on the frog, whose folded legs
press one leg's flesh against another's."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core import samples
from volanim_core.reconstruct.checks import report
from volanim_core.rig.connectivity import BoneSegment, Trans
from volanim_core.rig.ownership import Ownership, bone_parents
from volanim_core.rig.reach import hang_on, out_of_reach, reach_notes, unreached


def _body():
    """A trunk (bone 0, along x) with two limbs going up from its ends (1 from its root, 3 from its end: its
    child), and a forearm (2, child of 1) bent across to rest on limb 3: 2's block touches 3's flesh and
    nothing of 1's."""
    bones = [BoneSegment(np.array([2.0, 2, 2]), np.array([30.0, 2, 2]), "TRUNK"),
             BoneSegment(np.array([2.0, 2, 2]), np.array([2.0, 20, 2]), "L_ARM"),
             BoneSegment(np.array([2.0, 20, 2]), np.array([27.0, 20, 2]), "L_FOREARM"),
             BoneSegment(np.array([30.0, 2, 2]), np.array([30.0, 20, 2]), "R_ARM")]
    labels = np.zeros((34, 24, 5), np.uint8)
    labels[0:32, 0:5, :] = 1  # the trunk
    labels[0:5, 5:16, :] = 2  # the arm, on the trunk
    labels[10:27, 17:22, :] = 3  # the forearm: a gap of a row to its arm (y 16), resting on the right arm
    labels[27:32, 5:22, :] = 4  # the right arm, on the trunk
    own = Ownership(labels, (0, 0, 0), bones, np.zeros(4))
    return own, labels


def test_flesh_that_touches_its_chain_only_through_another_limb_is_named():
    own, labels = _body()
    assert bone_parents(own.bones) == [None, None, 1, 0]
    lost = unreached(own)
    assert lost.tolist() == [0, 0, int((labels == 3).sum()), 0]
    notes = reach_notes(own)
    assert len(notes) == 1 and notes[0].startswith(f"L_FOREARM: {int((labels == 3).sum())} of its")
    # its arm reaching it (the gap closed) makes it the arm's to carry: nothing said
    joined = labels.copy()
    joined[0:12, 16, :] = 2
    closed = Ownership(joined, (0, 0, 0), own.bones, np.zeros(4))
    assert not unreached(closed).any() and reach_notes(closed) == []
    # nor when its flesh starts in the ball at its own joint (2, 20, 2), which re-grows it in every pose
    at_joint = labels.copy()
    at_joint[5:10, 17:22, :] = 3  # its nearest voxel 3 from the joint
    assert not unreached(Ownership(at_joint, (0, 0, 0), own.bones, np.array([0, 0, 3.0, 0]))).any()
    assert unreached(Ownership(at_joint, (0, 0, 0), own.bones, np.zeros(4))).tolist()[2] > 0  # 1.5: too small


def test_hang_on_gives_the_stray_flesh_to_the_limb_it_rests_on_and_nothing_else():
    """`--hang-on`: the forearm resting on the right arm, apart from its own, becomes the right arm's flesh;
    every other voxel keeps its owner, the body is the same, and nothing is left out of reach. An island that
    touches no flesh is no limb's to hang on: it stays."""
    own, labels = _body()
    island = labels.copy()
    island[12:15, 23, 0:2] = 2  # a speck of the arm's, touching nothing
    own = Ownership(island, (0, 0, 0), own.bones, np.zeros(4))
    hung, moved = hang_on(own)
    forearm = labels == 3
    assert moved == [(2, 3, int(forearm.sum()))]
    assert (hung.labels[forearm] == 4).all()
    assert np.array_equal(hung.labels[~forearm], island[~forearm])
    assert not unreached(hung).any() and reach_notes(hung) == []
    # a rig with nothing out of reach is given back as it is
    same, none = hang_on(hung)
    assert none == [] and same is hung


def test_an_island_at_rest_is_no_limbs_loss():
    """A porous scan's specks that touch no flesh at all come apart in the rest pose too (`report` counts
    the rest's pieces): they are not said."""
    own, labels = _body()
    island = labels.copy()
    island[:, :, :] = np.where(labels == 3, 0, labels)  # no forearm ...
    island[12:15, 22:24, 0:2] = 3  # ... but a speck of its flesh, alone
    assert not unreached(Ownership(island, (0, 0, 0), own.bones, np.zeros(4))).any()


@pytest.mark.slow
def test_the_frogs_legs_pressed_together_are_named_and_are_the_leaf_that_tears():
    """The frog's auto-rig (autorig --connect's pieces): R_POST_3's flesh touches the body only through
    L_POST2_3's, and bent 45 degrees that leaf tears off; every leaf whose flesh its chain reaches stays
    whole at 45 degrees. (Spot's, the rabbit's, the ant's, Bob's and the mannequins' rigs name none:
    benchmarks/bench_autorig_bodies.py prints it.)"""
    from volanim_core.rig.attach import connect
    from volanim_core.rig.autorig import autorig
    from volanim_core.rig.curve_skeleton import balls
    from volanim_core.rig.ownership import ownership
    from volanim_core.rig.pose import bend_across, pose_matrices, root_bones
    from volanim_core.skeleton.skeletonize import skeletonize

    s = samples.load("frog")
    skel = skeletonize(s.mask)
    bones = autorig(skel).bones
    conn = connect(skel, bones, method="pieces", mask=balls(skel))[0]
    own = ownership(s.mask, conn)
    named = {own.bones[k].label: lost for k, lost in out_of_reach(own)}
    assert named.get("R_POST_3", 0) > 0.9 * 27_000
    c = conn.with_ownership(own)
    for k in bones.leaves():
        label = bones.bones[k].label
        rep = report(c, Trans(root_bones(bones), pose_matrices(bones, {label: bend_across(bones, label, 45)})),
                     bones=bones)
        assert rep.healthy == (label not in named), (label, rep.verdict)
