"""Smooth joints: blend weights (rig/skinning.py) and dual-quaternion blending (rig/dual_quaternion.py)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from tests import naive

from volanim_core.reconstruct.breakage import components
from volanim_core.reconstruct.engine import posed_centres, reconstruct
from volanim_core.rig.connectivity import BoneSegment, Connectivity
from volanim_core.rig.dual_quaternion import blended_matrices
from volanim_core.rig.pose import apply_rows, euler
from volanim_core.rig.skinning import Joints, skin_weights, transform_table

SMOOTH = Joints("smooth")


def rotation_about(centre, rot) -> np.ndarray:
    """Row-vector 4x4: rotate by ``rot`` (3x3, column convention) about ``centre``."""
    m = np.eye(4)
    m[:3, :3] = rot.T
    m[3, :3] = centre - centre @ rot.T
    return m


def cylinder(length=60, radius=4.0, joint=30) -> Connectivity:
    """A straight rod along x: two bones meeting at x = ``joint``, one medial point per voxel."""
    x = np.arange(5, 5 + length)
    points = np.column_stack([x, np.full_like(x, 20), np.full_like(x, 20)])
    bones = [BoneSegment((5, 20, 20), (joint, 20, 20), "UPPER"),
             BoneSegment((joint, 20, 20), (5 + length, 20, 20), "LOWER")]
    return Connectivity(bones, points, np.full(len(x), radius), None, (x >= joint).astype(int), joints=SMOOTH)


def test_blended_centres_match_the_naive_dual_quaternion_reference():
    rng = np.random.default_rng(4)
    mats = np.stack([rotation_about(rng.uniform(-20, 20, 3), Rotation.random(random_state=k).as_matrix())
                     for k in range(5)])
    mats[:, 3, :3] += rng.uniform(-5, 5, (5, 3))
    influence = np.array([[0, 1, -1, -1], [2, 0, 4, -1], [3, 1, 2, 4], [4, -1, -1, -1]])
    weight = np.array([[0.7, 0.3, 0, 0], [0.5, 0.25, 0.25, 0], [0.4, 0.3, 0.2, 0.1], [1.0, 0, 0, 0]])
    points = rng.uniform(0, 50, (4, 3))
    ours = blended_matrices(mats, influence, weight)
    moved = np.einsum("ni,nij->nj", points, ours[:, :3, :3]) + ours[:, 3, :3]
    for k in range(4):
        expect = naive.dual_quaternion_blend(points[k], mats, influence[k], weight[k])
        np.testing.assert_allclose(moved[k], expect, atol=1e-9)
    np.testing.assert_allclose(ours[3], mats[4], atol=1e-12)  # one bone at weight 1: exactly its motion


def test_a_blend_of_turns_about_one_joint_keeps_every_distance_to_it():
    """Two bones turning about the same joint by 0 and 120 degrees: any blend is a turn about that
    joint (dual quaternions never shrink it, as a linear blend of matrices does)."""
    joint = np.array([10.0, -3.0, 7.0])
    mats = np.stack([np.eye(4), rotation_about(joint, euler((0, 0, 120)))])
    w = np.linspace(0, 1, 11)
    out = blended_matrices(mats, np.tile([0, 1], (11, 1)), np.column_stack([1 - w, w]))
    p = joint + np.array([6.0, 2.0, -1.0])
    moved = np.einsum("i,nij->nj", p, out[:, :3, :3]) + out[:, 3, :3]
    np.testing.assert_allclose(np.linalg.norm(moved - joint, axis=1), np.linalg.norm(p - joint), atol=1e-9)
    ends = [p @ m[:3, :3] + m[3, :3] for m in mats]
    linear = (1 - w)[:, None] * ends[0] + w[:, None] * ends[1]
    assert np.linalg.norm(linear[5] - joint) < 0.6 * np.linalg.norm(p - joint)  # the candy wrapper we avoid


def test_a_shared_uniform_scale_is_kept_and_a_shear_is_refused():
    joint = np.array([3.0, 4.0, 5.0])
    mats = np.stack([np.eye(4), rotation_about(joint, euler((40, 0, 0)))])
    half = mats @ np.diag([0.5, 0.5, 0.5, 1.0])  # a coarse preview's 1/2
    a = blended_matrices(mats, np.array([[0, 1]]), np.array([[0.5, 0.5]]))
    b = blended_matrices(half, np.array([[0, 1]]), np.array([[0.5, 0.5]]))
    np.testing.assert_allclose(b[0], a[0] @ np.diag([0.5, 0.5, 0.5, 1.0]), atol=1e-12)
    sheared = mats.copy()
    sheared[1, 0, 1] = 0.3
    with pytest.raises(ValueError, match="bone 1: its matrix is not a rotation"):
        blended_matrices(sheared, np.array([[0, 1]]), np.array([[0.5, 0.5]]))


def test_weights_are_a_partition_of_unity_falling_off_from_the_joint():
    conn = cylinder()
    skin = skin_weights(conn.points, conn.dt, conn.bone, conn.bones, Joints("smooth", 1.0))
    assert np.all(skin.weight >= 0)
    np.testing.assert_allclose(skin.weight.sum(1), 1.0, atol=1e-12)
    x = conn.points[skin.index, 0]
    # blend width h: 1 x the bones' thickness (4); each bone reaches fully h along the rod from its
    # nearest point, then fades to nothing at 2h: UPPER's last point is x 29, LOWER's first 30
    assert x.min() == 30 - 2 * 4 + 1 and x.max() == 29 + 2 * 4 - 1
    own = skin.weight[:, 0]
    lower = conn.bone[skin.index] == 1
    assert np.all(np.diff(own[~lower]) < 0) and np.all(np.diff(own[lower]) > 0)  # 1 far away, 1/2 at the joint
    assert own[x == 30][0] == pytest.approx(0.5, abs=0.05)  # x 30 lies on both segments: the joint
    np.testing.assert_array_equal(skin.influence[:, 1], 1 - conn.bone[skin.index])


def test_a_seam_along_the_limb_blends_only_at_the_joint():
    """mannequin-large's hip: the torso's lowest points run beside the thigh for a long way below the
    joint. The thigh there stays rigid and those torso points go with the thigh; blending by the
    distance from the seam instead dragged the thigh's upper half (far-thigh Dice 0.90 at 120 degrees)."""
    z_torso, z_leg = np.arange(20, 81), np.arange(0, 40)
    points = np.vstack([np.column_stack([np.full_like(z_torso, 20), np.full_like(z_torso, 20), z_torso]),
                        np.column_stack([np.full_like(z_leg, 23), np.full_like(z_leg, 20), z_leg])])
    bone = np.r_[np.zeros(len(z_torso), int), np.ones(len(z_leg), int)]
    joint = np.array([21.5, 20.0, 40.0])
    bones = [BoneSegment(joint, (20, 20, 80), "TORSO"), BoneSegment(joint, (23, 20, 0), "LEG")]
    conn = Connectivity(bones, points, np.full(len(points), 5.0), None, bone, joints=SMOOTH)
    skin = conn.skin
    weight_on = np.zeros((len(points), 2))
    weight_on[np.arange(len(points)), bone] = 1.0
    for r, i in enumerate(skin.index):
        weight_on[i] = 0.0
        for k, w in zip(skin.influence[r], skin.weight[r]):
            if k >= 0:
                weight_on[i, k] += w
    far = points[:, 2] <= 40 - 3 * 5  # 3 blend widths (the thickness, 5) or more below the joint
    assert np.all(weight_on[far & (bone == 1), 1] == 1.0)  # the leg: rigid
    assert np.all(weight_on[far & (bone == 0), 1] > 0.95)  # the torso's points beside it: with the leg
    mats = np.stack([np.eye(4), rotation_about(joint, euler((90, 0, 0)))])
    bent = conn.posed(mats)
    leg = far & (bone == 1)
    np.testing.assert_allclose(posed_centres(bent)[leg], (np.c_[points[leg], np.ones(leg.sum())] @ mats[1])[:, :3],
                               atol=1e-9)
    assert len(components(reconstruct(bent, mode="binary", padding=1).volume)) == 1


