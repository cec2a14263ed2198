"""Pose state and previews in the model (no Qt)."""

from __future__ import annotations

import numpy as np
import pytest

from paths import ASSETS
from volanim_core import io, samples
from volanim_core.reconstruct.engine import reconstruct
from volanim_core.skeleton.skeletonize import skeletonize
from volanim_studio.model import Document
from volanim_studio.model.preview import make_preview


@pytest.fixture
def doc():
    s = samples.mannequin()
    d = Document()
    d.set_volume(s.volume, s.mask)
    d.set_skeleton(skeletonize(s.mask))
    d.bone_edits.set_bones(s.bones)
    d.attachments.load(ASSETS / "mannequin.0.50.connect")
    return d


def test_slider_drag_is_one_undo_step_and_children_follow(doc):
    b = doc.bones.index("L_UPPERARM")
    for a in range(0, -46, -5):
        doc.pose.set_angles(b, (0, a, 0))
    doc.undo.seal()
    m = doc.pose.matrices()
    assert np.allclose(m[doc.bones.index("L_FOREARM")], m[b]) and not np.allclose(m[b], np.eye(4))
    doc.undo.undo()
    assert doc.pose.is_rest
    doc.undo.redo()
    assert np.allclose(doc.pose.angles_of(b), (0, -45, 0))


def test_pose_survives_reordering_and_reset(doc):
    b = doc.bones.index("R_SHIN")
    doc.pose.set_angles(b, (20, 0, 0), merge=False)
    doc.bone_edits.set_root_order(list(range(len(doc.bones)))[::-1])
    assert np.allclose(doc.pose.angles_of(doc.bones.index("R_SHIN")), (20, 0, 0))
    doc.pose.reset(doc.bones.index("R_SHIN"))
    assert doc.pose.is_rest


def test_trans_and_tskel_round_trip(tmp_path, doc):
    doc.pose.set_angles(doc.bones.index("L_UPPERARM"), (0, -45, 10), merge=False)
    doc.pose.save_trans(tmp_path / "p.trans")
    m = doc.pose.matrices()
    doc.pose.reset()
    doc.pose.load_trans(tmp_path / "p.trans")
    assert np.allclose(doc.pose.matrices(), m, atol=1e-9)
    n = doc.pose.save_tskel(tmp_path / "p.tskel")
    t = io.read_tskel(tmp_path / "p.tskel")
    assert len(t) == n == int((doc.attachments.bone[: doc.visible_count] >= 0).sum())
    assert np.allclose(t.matrices, m)
    wrong = tmp_path / "w.trans"
    wrong.write_text("Root: 0 0 0 :: 1 1 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n")
    with pytest.raises(ValueError, match="18 bones but the .trans has 1"):
        doc.pose.load_trans(wrong)


def test_preview_equals_the_core_and_reduced_preview_is_coarser(doc):
    doc.pose.set_angles(doc.bones.index("L_UPPERARM"), (0, -45, 0), merge=False)
    t = doc.pose.tskel()
    p = make_preview(t, mode="sampled", source=doc.volume)
    direct = reconstruct(t, mode="sampled", source=doc.volume)
    assert np.array_equal(p.reconstruction.volume, direct.volume) and p.reconstruction.origin == direct.origin
    half = make_preview(t, mode="bone", factor=2)
    assert all(abs(a * 2 - b) <= 4 for a, b in zip(half.reconstruction.volume.shape, direct.volume.shape))
    with pytest.raises(ValueError, match="connect points"):
        make_preview(type(t)(t.bones, t.matrices, np.zeros((0, 3)), [], None, []))


def test_neighbour_lists_are_cached_until_the_frame_changes(doc):
    """The studio keeps no lists of its own: reconstruct() remembers them per connectivity."""
    from volanim_core.reconstruct.engine import file_ordered
    from volanim_core.reconstruct.neighbours import CUT_MIN_RADIUS, cached_neighbours

    def lists():
        return cached_neighbours(file_ordered(doc.pose.tskel())[0])

    first = lists()
    doc.pose.set_angles(doc.bones.index("L_UPPERARM"), (0, -30, 0), merge=False)
    assert lists() is first  # a pose change keeps them
    clipped = int(np.flatnonzero(doc.pose.tskel().dt >= CUT_MIN_RADIUS)[0])
    doc.attachments.assign([clipped], doc.bones.index("HEAD"))  # an edit of a point they hold drops them
    second = lists()
    assert second is not first
    doc.thinness = 0.8
    assert lists() is not second


