"""Naming chains in one line (issue #18: naming the mannequin's joints took 43 of ~100 actions)."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core import samples
from volanim_core.rig.bones import BoneSkeleton
from volanim_studio.model import Document


@pytest.fixture
def doc():
    """The mannequin's bones with every joint renamed J0, J1, ... (as clicking them in makes them)."""
    man = samples.mannequin_bones()
    d = Document()
    d.set_volume(samples.mannequin().volume)
    old = list(man.joints)
    anon = {n: f"J{k}" for k, n in enumerate(old)}
    d.bone_edits.set_bones(BoneSkeleton({anon[n]: p for n, p in man.joints.items()},
                                        [type(b)(anon[b.proximal], anon[b.distal], "") for b in man.bones]))
    d.anon = anon
    return d


def test_the_chain_of_an_arm_bone_runs_from_the_neck_to_the_fingers(doc):
    a = doc.anon
    upper = next(i for i, b in enumerate(doc.bones.bones) if b.proximal == a["L_SHOULDER"])
    assert doc.bone_edits.chain_through(upper) == [a[n] for n in ("NECK", "L_SHOULDER", "L_ELBOW", "L_WRIST",
                                                                      "L_FINGERS")]
    assert doc.bone_edits.chain_from(a["L_HIP"]) == [a[n] for n in ("L_HIP", "L_KNEE", "L_ANKLE", "L_TOE")]
    assert doc.bone_edits.chain_from(a["PELVIS"]) == [a["PELVIS"]]  # a fork: which way is not known


def test_one_line_names_a_chain_with_the_side_added_in_one_undo_step(doc):
    a = doc.anon
    chain = doc.bone_edits.chain_from(a["R_HIP"])
    before = doc.undo.edits
    assert doc.bone_edits.rename_chain(chain, "HIP, KNEE ANKLE,TOE") == ["R_HIP", "R_KNEE", "R_ANKLE", "R_TOE"]
    assert doc.undo.edits == before + 1
    assert np.array_equal(doc.bones.joints["R_KNEE"], samples.mannequin_bones().joints["R_KNEE"])
    doc.undo.undo()
    assert "R_KNEE" not in doc.bones.joints and a["R_KNEE"] in doc.bones.joints
    neck = doc.bone_edits.chain_through(next(i for i, b in enumerate(doc.bones.bones)
                                             if b.proximal == a["L_SHOULDER"]))
    names = ["NECK", "SHOULDER", "ELBOW", "WRIST", "FINGERS"]  # every joint, the fork too
    assert doc.bone_edits.rename_chain(neck, names)[:2] == ["NECK", "L_SHOULDER"]  # on the plane: no prefix


def test_fewer_names_than_joints_leave_the_fork_at_the_top_its_name(doc):
    """The README's step: the arm's chain from the neck named SHOULDER, ELBOW, WRIST, FINGERS renamed
    the neck SHOULDER and left the fingertip unnamed (issue #37)."""
    a = doc.anon
    edits = doc.bone_edits
    edits.rename_chain(edits.chain_from(a["PELVIS"]) + [a["NECK"], a["HEAD"]], "PELVIS, NECK, HEAD")
    arm = edits.chain_through(next(i for i, b in enumerate(doc.bones.bones) if b.proximal == a["L_SHOULDER"]))
    assert arm[0] == "NECK"
    assert edits.rename_chain(arm, "SHOULDER, ELBOW, WRIST, FINGERS") == ["L_SHOULDER", "L_ELBOW", "L_WRIST",
                                                                          "L_FINGERS"]
    assert "NECK" in doc.bones.joints and a["L_FINGERS"] not in doc.bones.joints
    assert edits.chain_from("L_SHOULDER") == ["L_SHOULDER", "L_ELBOW", "L_WRIST", "L_FINGERS"]
    leg = edits.chain_from(a["R_HIP"])  # no fork on top: the names start at its first joint
    assert edits.rename_chain(leg, "HIP, KNEE") == ["R_HIP", "R_KNEE"]


@pytest.mark.parametrize("names, error", [("", "type the names"), ("A B C D E", "5 names for a chain of 4"),
                                          ("HIP HIP", "appears twice"), ("L_HIP, L_TAKEN", "already a joint")])
def test_bad_chain_names_are_refused_and_change_nothing(doc, names, error):
    doc.bone_edits.rename_joint(doc.anon["HEAD"], "L_TAKEN")  # a name outside the chain
    chain = doc.bone_edits.chain_from(doc.anon["L_HIP"])
    joints = dict(doc.bones.joints)
    with pytest.raises(ValueError, match=error):
        doc.bone_edits.rename_chain(chain, names)
    assert doc.bones.joints.keys() == joints.keys()