def test_weights_are_zero_across_a_gap():
    """A third bone's points touch the rod's LOWER end at rest (a hand on the hip): they are not linked to
    it, so neither gets weight from the other, though they are nearer than the blend width."""
    rod = cylinder()
    x = np.arange(50, 65)
    hand = np.column_stack([x, np.full_like(x, 28), np.full_like(x, 20)])  # 8 voxels over the rod: spheres touch
    bones = [*rod.bones, BoneSegment((70, 28, 20), (50, 28, 20), "HAND")]
    points = np.vstack([rod.points, hand])
    bone = np.concatenate([rod.bone, np.full(len(x), 2)])
    dt = np.full(len(points), 4.0)
    skin = skin_weights(points, dt, bone, bones, Joints("smooth", 3.0))
    touched = bone[skin.index] == 2
    assert not touched.any()
    assert not (skin.influence == 2).any()
    assert len(skin) > 0  # the rod's own joint still blends


@pytest.mark.parametrize("angle", [0, 30, 60, 90, 120, 150])
def test_a_bent_cylinder_stays_one_piece_with_its_radius(angle):
    conn = cylinder(radius=4.0)
    joint = np.array([30.0, 20.0, 20.0])
    mats = np.stack([np.eye(4), rotation_about(joint, euler((0, 0, angle)))])
    smooth = conn.posed(mats)
    r = reconstruct(smooth, mode="binary", padding=1)
    assert len(components(r.volume)) == 1
    c = posed_centres(smooth)
    # centres keep their distance to the joint (each turned about it), and the medial curve stretches
    # little through the bend (1 voxel apart at rest): neighbouring spheres still overlap deeply
    np.testing.assert_allclose(np.linalg.norm(c - joint, axis=1), np.linalg.norm(conn.points - joint, axis=1),
                               atol=1e-5)
    assert np.linalg.norm(np.diff(c, axis=0), axis=1).max() < 2.0  # half the radius
    # the radius stays: every posed centre's voxels within 3.5 of it are filled, nothing beyond 4 + 1
    filled = np.argwhere(r.volume > 0) + r.origin
    d = np.sqrt(((filled[:, None, :] - c[None]) ** 2).sum(2)).min(1)
    assert d.max() < 4.0
    grid = np.argwhere(np.ones(r.volume.shape, bool)) + r.origin
    near = np.sqrt(((grid[:, None, :] - c[None]) ** 2).sum(2)).min(1) < 3.5
    assert r.volume.reshape(-1)[near].all()
    if angle >= 60:
        rigid = reconstruct(conn.with_joints(Joints()).posed(mats), mode="binary", padding=1)
        assert rigid.stats["filled"] < r.stats["filled"]  # the rigid bend's outside opens


