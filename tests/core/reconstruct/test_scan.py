"""Scanning an animation for breakage: a whole frame is healthy, a torn-off forearm ranks first."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core.errors import Cancelled
from volanim_core.reconstruct.scan import scan_frames, worst_first
from volanim_core.rig.bones import Bone, BoneSkeleton
from volanim_core.rig.connectivity import Connectivity
from volanim_core.rig.pose import pose_matrices, root_bones


def arm_connectivity():
    """Spheres of radius 2 every voxel down the upper arm (bone 1) and the forearm (bone 2)."""
    joints = {"PELVIS": (20, 20, 20), "L_SHOULDER": (22, 20, 30), "L_ELBOW": (22, 20, 24), "L_WRIST": (22, 20, 19)}
    bones = BoneSkeleton(joints, [Bone("PELVIS", "L_SHOULDER", "SPINE"), Bone("L_SHOULDER", "L_ELBOW", "L_UPPERARM"),
                                  Bone("L_ELBOW", "L_WRIST", "L_FOREARM")])
    z = np.arange(-1.0, 10.0)
    points = np.column_stack([np.full_like(z, 2.0), np.zeros_like(z), z]) + 20
    bone = np.where(z >= 4, 1, 2)
    return bones, Connectivity(root_bones(bones), points, np.full(len(z), 2.0), np.ones(len(z)), bone)


def test_a_torn_forearm_is_the_worst_frame_and_names_the_elbow():
    bones, conn = arm_connectivity()
    frames = np.stack([pose_matrices(bones), pose_matrices(bones, translations={2: [3.5, 0.0, 0.0]}),
                       pose_matrices(bones, translations={2: [12.0, 0.0, 0.0]})])
    v = scan_frames(conn, frames, [10, 11, 12], joints=dict(bones.joints))
    assert v[0].healthy and v[0].pieces == 1 and v[0].cracks == 0
    assert v[2].pieces == 2 and v[2].detached > 0 and v[2].cracks > 0 and v[2].worst_joint == "L_ELBOW"
    assert [x.frame for x in worst_first(v)][0] == 12
    assert v[1].pieces == 1 and v[1].cracks > 0  # slid: cracked at the elbow, still one piece
    assert [x.frame for x in worst_first(v)] == [12, 11, 10]


def test_the_scan_reports_progress_and_stops_on_cancel():
    bones, conn = arm_connectivity()
    frames = np.stack([pose_matrices(bones)] * 5)
    seen = []
    scan_frames(conn, frames, progress=lambda d, t: seen.append((d, t)))
    assert seen[0] == (0, 5) and seen[-1] == (5, 5)
    with pytest.raises(Cancelled):
        scan_frames(conn, frames, cancel=lambda: True)


def speckled_arm():
    """The arm, and a speck of its own attached to the spine: two pieces at rest (as the frog's scan has
    6,069 specks of tissue), which no pose should be blamed for."""
    bones, conn = arm_connectivity()
    points = np.vstack([conn.points, [[40.0, 40.0, 40.0]]])
    return bones, Connectivity(conn.bones, points, np.append(conn.dt, 1.5), np.append(conn.thinness, 1.0),
                               np.append(conn.bone, 0))


def test_pieces_apart_at_rest_are_not_breakage_a_torn_forearm_still_is():
    """Before: the unposed frog was "BROKEN into 6069 pieces", every speck of it counted as breakage."""
    from volanim_core.reconstruct.breakage import breakage_report
    from volanim_core.rig.connectivity import Trans
    from volanim_core.rig.pose import posed_joints
    from volanim_core.rig.tskel_tools import connect_to_tskel

    bones, conn = speckled_arm()
    rest, torn = pose_matrices(bones), pose_matrices(bones, translations={2: [12.0, 0.0, 0.0]})
    v = scan_frames(conn, np.stack([rest, torn]), joints=dict(bones.joints))
    assert v[0].pieces == 2 and v[0].rest_pieces == 2 and v[0].healthy
    assert v[1].pieces == 3 and not v[1].healthy and [x.frame for x in worst_first(v)] == [1, 0]
    joints = dict(bones.joints)
    r = breakage_report(connect_to_tskel(conn, Trans(root_bones(bones), rest)), joints, joints)
    assert r.healthy and len(r.components) == 2 and r.rest_pieces == 2 and not r.pieces
    assert r.verdict == "healthy: nothing torn off (the rest pose too is 2 pieces), no stump"
    r = breakage_report(connect_to_tskel(conn, Trans(root_bones(bones), torn)), joints, posed_joints(bones, torn))
    assert not r.healthy and len(r.pieces) == 1 and r.verdict.startswith("BROKEN: the pose tore off 1 piece (near ")
    assert r.pieces[0][0] < r.components[0]  # the forearm, not the speck or the upper arm
