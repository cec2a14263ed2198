"""The breakage report: healthy poses, and a wrong shoulder attachment that it must point at."""

from __future__ import annotations

import numpy as np
import pytest

from paths import ASSETS
from volanim_core import io, samples
from volanim_core.reconstruct.breakage import breakage_report, components, misplaced_points, stumps
from volanim_core.rig.connectivity import BoneSegment, Connectivity, Trans
from volanim_core.rig.pose import local_motion, pose_matrices, posed_joints, root_bones, scaled
from volanim_core.rig.tskel_tools import connect_to_tskel


@pytest.fixture(scope="module")
def man():
    return samples.mannequin(), io.read_connect(ASSETS / "mannequin.0.50.connect")


def frame(s, conn, rotations):
    m = pose_matrices(s.bones, rotations)
    return connect_to_tskel(conn, Trans(root_bones(s.bones), m)), posed_joints(s.bones, m)


def shoulder_on_torso(s, conn, radius=20.0):
    """The deliberate mistake: upper-arm points near the shoulder attached to the SPINE."""
    bone = conn.bone.copy()
    near = np.linalg.norm(conn.points - s.bones.joints["L_SHOULDER"], axis=1) < radius
    bone[near & (conn.bone == s.bones.index("L_UPPERARM"))] = s.bones.index("SPINE")
    return Connectivity(conn.bones, conn.points, conn.dt, conn.thinness, bone)


def test_rest_pose_is_healthy(man):
    s, conn = man
    t, pj = frame(s, conn, {})
    r = breakage_report(t, s.bones.joints, pj)
    assert r.healthy and r.cracks == 0 and r.lost_voxels == 0 and r.loss_percent == 0 and not r.pieces


def test_wrong_shoulder_connectivity_is_reported_at_the_shoulder(man):
    s, conn = man
    good, pj = frame(s, conn, {"L_UPPERARM": (0, -90, 0)})
    assert breakage_report(good, s.bones.joints, pj).healthy
    bad, pj = frame(s, shoulder_on_torso(s, conn), {"L_UPPERARM": (0, -90, 0)})
    r = breakage_report(bad, s.bones.joints, pj)
    assert not r.healthy and len(r.components) == 2
    assert r.pieces[0][1] == "L_SHOULDER" and "near L_SHOULDER" in "\n".join(r.lines())
    assert r.joints[0].name == "L_SHOULDER"


def test_a_stump_that_stays_one_piece_is_not_healthy(man):
    """Shoulder points left on the torso, arm raised 90 degrees: one component and 59 cracks, and the
    old report said "healthy" while a piece of the upper arm stayed at the shoulder (issue #18)."""
    s, conn = man
    bad, pj = frame(s, shoulder_on_torso(s, conn, radius=12.0), {"L_UPPERARM": (0, -90, 0)})
    r = breakage_report(bad, s.bones.joints, pj)
    assert len(r.components) == 1  # what the old verdict looked at
    assert not r.healthy and r.verdict.startswith("STUMP left behind near L_SHOULDER")
    st = r.stumps[0]
    assert (st.attached, st.lies_along, st.joint) == ("SPINE", "L_UPPERARM", "L_SHOULDER")
    moved = shoulder_on_torso(s, conn, radius=12.0).bone != conn.bone
    assert moved.sum() / 4 < st.points <= moved.sum()  # those moved onto the torso, less the ones at the joint
    assert np.linalg.norm(st.posed.mean(0) - s.bones.joints["L_SHOULDER"]) < 12  # where the pose left them
    assert "stump near L_SHOULDER" in "\n".join(r.lines())