def test_sampled_mode_reads_each_voxel_through_its_owners_blended_motion():
    conn = cylinder(radius=3.0)
    joint = np.array([30.0, 20.0, 20.0])
    mats = np.stack([np.eye(4), rotation_about(joint, euler((0, 0, 90)))])
    t = conn.posed(mats)
    source = np.zeros((80, 40, 40), np.uint16)
    source[...] = np.arange(80)[:, None, None] * 100 + np.arange(40)[None, :, None]  # position-coded
    ours = reconstruct(t, mode="sampled", source=source, padding=1)
    table, row = transform_table(t)
    owner = reconstruct(t, mode="owner", padding=1)
    assert owner.origin == ours.origin
    q = np.argwhere(owner.volume > 0)
    rows = owner.volume[tuple(q.T)].astype(int) - 1
    back = np.einsum("ni,nij->nj", np.column_stack([q + ours.origin, np.ones(len(q))]), np.linalg.inv(table[rows]))
    idx = np.floor(back[:, :3] + 0.5).astype(int)
    inside = ((idx >= 0) & (idx < source.shape)).all(1)
    expect = np.zeros(len(q), np.uint16)
    expect[inside] = source[tuple(idx[inside].T)]
    np.testing.assert_array_equal(ours.volume[tuple(q.T)], expect)
    assert (rows >= len(mats)).sum() > 50  # many voxels are read through a blended motion
    assert set(row[conn.points[:, 0] < 20]) == {0}  # far from the joint: the bone's own matrix


