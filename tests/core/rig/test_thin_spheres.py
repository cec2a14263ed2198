"""One-voxel spheres under smooth joints (rig/thin_spheres.py): specks and surface points move as the
sphere that holds them, a thin sheet keeps its own smooth weights."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from leaf_bends import leaf_bends
from volanim_core import samples
from volanim_core.reconstruct.breakage import components
from volanim_core.reconstruct.checks import report
from volanim_core.reconstruct.engine import reconstruct
from volanim_core.rig.attach import connect
from volanim_core.rig.autorig import autorig
from volanim_core.rig.connectivity import BoneSegment, Connectivity, Trans
from volanim_core.rig.curve_skeleton import balls
from volanim_core.rig.pose import bend_across, pose_matrices, root_bones
from volanim_core.rig.skinning import Joints, skin_weights
from volanim_core.rig.thin_spheres import holder
from volanim_core.skeleton.skeletonize import skeletonize

SMOOTH = Joints("smooth")


# full tier only, so that make test stays under 10 minutes: the 46 M-voxel sample skeletonized, proposed,
# connected and each leaf bent
@pytest.mark.slow
def test_mannequin_large_bends_every_leaf_90_degrees_with_smooth_joints():
    """A one-voxel sphere at the ankle's surface, its centre just inside a shin sphere of radius 10, was
    linked only to spheres a radius away: the foot's reach along the body stopped one link short of it, so
    it stayed rigid on the shin while the flesh holding it turned a quarter of the foot's 90 degrees, and
    the bend tore it off."""
    s = samples.mannequin_large()
    skel = skeletonize(s.mask)
    assert leaf_bends(skel, autorig(skel).bones, (90,), "smooth") == []


# full tier only, so that make test stays under 10 minutes: the frog skeletonized, proposed, connected and one leg
# bent
@pytest.mark.slow
def test_the_frogs_thin_sheets_keep_their_own_weights():
    """The frog's tissue is thin in places: a sheet of 120 one-voxel spheres with a few of radius 2 in it.
    Each sheet point given the weights of the radius-2 sphere that held it best (weights 0.44 and 0.86 a
    voxel apart) tore the sheet at the front leg's tip bent 90 degrees; a group that spreads beyond one
    sphere keeps its smooth weights."""
    s = samples.frog()
    skel = skeletonize(s.mask)
    bones = autorig(skel).bones
    conn = connect(skel, bones, method="pieces", mask=balls(skel))[0].with_joints(SMOOTH)
    trans = Trans(root_bones(bones), pose_matrices(bones, {"ANT_3": bend_across(bones, "ANT_3", 90)}))
    assert report(conn, trans, bones=bones).healthy


def rod_with_a_speck(speck: np.ndarray) -> Connectivity:
    """A rod of radius 4 along x (two bones meeting at x = 30, one medial point per voxel) and one-voxel
    spheres ``speck`` on LOWER, linked to nothing of the rod (more than 4 voxels from its centres)."""
    x = np.arange(5, 65)
    rod = np.column_stack([x, np.full_like(x, 20), np.full_like(x, 20)])
    bones = [BoneSegment((5, 20, 20), (30, 20, 20), "UPPER"), BoneSegment((30, 20, 20), (65, 20, 20), "LOWER")]
    return Connectivity(bones, np.vstack([rod, speck]), np.r_[np.full(len(x), 4.0), np.ones(len(speck))], None,
                        np.r_[(x >= 30).astype(int), np.ones(len(speck), int)], joints=SMOOTH)


def test_a_speck_group_moves_as_one():
    """A line of linked one-voxel spheres along the rod's surface across the joint: each used to take the
    weights of the sphere it lay deepest in, different along the line, so a bend stretched the group
    apart. Now the group takes the weights of the one sphere that holds it best, and keeps its shape."""
    speck = np.column_stack([np.arange(25, 36), np.full(11, 24), np.full(11, 22)])  # 4.5 from the axis
    conn = rod_with_a_speck(speck)
    skin = skin_weights(conn.points, conn.dt, conn.bone, conn.bones, SMOOTH)
    at = {int(k): r for r, k in enumerate(skin.index)}
    rows = [at[k] for k in range(60, 71)]
    assert len(rows) == 11
    for r in rows[1:]:
        np.testing.assert_array_equal(skin.influence[r], skin.influence[rows[0]])
        np.testing.assert_allclose(skin.weight[r], skin.weight[rows[0]])
    # the host is the rod sphere whose surface is nearest one of the group's points, and it is blended
    host, gap = holder(conn.points[:60], conn.dt[:60], speck.astype(float))
    assert gap.min() < 1.0 and skin.weight[rows[0]][0] < 1.0
    joint = np.array([30.0, 20.0, 20.0])
    for angle in (45, 90):
        m = np.eye(4)
        m[:3, :3] = Rotation.from_euler("z", angle, degrees=True).as_matrix().T
        m[3, :3] = joint - joint @ m[:3, :3]
        posed = conn.posed(np.stack([np.eye(4), m]))
        assert len(components(reconstruct(posed, mode="binary", padding=1).volume)) == 1


def test_bones_are_as_many_joints_apart_as_the_chain_between_them():
    from volanim_core.rig.skinning import bone_hops

    chain = [BoneSegment((0, 0, 0), (10, 0, 0)), BoneSegment((10, 0, 0), (20, 0, 0)),
             BoneSegment((20, 0, 0), (30, 0, 0)), BoneSegment((10, 0, 0), (10, 10, 0)),  # a sibling of 1
             BoneSegment((50, 0, 0), (60, 0, 0))]  # apart from all
    hops = bone_hops(chain)
    np.testing.assert_array_equal(hops[0, :4], [0, 1, 2, 1])
    np.testing.assert_array_equal(hops[2, :4], [2, 1, 0, 2])
    assert hops[4, :4].min() > 2 and hops[4, 4] == 0


def test_every_leaf_of_the_rabbit_bends_90_degrees_with_smooth_joints(tmp_path):
    """The rabbit's ear curls back and its tip rests on the ear's root, four bones along the chain: the two
    were blended where they touch, and the tip bent 90 degrees tore two 30-voxel pieces out of the fold.
    A bone now blends only with bones at most two joints away. And a six-point speck at the hip, its points
    each given the weights of a different sphere, tore itself apart: a speck group now moves as one."""
    from volanim_core.io.mesh_files import read_mesh, voxelize

    samples.write_sample("rabbit", tmp_path)
    vol, _ = voxelize(read_mesh(tmp_path / "rabbit.ply"), size=160)
    skel = skeletonize(vol > 0)
    assert leaf_bends(skel, autorig(skel).bones, (90,), "smooth") == []
