"""Propose bones in the document: a preview is one undo step, replaced by the next, taken back on discard."""

from __future__ import annotations

import numpy as np

from volanim_core import samples


def test_a_preview_is_one_undo_step_and_the_next_replaces_it(doc):
    before = doc.undo.undo_label
    proposal = doc.proposal.compute("humanoid")
    doc.proposal.preview(proposal)
    assert [b.name for b in doc.bones.bones] == [b.name for b in samples.mannequin_bones().bones]
    assert doc.undo.undo_label.startswith("Propose bones (humanoid, 18 bones)")
    doc.proposal.preview(doc.proposal.compute("none"))  # another template: the first preview is undone first
    assert doc.undo.undo_label.startswith("Propose bones (none,")
    doc.undo.undo()
    assert doc.undo.undo_label == before and len(doc.bones) == 0


def test_accepted_bones_are_edited_like_any_and_discard_keeps_later_edits(doc):
    doc.proposal.preview(doc.proposal.compute("humanoid"))
    doc.proposal.accept()
    doc.bone_edits.move_joint("HEAD", doc.bones.joints["HEAD"] + 3)
    doc.proposal.discard()  # nothing previewing: the user's bones and edit stay
    assert "HEAD" in doc.bones.joints and doc.undo.undo_label == "Move joint HEAD"
    doc.proposal.preview(doc.proposal.compute("humanoid"))
    doc.bone_edits.move_joint("NECK", doc.bones.joints["NECK"] + 1)
    doc.proposal.discard()  # the preview is no longer the last edit: the user's edit on it is kept
    assert doc.undo.undo_label == "Move joint NECK"
    assert np.allclose(doc.bones.joints["HEAD"], doc.proposal.compute("humanoid").bones.joints["HEAD"])