def test_points_in_any_order_move_by_their_own_rows():
    rng = np.random.default_rng(2)
    table = np.stack([rotation_about(rng.uniform(0, 9, 3), Rotation.random(random_state=k).as_matrix())
                      for k in range(6)])
    points = rng.uniform(0, 30, (40, 3))
    for row in (np.sort(rng.integers(0, 6, 40)), rng.integers(0, 6, 40), np.r_[5, 4, rng.integers(0, 3, 38)]):
        expect = np.array([np.append(p, 1) @ table[r] for p, r in zip(points, row)])[:, :3]
        np.testing.assert_allclose(apply_rows(points, row, table, 3), expect, atol=1e-12)


def test_a_thick_bone_reaches_further_than_a_thin_one():
    """The blend width is a multiple of each bone's own thickness (its thickest sphere): one sphere of
    radius 5 on UPPER widens UPPER's reach into LOWER, while LOWER (radius 2) reaches UPPER as before."""
    conn = cylinder(radius=2.0)
    dt = conn.dt.copy()
    dt[conn.points[:, 0] == 25] = 5.0
    skin = skin_weights(conn.points, dt, conn.bone, conn.bones, Joints("smooth", 1.0))
    x = conn.points[skin.index, 0]
    lower = conn.bone[skin.index] == 1
    assert x[~lower].min() == 30 - 2 * 2 + 1  # LOWER reaches 2h = 4 from x 30
    assert x[lower].max() > 29 + 2 * 2  # UPPER reaches beyond LOWER's 2h (up to 2 x 5 from x 29)
    assert x[lower].max() < 29 + 2 * 5


@pytest.mark.parametrize("angle", [60, 90, 120])
def test_a_speck_at_the_surface_moves_with_the_flesh_it_lies_on(angle):
    """A one-voxel sphere at the rod's surface beside the joint, linked to nothing (the skeleton's noise at
    a scan's surface): no bone's reach gets to it, so it used to move rigidly with its own bone while the
    blended flesh under it turned half as far, and the bend tore it off as a piece of its own."""
    rod = cylinder(radius=4.0)
    speck = np.array([[31, 24, 21]])  # 4.1 voxels from the nearest centre: in no sphere, unlinked, touching the rod
    conn = Connectivity(rod.bones, np.vstack([rod.points, speck]), np.r_[rod.dt, 1.0], None,
                        np.r_[rod.bone, 1], joints=SMOOTH)
    joint = np.array([30.0, 20.0, 20.0])
    mats = np.stack([np.eye(4), rotation_about(joint, euler((0, 0, angle)))])
    assert len(components(reconstruct(conn.posed(np.stack([np.eye(4)] * 2)), mode="binary", padding=1).volume)) == 1
    assert len(components(reconstruct(conn.posed(mats), mode="binary", padding=1).volume)) == 1
    skin = skin_weights(conn.points, conn.dt, conn.bone, conn.bones, SMOOTH)
    host = 26  # the rod point at x = 31, the sphere the speck lies on
    at = {int(k): r for r, k in enumerate(skin.index)}
    assert len(conn) - 1 in at and host in at
    np.testing.assert_array_equal(skin.influence[at[len(conn) - 1]], skin.influence[at[host]])
    np.testing.assert_allclose(skin.weight[at[len(conn) - 1]], skin.weight[at[host]])