def test_an_owned_body_is_not_judged_by_its_points_attachments(man):
    """#84: the owned body moves by its ownership. Shoulder points on the torso changed 65 of its voxels' owners,
    the raised arm came out whole (as the right attachments give it), and the report still said "STUMP left
    behind near L_SHOULDER: 27 points of SPINE" from the points. The same mistake on the spheres is a stump."""
    from volanim_core.rig.ownership import ownership

    s, conn = man
    bad = shoulder_on_torso(s, conn, radius=12.0)
    owned = bad.with_ownership(ownership(s.mask, bad))
    right = conn.with_ownership(ownership(s.mask, conn))
    assert (owned.ownership.labels != right.ownership.labels).sum() < 100
    t, pj = frame(s, owned, {"L_UPPERARM": (0, -90, 0)})
    r = breakage_report(t, s.bones.joints, pj)
    assert r.stumps == [] and r.healthy and len(r.components) == 1, r.verdict
    good, _ = frame(s, right, {"L_UPPERARM": (0, -90, 0)})
    assert abs(r.posed_voxels - breakage_report(good, s.bones.joints, pj).posed_voxels) < 100  # the same body
    spheres, _ = frame(s, bad, {"L_UPPERARM": (0, -90, 0)})
    assert breakage_report(spheres, s.bones.joints, pj).verdict.startswith("STUMP left behind near L_SHOULDER")


@pytest.mark.parametrize("rotations", [{"L_UPPERARM": (0, -90, 0)}, {"L_FOREARM": (90, 0, 0)},
                                       {"L_THIGH": (90, 0, 0), "R_SHIN": (-90, 0, 0)}, {"SPINE": (0, 0, 45)},
                                       {"HEAD": (30, 0, 60), "R_UPPERARM": (0, 90, 0), "R_FOREARM": (0, 0, 90)}])
def test_correct_connectivity_has_no_stump_in_any_pose(man, rotations):
    s, conn = man
    t, pj = frame(s, conn, rotations)
    assert stumps(t, s.bones.joints) == []


def test_misplaced_points_ignore_points_near_a_joint():
    """A point as close to both bones (within its radius) is never counted as lying along the other."""
    bones = [BoneSegment([0, 0, 0], [10, 0, 0], "A"), BoneSegment([10, 0, 0], [20, 0, 0], "B")]
    pts = np.array([[9.0, 1, 0], [15.0, 1, 0], [18.0, 0, 0]])
    conn = Connectivity(bones, pts, np.array([2.0, 2.0, 2.0]), None, np.array([0, 0, 1]))
    idx, along = misplaced_points(conn)
    assert idx.tolist() == [1] and along.tolist() == [1]  # 5 closer to B than to A, radius 2


def test_components_counts_pieces():
    v = np.zeros((10, 10, 10), np.uint8)
    v[1:3, 1:3, 1:3] = 1
    v[6:9, 6:9, 6:9] = 2
    v[3, 3, 3] = 1  # touches the first block by a corner: 26-connected
    assert components(v) == [27, 9]


def test_local_motion_inverts_fk_and_scaled_preview(man):
    s, _ = man
    rot = {"L_UPPERARM": (10, -45, 5), "R_THIGH": (30, 0, 0)}
    m = pose_matrices(s.bones, rot, {"SPINE": (0, 2, 0)})
    angles, shifts = local_motion(s.bones, m)
    assert np.allclose(pose_matrices(s.bones, angles, shifts), m, atol=1e-9)
    p = np.array([100.0, 50.0, 200.0, 1.0])
    assert np.allclose(p @ scaled(m, 2.0), (p @ m) * [0.5, 0.5, 0.5, 1.0])


def test_pieces_and_where_they_broke_off_match_a_brute_force_answer():
    """Sizes largest first (ties in scan order); the main body's centroid; each other piece's voxel
    nearest to the main body (ties: the first in x-fastest order) -- against scipy + all pairs."""
    from scipy import ndimage

    from volanim_core.reconstruct.breakage import _components

    rng = np.random.default_rng(5)
    vol = (ndimage.gaussian_filter(rng.random((30, 24, 20)), 1.5) > 0.56).astype(np.uint8) * 3
    vol[3:25, 10:13, 8:11] = 7  # one clear main body
    zyx = vol.T
    labels, n = ndimage.label(zyx > 0, structure=np.ones((3, 3, 3), bool))
    assert n > 3
    sizes = np.bincount(labels.ravel())[1:]
    order = np.argsort(-sizes, kind="stable")
    main = order[0] + 1
    body = np.argwhere(labels == main)
    want = [(int(sizes[order[0]]), body.mean(0)[::-1])]
    for k in order[1:] + 1:
        piece = np.argwhere(labels == k)  # C order of [z, y, x]: x fastest
        d2 = ((piece[:, None, :] - body[None, :, :]) ** 2).sum(-1).min(1)
        want.append((int(sizes[k - 1]), piece[int(np.argmin(d2))][::-1].astype(float)))
    got, runs = _components(vol)
    assert [s for s, _, _ in got] == [s for s, _ in want]
    for (_, a, _), (_, b) in zip(got, want):
        assert np.allclose(a, b)
    assert [k for _, _, k in got] == [int(k) for k in order + 1]  # numbered as scipy numbers them
    from volanim_core.reconstruct.breakage import pieces_at

    probe = np.argwhere(np.ones(vol.shape, bool))[::7]  # filled and empty voxels, and their pieces
    assert np.array_equal(pieces_at(runs, vol, probe), labels.T[tuple(probe.T)])


