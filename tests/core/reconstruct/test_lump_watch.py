"""A clip's scan looks for lumps as the report does (reconstruct/lump_watch.py, #84): `volanim scan` said
"0 broken" over the walk while frame 644's own report listed lumps of 3,199, 1,868 and 1,729 voxels."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core import samples
from volanim_core.io.bvh_files import read_bvh
from volanim_core.motion.retarget import Retarget
from volanim_core.reconstruct.breakage import RestParts, breakage_report
from volanim_core.reconstruct.lump_watch import LumpWatch
from volanim_core.reconstruct.scan import scan_frames, scan_summary, worst_first
from volanim_core.rig.attach import connect
from volanim_core.rig.ownership import ownership
from volanim_core.rig.pose import pose_matrices, posed_joints
from volanim_core.skeleton.skeletonize import skeletonize


@pytest.fixture(scope="module")
def rigs():
    """The default pipeline's points on their nearest bones (the thesis's spheres), and with the scan's ownership."""
    s = samples.mannequin()
    conn = connect(skeletonize(s.mask, min_thinness=0.5), s.bones)[0]
    return s, conn, conn.with_ownership(ownership(s.mask, conn))


def _report(s, conn, m):
    return breakage_report(conn.posed(m), dict(s.bones.joints), posed_joints(s.bones, m), rest=RestParts.of(conn))


def test_the_scan_finds_the_walks_lumps_the_report_lists(rigs):
    s, spheres, _ = rigs
    m = Retarget.build(s.bones, read_bvh(samples.walk_clip())).matrices()[[0, 644]]
    report = _report(s, spheres, m[1])
    assert report.lumps and report.lumps[0].near == "PELVIS"
    v = scan_frames(spheres, m, [0, 644], joints=dict(s.bones.joints))
    assert (v[1].lump, v[1].lump_near) == (report.lumps[0].voxels, "PELVIS")  # the report's own, not an estimate
    assert "2 with lumps" in scan_summary(v)


def test_a_painted_lump_is_found_in_the_frame_that_carries_it_and_only_there(rigs):
    """Owned frames: the armpit painted to the arm (what an animator's wrong repaint does) carries a lump when the
    arm rises, not at rest. The watch reconstructs neither the rest frame nor a frame that carries nothing."""
    s, _, owned = rigs
    own = owned.ownership
    arm = s.bones.index("L_UPPERARM")
    full = own.volume(s.mask.shape)
    box = (slice(96, 108), slice(40, 60), slice(200, 222))
    full[box] = np.where(full[box] != 0, arm + 1, 0)
    lo = np.asarray(own.origin)
    painted = owned.with_ownership(own.with_labels(
        np.asfortranarray(full[tuple(slice(o, o + n) for o, n in zip(lo, own.labels.shape))])))
    rest, raised = np.tile(np.eye(4), (len(s.bones.bones), 1, 1)), pose_matrices(s.bones, {"L_UPPERARM": (0, -90, 0)})
    watch = LumpWatch(painted)
    assert not watch.may_carry(rest) and watch.may_carry(raised)
    assert not LumpWatch(owned).may_carry(raised)  # the ownership as made: the raised arm carries nothing
    report = _report(s, painted, raised)
    v = worst_first(scan_frames(painted, np.stack([rest, raised]), [0, 1], joints=dict(s.bones.joints)))
    assert [(x.frame, x.lump) for x in v] == [(1, report.lumps[0].voxels), (0, 0)]
    assert v[0].lump_near == report.lumps[0].near == "L_SHOULDER"


def test_smooth_joints_are_not_judged(rigs):
    from volanim_core.rig.skinning import Joints

    s, spheres, _ = rigs
    m = pose_matrices(s.bones, {"L_UPPERARM": (0, -90, 0)})[None]
    assert scan_frames(spheres.with_joints(Joints("smooth")), m)[0].lump == 0