def test_a_report_made_with_kept_rest_parts_equals_a_fresh_one_and_edits_drop_them(doc):
    joints = dict(doc.bones.joints)
    doc.pose.set_angles(doc.bones.index("L_UPPERARM"), (0, -45, 0), merge=False)
    t = doc.pose.tskel()
    assert doc.pose.rest_parts(t) is None
    version = doc.pose.rest_version
    first = make_preview(t, report=True, joints=joints, posed_joints=doc.pose.posed_joints())
    doc.pose.keep_rest_parts(t, first.rest_parts, version)
    doc.pose.set_angles(doc.bones.index("L_UPPERARM"), (0, -80, 0), merge=False)  # a pose change keeps them
    t = doc.pose.tskel()
    kept = doc.pose.rest_parts(t)
    assert kept is first.rest_parts
    again = make_preview(t, report=True, joints=joints, posed_joints=doc.pose.posed_joints(), rest_parts=kept)
    fresh = make_preview(t, report=True, joints=joints, posed_joints=doc.pose.posed_joints())
    assert again.report == fresh.report and again.rest_parts is kept
    # an attachment edit drops them, and a report asked for before the edit is not kept after it
    version = doc.pose.rest_version
    doc.attachments.assign([0], doc.bones.index("HEAD"))
    assert doc.pose.rest_parts(doc.pose.tskel()) is None
    doc.pose.keep_rest_parts(doc.pose.tskel(), fresh.rest_parts, version)
    assert doc.pose.rest_parts(doc.pose.tskel()) is None
    doc.thinness = 0.8  # another slider position is another frame
    assert doc.pose.rest_parts(doc.pose.tskel()) is None


def test_a_frame_maker_makes_on_any_thread_the_frame_of_the_moment_it_was_asked(doc):
    """#85: the live thread makes each drag's frame itself (grouping the frog's 400 k points took the GUI thread
    10-15 ms a picture). The maker copies what the frame is made of when it is asked for: an edit after that (a
    point given to another bone, the pose turned on) is not in the frame it makes, which is tskel() of then."""
    import threading

    b = doc.bones.index("L_UPPERARM")
    doc.pose.set_angles(b, (0, -40, 0))
    want = doc.pose.tskel()
    make = doc.pose.frame_maker()
    shown = np.flatnonzero(doc.skeleton.thinness >= doc.thinness)[:50]  # points the frame holds
    doc.attachments.assign_many(shown, np.full(len(shown), doc.bones.index("HEAD")), "to the head")
    doc.pose.set_angles(b, (0, -80, 0))
    made = []
    worker = threading.Thread(target=lambda: made.append(make()))
    worker.start()
    worker.join()
    got = made[0]
    assert np.array_equal(got.points, want.points) and np.array_equal(got.bone, want.bone)
    assert np.array_equal(got.matrices, want.matrices)
    now = doc.pose.tskel()  # the document moved on: other attachments, another pose
    assert not np.array_equal(now.bone, got.bone) and not np.array_equal(now.matrices, got.matrices)


def test_a_drag_s_pictures_share_one_connectivity_and_any_edit_makes_a_new_one(doc):
    """#85: each live picture grouped the frog's 400 k points by bone again, copied them to attach the ownership and
    hashed them to find it: 95 ms of a picture's 256. Now a drag's pictures share the connectivity (and its
    ownership); a point given to another bone, a bone moved or another thinness is a new one, never the old."""
    b = doc.bones.index("L_UPPERARM")
    first = doc.pose.frame_maker()()
    doc.pose.set_angles(b, (0, -40, 0))
    second = doc.pose.frame_maker()()
    assert second.connectivity is first.connectivity
    assert not np.array_equal(second.matrices, first.matrices)
    assert np.array_equal(second.matrices, doc.pose.tskel().matrices)
    shown = np.flatnonzero(doc.skeleton.thinness >= doc.thinness)[:50]
    doc.attachments.assign_many(shown, np.full(len(shown), doc.bones.index("HEAD")), "to the head")
    third = doc.pose.frame_maker()()
    assert third.connectivity is not first.connectivity
    assert np.array_equal(third.bone, doc.pose.tskel().bone) and not np.array_equal(third.bone, first.bone)
    doc.thinness = min(1.0, doc.thinness + 0.1)
    fourth = doc.pose.frame_maker()()
    assert len(fourth) == len(doc.pose.tskel()) < len(third)
    # the owned frame of two pictures: one connectivity with the ownership, the same as a fresh attach's
    a, b2 = doc.ownership.attach(fourth), doc.ownership.attach(doc.pose.frame_maker()())
    assert a.ownership is not None and b2.connectivity is a.connectivity
    assert np.array_equal(a.ownership.labels, doc.ownership.attach(doc.pose.tskel()).ownership.labels)