def test_a_piece_far_from_the_main_body_is_located_where_it_is_nearest():
    """The search box around a piece grows until it holds a main-body voxel closer than its margin:
    a piece 30 voxels away, off-axis, still gets its nearest voxel, not the first one found."""
    from volanim_core.reconstruct.breakage import _components

    vol = np.zeros((60, 50, 40), np.uint8)
    vol[2:20, 2:20, 2:20] = 1  # the main body
    vol[45:50, 30:33, 25:27] = 1  # a piece far off, nearest to the body's corner (19, 19, 19)
    vol[6, 28, 3] = 1  # and a one-voxel piece 8 beyond the body's y face
    got = _components(vol)[0]
    assert [n for n, _, _ in got] == [18**3, 30, 1]
    assert np.allclose(got[1][1], (45, 30, 25)) and np.allclose(got[2][1], (6, 28, 3))


def test_rest_voxels_kept_by_the_caller_give_the_same_report(man):
    from volanim_core.reconstruct.breakage import lost_voxels, rest_voxels
    from volanim_core.reconstruct.engine import reconstruct
    from volanim_core.rig.tskel_tools import identity_tskel

    s, conn = man
    m = pose_matrices(s.bones, {"L_UPPERARM": (0, -60, 0)})
    posed = connect_to_tskel(conn, Trans(root_bones(s.bones), m))
    rest = reconstruct(identity_tskel(conn), mode="bone")
    vol = reconstruct(posed, mode="bone")
    kept = rest_voxels(rest)
    assert len(kept[0]) == rest.stats["filled"] and kept[1].min() >= 0
    assert (np.diff(kept[1]) >= 0).all()  # grouped by bone: moved a slice per bone
    a, b = lost_voxels(rest, vol, posed.matrices), lost_voxels(rest, vol, posed.matrices, kept)
    assert len(a) > 0 and np.array_equal(np.sort(a, axis=0), np.sort(b, axis=0))



def test_rest_voxels_of_a_volume_in_any_memory_order():
    """A Reconstruction built by hand may hold an x-slowest (C-ordered [x, y, z]) array: the same
    voxels, grouped by bone, in x-fastest order within each."""
    from volanim_core.reconstruct.breakage import rest_voxels
    from volanim_core.reconstruct.engine import Reconstruction

    vol = np.zeros((5, 4, 3), np.uint8)
    vol[1, 2, 0] = 2
    vol[4, 0, 2] = 1
    vol[0, 3, 1] = 2
    for v in (vol, np.asfortranarray(vol)):
        points, bone = rest_voxels(Reconstruction(v, (10, 20, 30)))
        assert points.tolist() == [[14, 20, 32], [11, 22, 30], [10, 23, 31]] and bone.tolist() == [0, 1, 1]