@pytest.mark.slow  # Visible-Human scale (the full tier): 6-11 s each
def test_mannequin_large_raises_its_arm_with_nothing_torn_off_and_no_stump():
    """The largest sample, arm raised 90 degrees with smooth joints: its one-voxel surface specks (two
    stay apart at rest already) moved rigidly while the flesh they lie on blended, and tore off two pieces
    at the shoulder; four torso points on the flank beside the hanging arm, a gap from it, were reported as
    a stump (#42)."""
    from volanim_core import samples
    from volanim_core.reconstruct.breakage import breakage_report
    from volanim_core.rig.pose import pose_matrices, posed_joints

    s = samples.mannequin_large()
    conn = samples.part_connectivity(s).with_joints(SMOOTH)
    m = pose_matrices(s.bones, {"L_UPPERARM": (0, -90, 0)})
    report = breakage_report(conn.posed(m), s.bones.joints, posed_joints(s.bones, m))
    assert report.rest_pieces == 3 and len(report.components) == 3
    assert report.pieces == report.specks == [] and report.stumps == [] and report.cracks == 0 and report.healthy


def slab(width=24, length=60, radius=3.0, joint=30) -> Connectivity:
    """A flat plate: a medial sheet in the plane z = 20 (x along the two bones, y across), one point per voxel."""
    x, y = np.meshgrid(np.arange(5, 5 + length), np.arange(20 - width // 2, 20 + width // 2), indexing="ij")
    points = np.column_stack([x.ravel(), y.ravel(), np.full(x.size, 20)])
    bones = [BoneSegment((5, 20, 20), (joint, 20, 20), "UPPER"),
             BoneSegment((joint, 20, 20), (5 + length, 20, 20), "LOWER")]
    return Connectivity(bones, points, np.full(len(points), radius), None, (points[:, 0] >= joint).astype(int),
                        joints=SMOOTH)


def test_blended_points_of_a_medial_sheet_are_told_from_those_of_a_curve():
    """A plate's blended points lie on a sheet (their radii follow its stretch), a rod's on a curve (they
    keep their radii: the bent cylinder above); one-voxel spheres never thin. Each sheet link is listed
    once, with its rest length."""
    rod = cylinder()
    assert not len(skin_weights(rod.points, rod.dt, rod.bone, rod.bones, SMOOTH).sheet)
    plate = slab()
    dt = plate.dt.copy()
    dt[plate.points[:, 1] == 8] = 1.0  # the plate's edge row: one-voxel spheres
    skin = skin_weights(plate.points, dt, plate.bone, plate.bones, SMOOTH)
    edge = plate.points[skin.index, 1] == 8
    np.testing.assert_array_equal(skin.sheet, skin.index[~edge])
    a, b = skin.pairs.T
    assert (a < b).all() and len(np.unique(a * len(plate) + b)) == len(a)
    assert np.isin(skin.sheet, skin.pairs).all()
    np.testing.assert_allclose(skin.rest, np.linalg.norm(plate.points[a] - plate.points[b], axis=1))


def fanned_plate(angle):
    """The plate turned about its own long axis (x) by a blend whose weights grow along it: a point turns by
    ``w * angle``, w 0 at one end to 1 at the other, as mannequin-large's crotch sheet does about the hip's
    axis, with thigh weights 0.2 at the midline and 0.95 at the thigh. The sheet shears into a fan (a
    helicoid) and its area grows."""
    from volanim_core.rig.connectivity import Tskel
    from volanim_core.rig.skinning import Skin, _with_sheets, links

    plate = slab(width=24, length=30, radius=3.0, joint=100)  # all on UPPER; LOWER only drives the blend
    x = plate.points[:, 0]
    w = (x - x.min()) / np.ptp(x)
    index = np.flatnonzero(w > 0)
    influence = np.tile([0, 1, -1, -1], (len(index), 1))
    weight = np.column_stack([1 - w[index], w[index], np.zeros((len(index), 2))])
    pts = plate.points.astype(float)
    skin = _with_sheets(Skin(index, influence, weight), pts, plate.dt, links(pts, plate.dt))
    mats = np.stack([np.eye(4), rotation_about(np.array([0.0, 20.0, 20.0]), euler((angle, 0, 0)))])
    fanned = Tskel(plate.bones, mats, plate.points, plate.dt, None, plate.bone, joints=SMOOTH, skin=skin)
    kept = Tskel(plate.bones, mats, plate.points, plate.dt, None, plate.bone, joints=SMOOTH,
                 skin=Skin(index, influence, weight))  # the same weights, radii kept
    return plate, fanned, kept


@pytest.mark.parametrize("angle", [45, 120, 180])
def test_a_fanned_sheet_thins_by_its_stretch(angle):
    """Each sphere of a fanned sheet thins by the mean stretch of its links (a naive reference, point by
    point), to no less than THIN_FLOOR of its radius: the fan fills less than with its radii kept, in one
    piece. The same frame unposed keeps every radius exactly. (The volume against rest is measured on
    mannequin-large below: a plate this thin is all discretisation, its rest count 20 % under a turned one's.)"""
    from volanim_core.rig.skinning import THIN_FLOOR, posed_radii

    plate, fanned, kept = fanned_plate(angle)
    c = posed_centres(fanned)
    r = posed_radii(fanned, c)
    skin = fanned.skin
    np.testing.assert_allclose(r, naive.thinned_radii(plate.points, c, plate.dt, skin.sheet, skin.pairs, THIN_FLOOR),
                               rtol=1e-12)
    assert THIN_FLOOR * 3.0 <= r.min() < 3.0 and r.max() == 3.0
    thinned = reconstruct(fanned, mode="binary", padding=1)
    assert thinned.stats["filled"] < reconstruct(kept, mode="binary", padding=1).stats["filled"]
    assert len(components(thinned.volume)) == 1
    _, still, _ = fanned_plate(0)
    assert posed_radii(still, posed_centres(still)) is still.dt


def test_thinned_radii_follow_the_points_in_any_order():
    """A frame's points reordered or a subset taken (Tskel.take: grouping by bone, the thinness slider):
    the sheet and its links are renumbered, so each point thins exactly as before."""
    from volanim_core.rig.skinning import posed_radii

    _, fanned, _ = fanned_plate(90)
    expect = posed_radii(fanned, posed_centres(fanned))
    order = np.random.default_rng(1).permutation(len(fanned))
    moved = fanned.take(order)
    np.testing.assert_allclose(posed_radii(moved, posed_centres(moved)), expect[order])
    half = np.sort(order[: len(order) // 2])
    sub = fanned.take(half)
    r = posed_radii(sub, posed_centres(sub))
    assert r.shape == (len(half),) and (r >= 0.75 * 3.0).all()


@pytest.mark.slow  # Visible-Human scale (the full tier): 6-11 s each
def test_mannequin_large_bends_its_hip_120_degrees_within_3_percent_of_its_volume():
    """Hip flexion 120 degrees with smooth joints: the crotch's medial sheet, blended between torso and
    thigh, fanned out with its radii kept and the body grew 4.6 % (target: within 3 %). Its spheres now
    thin with the sheet's stretch; nothing tears off, no crack, no stump."""
    from volanim_core import samples
    from volanim_core.reconstruct.breakage import breakage_report
    from volanim_core.rig.pose import pose_matrices, posed_joints

    s = samples.mannequin_large()
    conn = samples.part_connectivity(s).with_joints(SMOOTH)
    m = pose_matrices(s.bones, {"L_THIGH": (-120, 0, 0)})
    report = breakage_report(conn.posed(m), s.bones.joints, posed_joints(s.bones, m))
    assert abs(report.loss_percent) <= 3.0
    assert report.pieces == [] and report.stumps == [] and report.cracks == 0
