"""Connectivity in the studio model: cube, lasso, auto-connect, mirror, .connect round trips."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core import io, samples
from volanim_studio.model import Document
from volanim_studio.model.interaction import CubeMode, LassoMode, PickEvent
from volanim_studio.model.selection import in_cube, in_polygon, select_lasso, visible_mask


@pytest.fixture
def doc(doc):
    doc.bone_edits.set_bones(samples.mannequin_bones())
    return doc


def test_selection_math():
    pts = np.array([[0, 0, 0], [5, 5, 5], [10, 0, 0]])
    assert in_cube(pts, (0, 0, 0), 10).tolist() == [True, True, False]
    xy = np.array([[1.0, 1.0], [5.0, 5.0], [20.0, 1.0]])
    assert in_polygon(xy, [(0, 0), (10, 0), (10, 10), (0, 10)]).tolist() == [True, True, False]
    assert not in_polygon(xy, [(0, 0), (10, 0)]).any()  # two points are no outline
    # a column of three points at one pixel, one point alone: the front one of the column is visible
    xy = np.array([[5.0, 5.0], [5.2, 5.1], [5.1, 4.9], [50.0, 50.0]])
    depth = np.array([0.5, 0.2, 0.9, 0.7])
    assert visible_mask(xy, depth).tolist() == [False, True, False, True]


def test_lasso_depth_modes_on_a_built_scene():
    # a chest at depth 0..10 in front of an arm at depth 50..60, both under the outline
    chest = np.column_stack([np.full(10, 5.0), np.linspace(1, 9, 10)])
    arm = chest + [0.3, 0.2]
    xy = np.vstack([chest, arm])
    view = np.r_[np.linspace(0, 10, 10), np.linspace(50, 60, 10)]
    depth = view / 100
    poly = [(0, 0), (10, 0), (10, 10), (0, 10)]
    assert len(select_lasso(xy, depth, view, poly, mode="through")) == 20
    assert set(select_lasso(xy, depth, view, poly, mode="visible")) <= set(range(10))
    assert select_lasso(xy, depth, view, poly, mode="slab", slab=15).tolist() == list(range(10))
    with pytest.raises(ValueError, match="depth mode"):
        select_lasso(xy, depth, view, poly, mode="xray")


def test_cube_connect_remove_undo_and_counts(doc):
    mode = CubeMode(doc)
    elbow = samples.mannequin_bones().joints["L_ELBOW"]
    i = int(np.argmin(((doc.skeleton.points[: doc.visible_count] - elbow) ** 2).sum(1)))
    mode.press(PickEvent(point=i))
    assert np.array_equal(doc.cube_centre, doc.skeleton.points[i])
    assert mode.apply() == 0  # no working bone yet: nothing happens
    doc.select_bones([doc.bones.index("L_UPPERARM")])
    inside = mode.inside()
    assert len(inside) > 0
    assert mode.apply() == len(inside)
    per_bone, unconnected = doc.attachments.counts()
    assert per_bone[doc.bones.index("L_UPPERARM")] == len(inside)
    assert unconnected == doc.visible_count - len(inside)
    assert doc.bone_of_point(int(inside[0])) == "L_UPPERARM"
    mode.key("Right")
    assert doc.cube_centre[0] == doc.skeleton.points[i][0] + 1
    mode.key("X")
    doc.undo.undo()
    doc.undo.undo()
    assert (doc.attachments.bone == -1).all()


def test_lasso_mode_connects_working_bone(doc):
    mode = LassoMode(doc)
    doc.settings.lasso_depth = "through"
    doc.select_bones([0])
    shown = doc.shown_indices()
    xy = doc.skeleton.points[shown][:, [0, 2]].astype(float)  # a front view: x across, z up
    outline = [(-1, 199.5), (300, 199.5), (300, 400), (-1, 400)]
    zeros = np.zeros(len(xy))
    n = mode.finish(outline, xy, zeros, zeros, shown)
    assert n == int((doc.skeleton.points[shown][:, 2] >= 200).sum())
    n2 = mode.finish(outline, xy, zeros, zeros, shown, remove=True)
    assert n2 == n and (doc.attachments.bone == -1).all()


def test_bone_edits_carry_attachments(doc):
    a = doc.bones.index("L_THIGH")
    doc.attachments.assign([0, 1, 2], a)
    doc.bone_edits.set_root_order([a] + [i for i in range(len(doc.bones)) if i != a])
    assert doc.attachments.bone[:3].tolist() == [0, 0, 0] and doc.bone_of_point(0) == "L_THIGH"
    doc.bone_edits.remove_bones([0])
    assert doc.attachments.bone[:3].tolist() == [-1, -1, -1]
    doc.undo.undo()
    assert doc.bone_of_point(0) == "L_THIGH"
    doc.undo.undo()
    assert doc.attachments.bone[0] == a


def test_auto_connect_scopes_and_report(doc):
    doc.attachments.assign([0], doc.bones.index("HEAD"))
    report = doc.attachments.auto(scope="unconnected")
    assert report.kept == 1 and report.attached == doc.visible_count - 1
    assert doc.bone_of_point(0) == "HEAD"  # the manual attachment is kept
    doc.undo.undo()
    assert (doc.attachments.bone[1:] == -1).all()
    report = doc.attachments.auto(scope="all", overwrite=True)
    assert report.kept == 0
    doc2 = Document()
    doc2.set_skeleton(doc.skeleton)
    doc2.bone_edits.set_bones(doc.bones)
    with pytest.raises(ValueError, match="segmented volume"):
        doc2.attachments.auto()


def test_mirror_connectivity(doc):
    doc.attachments.auto(scope="all")
    left = doc.bones.index("L_FOREARM")
    right = doc.bones.index("R_FOREARM")
    on_left = np.flatnonzero(doc.attachments.bone == left)
    doc.attachments.assign(np.flatnonzero(doc.attachments.bone == right), -1)
    copied, lonely = doc.attachments.mirror([left])
    assert copied > 0 and copied + lonely >= len(on_left) * 0.9
    assert lonely == 0  # the mannequin is exactly symmetric
    assert (doc.attachments.bone == right).sum() == len(on_left)


def test_connect_save_reload_identical_and_missing_points(tmp_path, doc, mannequin):
    doc.attachments.auto(scope="all")
    doc.thinness = 0.6
    name = doc.attachments.default_filename("man")
    assert name == "man.0.60.connect"
    n = doc.attachments.save(tmp_path / name)
    shown = doc.visible_count
    assert n == int((doc.attachments.bone[:shown] >= 0).sum())
    other = Document()
    other.set_skeleton(mannequin[1])
    other.bone_edits.set_bones(doc.bones)
    assert other.attachments.load(tmp_path / name) == []
    assert np.array_equal(other.attachments.bone[:shown], doc.attachments.bone[:shown])
    # a cloud lacking some points gets them back, with a warning
    s = mannequin[1]
    partial = Document()
    partial.set_skeleton(type(s)(s.points[10:], s.dt[10:], s.thinness[10:]))
    partial.bone_edits.set_bones(doc.bones)
    warnings = partial.attachments.load(tmp_path / name)
    assert "10 points are not in the loaded skeleton" in warnings[0]
    assert len(partial.skeleton) == len(s) and partial.skeleton.is_sorted()
    # alone: the file's points and bones become the session's
    alone = Document()
    alone.attachments.load(tmp_path / name)
    assert len(alone.bones) == len(doc.bones) and (alone.attachments.bone >= 0).all()


def test_reload_onto_a_different_bone_skeleton_names_the_bone(tmp_path, doc):
    doc.attachments.auto(scope="all")
    doc.attachments.save(tmp_path / "a.connect")
    other = Document()
    other.set_skeleton(doc.skeleton)
    other.bone_edits.add_bone((1, 2, 3), (4, 5, 6))
    with pytest.raises(ValueError, match=r"bone 0 \(SPINE\) is not in the loaded bone skeleton"):
        other.attachments.load(tmp_path / "a.connect")
    io.write_bones(tmp_path / "x.bones", doc.bones)


def test_cube_keys_change_the_size_setting_that_the_panel_shows(doc):
    """+/- used to change a document attribute the cube-size slider never heard of."""
    mode = CubeMode(doc)
    seen = []
    doc.settings.events.cube_size.connect(lambda value, **_: seen.append(value))
    doc.set_cube(doc.skeleton.points[0])
    size = doc.settings.cube_size
    mode.key("Plus")
    mode.key("Plus")
    mode.key("Minus")
    assert doc.settings.cube_size == size + 2 and seen == [size + 2, size + 4, size + 2]


def test_auto_connect_fitted_gives_the_shown_points_what_the_command_line_gives(doc):
    """The studio's fitted auto-connect (#60) is the core's: the limbs' tubes measured on every point, the
    shown ones attached, one undoable step."""
    from volanim_core.rig.attach import attach_nearest_bone
    from volanim_core.rig.limb_tubes import carry_up

    skel = doc.skeleton
    report = doc.attachments.auto(scope="all", overwrite=True, method="fitted")
    n = doc.visible_count
    want = carry_up(skel.points, skel.dt, doc.bones, attach_nearest_bone(skel.points, doc.bones))[:n]
    assert report.attached == n and np.array_equal(doc.attachments.bone[:n], want)
    arm, torso = doc.bones.index("L_UPPERARM"), [doc.bones.index("SPINE"), doc.bones.index("L_CLAVICLE")]
    nearest = attach_nearest_bone(skel.points[:n], doc.bones)
    assert ((nearest == arm) & np.isin(want, torso)).any()  # the armpit: given to the torso
    doc.undo.undo()
    assert (doc.attachments.bone == -1).all()


def test_auto_connect_pieces_is_the_core_s_and_nearest_on_a_body_in_one_piece(doc):
    """The studio's pieces auto-connect (#62) is the core's; the mannequin is one piece, so it is the nearest
    bone for every point (a body in pieces: tests/core/rig/test_pieces.py)."""
    from volanim_core.rig.attach import attach_nearest_bone
    from volanim_core.rig.pieces import attach_by_piece

    skel = doc.skeleton
    report = doc.attachments.auto(scope="all", overwrite=True, method="pieces")
    n = doc.visible_count
    assert report.attached == n
    got = doc.attachments.bone[:n]
    assert np.array_equal(got, attach_by_piece(skel.points[:n], doc.bones, doc.mask))
    assert np.array_equal(got, attach_nearest_bone(skel.points[:n], doc.bones))


def test_auto_connect_measures_apart_from_the_document_and_refuses_a_result_for_other_bones(doc):
    """The studio runs the measuring in a worker (auto_job's task) and assigns on the GUI thread (its apply):
    the task changes nothing, and a result measured for bones since replaced is refused, not applied."""
    doc.bones = samples.mannequin_bones()
    task, apply = doc.attachments.auto_job(scope="all")
    label = doc.undo.undo_label
    result = task()
    assert (doc.attachments.bone == -1).all() and doc.undo.undo_label == label  # measured, nothing assigned
    report = apply(result)
    assert report.attached == doc.visible_count and doc.undo.undo_label.startswith("Auto-connect")
    task, apply = doc.attachments.auto_job(scope="all", method="nearest")
    result = task()
    doc.bones = samples.mannequin_bones()  # the bones replaced while it measured
    before = doc.attachments.bone.copy()
    with pytest.raises(ValueError, match="changed while auto-connect ran"):
        apply(result)
    assert np.array_equal(doc.attachments.bone, before)


def test_a_lasso_in_the_owned_body_gives_the_points_flesh_with_them_in_one_undo_step(doc):
    """#84: ownership repainted by lasso as points are. The default body moves the scan's voxels by their owners,
    which the points' attachments do not choose: a lasso that connects points also gives their flesh (the voxels
    of each point's sphere, the body's) to the working bone, and one Ctrl+Z takes both back."""
    from volanim_core.rig.ownership import ownership

    arm = doc.bones.index("L_UPPERARM")
    doc.attachments.auto(scope="unconnected")
    mode = LassoMode(doc)
    doc.settings.lasso_depth = "through"
    doc.select_bones([arm])
    shown = doc.shown_indices()
    p = doc.skeleton.points[shown]
    xy = p[:, [0, 2]].astype(float)
    outline = [(96, 200), (108, 200), (108, 222), (96, 222)]  # the armpit's side of the torso, front view
    zeros = np.zeros(len(xy))
    before = doc.undo.edits
    n = mode.finish(outline, xy, zeros, zeros, shown)
    assert n > 0 and doc.undo.edits == before + 1 and "their flesh" in doc.undo.undo_label
    # the flesh, computed here: every body voxel within a lassoed point's distance (its sphere)
    picked = doc.point_selection  # the points under the outline (selection.py's test, edges included)
    assert len(picked) and set(picked) >= set(shown[(xy[:, 0] > 96) & (xy[:, 0] < 108) & (xy[:, 1] > 200)
                                                      & (xy[:, 1] < 222)])
    grid = np.indices(doc.mask.shape).reshape(3, -1).T
    flesh = np.zeros(doc.mask.shape, bool)
    for k in picked:
        c, r = doc.skeleton.points[k], doc.skeleton.dt[k]
        near = grid[(np.abs(grid - c) <= r).all(1)]
        near = near[((near - c) ** 2).sum(1) <= r * r]
        flesh[tuple(near.T)] = True
    flesh &= doc.mask
    conn = doc.pose.tskel().connectivity
    owners = doc.ownership.of(conn).volume(doc.mask.shape)
    assert flesh.sum() > 500 and (owners[flesh] == arm + 1).all()
    made = ownership(doc.mask, conn).volume(doc.mask.shape)
    assert np.array_equal(owners[~flesh], made[~flesh])  # nothing else repainted
    doc.undo.undo()
    assert not doc.ownership.paints and not (doc.attachments.bone[picked] == arm).all()


# voxel points (one integer key each), and points no integer key holds: halves, a coordinate past 2**21
@pytest.mark.parametrize("shift, far", [(0.0, 0), (0.5, 0), (0.0, 2 ** 22)])
def test_a_file_s_points_are_found_in_the_skeleton_as_a_dict_of_tuples_finds_them(shift, far):
    from volanim_studio.model.attachments import row_positions

    rng = np.random.default_rng(7)
    points = np.unique(rng.integers(0, 40, (6000, 3)), axis=0).astype(np.float64) + shift
    rng.shuffle(points)
    wanted = np.vstack([points[rng.integers(0, len(points), 2000)], rng.integers(0, 50, (800, 3)) + shift,
                        [[0.0, 0.0, 0.0]], [[-0.0, 0.0, 0.0]], [[far, 1, 1]]])
    index = {tuple(p): i for i, p in enumerate(points.tolist())}
    want = np.array([index.get(tuple(p), -1) for p in wanted.tolist()])
    assert (want >= 0).sum() > 2000 and (want < 0).any()
    assert np.array_equal(row_positions(points, wanted), want)
    assert np.array_equal(row_positions(points[:0], wanted), np.full(len(wanted), -1))