def test_misplaced_points_are_part_of_the_limbs_flesh():
    """A torso point on the flank beside a hanging arm, a gap between them, lies nearer the arm's segment
    than the spine's but is no piece of the arm: it is not misplaced (mannequin-large's torso flank read as
    a 4-point stump at every shoulder angle). Torso points in the arm's flesh are, and so are those linked
    to them through each other, though their own spheres do not reach the arm's (a stump's far end)."""
    bones = [BoneSegment([0, 0, 0], [0, 0, 100], "SPINE"), BoneSegment([30, 0, 90], [30, 0, 40], "ARM")]
    torso = np.column_stack([np.zeros(101), np.zeros(101), np.arange(101)])
    arm = np.column_stack([np.full(51, 30), np.zeros(51), np.arange(40, 91)])
    flank = np.array([[17, 0, 45]])  # 13 from the arm's segment, 17 from the spine's; the arm's spheres 5 thick
    line = np.column_stack([np.full(11, 22), np.zeros(11), np.arange(55, 66)])  # 8 from the arm: a gap of 1
    touching = np.array([[24, 0, 60]])  # 6 from the arm: its sphere (2) reaches the arm's (5)
    points = np.vstack([torso, arm, flank, line, touching]).astype(float)
    dt = np.r_[np.full(101, 16.0), np.full(51, 5.0), 1.0, np.full(11, 2.0), 2.0]
    bone = np.r_[np.zeros(101, int), np.ones(51, int), np.zeros(13, int)]
    idx, along = misplaced_points(Connectivity(bones, points, dt, None, bone))
    assert sorted(idx.tolist()) == list(range(153, 165)) and set(along.tolist()) == {1}


def test_points_far_from_every_bone_lie_along_none():
    """The frog's foot webbing lies 51-57 voxels from every segment of its leg, 1 voxel nearer the upper
    arm's than the foot's: nearer by more than its radius, and touching a stray arm point, it was read as a
    21-point stump of the foot along the arm whenever the foot bent. Nearer by 5 % is along neither bone;
    a point 10 times nearer the arm's segment than its own still is a stump."""
    bones = [BoneSegment([0, 0, 0], [0, 40, 0], "FOOT"), BoneSegment([20, 0, 0], [60, 0, 0], "ARM")]
    web = [42.0, 40, 0]  # 42 from the foot's segment, 40 from the arm's
    stray = [42.0, 38, 0]  # an arm point beside it (nearer the arm's segment): the web touches the arm's flesh
    stump = [40.0, 4, 0]  # a foot point 4 from the arm's segment, 40 from the foot's
    arm = [40.0, 0, 0]
    points = np.array([web, stray, stump, arm])
    conn = Connectivity(bones, points, np.array([1.0, 1.0, 1.0, 3.0]), None, np.array([0, 1, 0, 1]))
    idx, along = misplaced_points(conn)
    assert idx.tolist() == [2] and along.tolist() == [1]


def thinned_pair(*middle):
    """Two spheres of different bones, overlapping at rest, on a medial sheet (smooth joints; the skin made
    by hand): LOWER moves 3 voxels away, the link between them stretches 2x, both thin to THIN_FLOOR and
    part; ``middle``: spheres of UPPER in between, on no sheet."""
    from volanim_core.rig.connectivity import Tskel
    from volanim_core.rig.skinning import Joints, Skin

    points = np.array([[10, 20, 20], [13, 20, 20], *middle])
    bone = np.array([0, 1] + [0] * len(middle))
    bones = [BoneSegment((0, 20, 20), (12, 20, 20), "UPPER"), BoneSegment((12, 20, 20), (30, 20, 20), "LOWER")]
    skin = Skin(np.zeros(0, np.int64), np.zeros((0, 4), np.int64), np.zeros((0, 4)),
                np.array([0, 1]), np.array([[0, 1]]), np.array([3.0]))
    mats = np.stack([np.eye(4)] * 2)
    mats[1, 3, 0] = 3.0
    return Tskel(bones, mats, points, np.full(len(points), 3.0), None, bone, joints=Joints("smooth"), skin=skin)


def test_spheres_parted_by_thinning_are_a_crack_unless_something_fills_the_gap():
    """A stretched sheet's spheres thin (rig/skinning.posed_radii): two that part only because they thinned
    open a crack when nothing lies between them, and none when a sphere fills the gap. With the rest radii
    (6 voxels apart, radii 3 + 3) neither was a crack."""
    from volanim_core.reconstruct.cracks import cracks

    where, gaps = cracks(thinned_pair())
    np.testing.assert_allclose(gaps, [6.0 - 2 * 0.75 * 3.0])
    np.testing.assert_allclose(where, [[11.5, 20, 20]])
    assert len(cracks(thinned_pair([12, 21, 20]))[1]) == 0
    assert len(cracks(thinned_pair([12, 29, 20]))[1]) == 1  # a sphere beside the gap, not in it
