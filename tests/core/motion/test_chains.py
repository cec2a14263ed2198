"""#86 item 2: a clip of its kind onto a creature's auto-rig, matched chain to chain (motion/chains.py).

Spot the cow (Keenan Crane, CC0) voxelized at 160 and auto-rigged gets chains named by where they lie
(``ANT3_1``); the quadruped clips are the 3ds Max biped-rigged elephant of test_clip_kind and Khronos'
Fox's real Walk (CC BY 4.0), which also drives the fox's own auto-rig. The truth the matching is checked
against is the clip's own forward kinematics, computed by the clip's reader, not by the retargeting."""

from __future__ import annotations

import numpy as np
import pytest
from tests.paths import FOX, WALK

from volanim_core.cli import main
from volanim_core.io.bvh_files import read_bvh
from volanim_core.io.clip_files import read_clip
from volanim_core.motion.chains import match_chains, rig_figure
from volanim_core.motion.kind import rig_kind
from volanim_core.motion.plausible import check_clip
from volanim_core.motion.retarget import Retarget
from written_clips import elephant_bvh, insect_bvh


@pytest.fixture(scope="module")
def spot(tmp_path_factory):
    from volanim_core import samples
    from volanim_core.io.bones_files import write_bones
    from volanim_core.io.mesh_files import read_mesh, voxelize
    from volanim_core.rig.autorig import autorig
    from volanim_core.skeleton.skeletonize import skeletonize

    folder = tmp_path_factory.mktemp("spot")
    samples.write_sample("spot", folder)
    vol, _ = voxelize(read_mesh(folder / "spot.ply"), size=160)
    bones = autorig(skeletonize(vol > 0)).bones
    write_bones(folder / "spot.bones", bones)
    elephant_bvh(folder / "elephant.bvh")
    return folder, bones


def test_spot_reads_as_a_quadruped_by_its_shape_though_no_bone_names_a_part(spot):
    _, bones = spot
    assert not any("THIGH" in b.label or "FEMUR" in b.label for b in bones.bones)
    assert rig_kind(bones, by_shape=False) is None and rig_kind(bones) == "quadruped"
    fig = rig_figure(bones)
    assert len(fig.legs) == 2 and fig.head and nearest(fig.up) == "y"  # Spot's mesh stands in y


def nearest(v) -> str:
    k = int(np.argmax(np.abs(v)))
    return ("-" if v[k] < 0 else "") + "xyz"[k]


def test_each_leg_of_spot_follows_the_elephant_s_leg_of_the_same_pair_and_side(spot):
    """Each of Spot's leg bones is driven by a joint of the elephant's leg of the same pair (hind, front)
    and side, below its clavicle; and as the elephant's left hind foot swings forward and back, Spot's does
    the same way (the clip's own FK against our posed joints, along each figure's forward)."""
    folder, bones = spot
    motion = read_bvh(folder / "elephant.bvh")
    found, why = match_chains(bones, motion)
    assert found is not None, why
    rig = found.rig
    for pair, limb in zip(rig.legs, ("Thigh|Calf|HorseLink|Foot", "UpperArm|Forearm|Hand")):
        for side, path in pair.items():
            for n in path[1:]:
                joint = found.mapping[next(b.label for b in bones.bones if b.distal == found.rig.names[n])]
                assert joint.startswith(f"Bip01_{side}_") and joint.split("_")[-1] in limb.split("|"), (side, joint)
    retarget = Retarget.build(bones, motion)
    mats = retarget.matrices()
    foot = found.rig.names[rig.legs[0]["L"][-1]]
    ours = bones.joints[foot] @ mats[:, _bone_ending(bones, foot), :3, :3] + mats[:, _bone_ending(bones, foot), 3, :3]
    _, pos = motion.forward_kinematics(slice(None))
    theirs = pos[:, motion.index("Bip01_L_Foot")] - pos[:, motion.index("Bip01")]  # the foot from the body
    root = bones.joints[found.rig.names[rig.spine[0]]] @ mats[:, 0, :3, :3] + mats[:, 0, 3, :3]
    along_ours = (ours - root) @ rig.forward
    along_theirs = theirs @ np.array([0.0, 0.0, 1.0])  # the elephant faces +z
    assert np.corrcoef(along_ours, along_theirs)[0, 1] > 0.95


def _bone_ending(bones, joint: str) -> int:
    return next(k for k, b in enumerate(bones.bones) if b.distal == joint)


def test_bvh2trans_walks_spot_with_the_elephant_and_every_check_holds(spot, tmp_path, capsys):
    folder, _ = spot
    assert main(["bvh2trans", str(folder / "elephant.bvh"), "--bones", str(folder / "spot.bones"),
                 "-o", str(tmp_path / "frames")]) == 0
    out = capsys.readouterr().out
    assert "# naming scheme: chains (quadruped)" in out
    assert "the clip's figure is a quadruped, as the rig: yes" in out
    assert "feet near the floor: 100%" in out and "feet below the body: 100%" in out
    assert "chain: hind L leg, 1 of 2" in out
    assert len(list((tmp_path / "frames").glob("*.trans"))) == 48


@pytest.fixture(scope="module")
def fox():
    """Khronos' Fox (CC BY 4.0): its own skinned surface at rest, filled at 160 and auto-rigged."""
    from volanim_core.io.mesh_files import read_mesh, voxelize
    from volanim_core.rig.autorig import autorig
    from volanim_core.skeleton.skeletonize import skeletonize

    vol, _ = voxelize(read_mesh(FOX), size=160)
    return autorig(skeletonize(vol > 0)).bones


@pytest.mark.parametrize("body", ["fox", "spot"])
def test_a_real_fox_s_walk_drives_each_leg_by_the_fox_s_leg_of_the_same_pair_and_side(body, request):
    """The Fox's Walk onto the fox's own auto-rig and onto Spot: each leg bone follows a joint of the fox's
    leg of the same pair and side (hind legs ``b_LeftLeg01`` .. ``b_LeftFoot02``, front legs ``b_LeftUpperArm``
    .. ``b_LeftHand``), the head the neck, the tail the tail; and as the fox's left hind foot swings forward
    and back, the rig's does the same way (the clip's own forward kinematics against our posed joints).
    The fox's tail starts higher than its neck, and its head was read as its tail: hind legs walked by front
    ones, left by right, every plausibility check still passing."""
    bones = request.getfixturevalue(body)
    bones = bones[1] if isinstance(bones, tuple) else bones
    motion = read_clip(FOX, "Walk")
    found, why = match_chains(bones, motion)
    assert found is not None, why
    rig = found.rig
    driver = {b.distal: found.mapping.get(b.label) for b in bones.bones}
    for pair, fork, limb in zip(rig.legs, ("b_Hip_01", "b_Spine02_03"), (("Leg", "Foot"), ("Arm", "Hand"))):
        for side, path in pair.items():
            if driver[rig.names[path[1]]] == fork:
                path = path[1:]  # a pelvis or scapula bone before the leg turns with the body: the fox has none
            for n in path[1:]:
                joint = driver[rig.names[n]]
                assert joint.startswith(f"b_{'Left' if side == 'L' else 'Right'}"), (side, rig.names[n], joint)
                assert any(part in joint for part in limb), (side, rig.names[n], joint)
    # the head and the tail from their own ends (a first step from the body turns with it)
    assert {driver[rig.names[n]].split("_")[1] for n in rig.tail[1:]} <= {"Hip", "Tail01", "Tail02", "Tail03"}
    assert {driver[rig.names[n]].split("_")[1] for n in rig.head[1:]} <= {"Spine02", "Neck", "Head"}
    mats = Retarget.build(bones, motion).matrices()
    foot = rig.names[rig.legs[0]["L"][-1]]
    k = _bone_ending(bones, foot)
    ours = bones.joints[foot] @ mats[:, k, :3, :3] + mats[:, k, 3, :3]
    root = bones.joints[rig.names[rig.spine[0]]] @ mats[:, 0, :3, :3] + mats[:, 0, 3, :3]
    _, pos = motion.forward_kinematics(slice(None))
    theirs = pos[:, motion.index("b_LeftFoot02_018")] - pos[:, motion.index("b_Hip_01")]
    assert np.corrcoef((ours - root) @ rig.forward, theirs @ np.array([0.0, 0.0, 1.0]))[0, 1] > 0.9  # faces +z


def test_a_person_s_walk_is_refused_for_spot_saying_what_each_is(spot, tmp_path, capsys):
    folder, _ = spot
    assert main(["bvh2trans", str(WALK), "--bones", str(folder / "spot.bones"), "-o", str(tmp_path / "f")]) == 2
    err = capsys.readouterr().err
    assert "the clip's figure is a quadruped, as the rig: no (it is a biped" in err
    assert not (tmp_path / "f").exists()


def test_a_creature_keeps_its_build_only_the_clip_s_motion_is_applied(spot):
    """At the clip's rest (the elephant's OFFSET pose: every rotation the identity) Spot stands as rigged:
    a cow's horn is no elephant's head, so nothing is turned onto the clip's rest directions."""
    folder, bones = spot
    motion = read_bvh(folder / "elephant.bvh")
    retarget = Retarget.build(bones, motion)
    assert all(v == 0.0 for v in retarget.absorbed_degrees().values())
    checks, _ = check_clip(retarget)
    assert all(c.ok for c in checks) and {c.name for c in checks} >= {"feet near the floor", "feet below the body"}




@pytest.fixture(scope="module")
def ant(tmp_path_factory):
    folder = tmp_path_factory.mktemp("ant")
    assert main(["samples", "ant", "-o", str(folder)]) == 0
    assert main(["voxelize", str(folder / "ant.ply"), str(folder / "ant.nrrd"), "--size", "160"]) == 0
    assert main(["markups", str(folder / "ant.mrk.json"), "--like", str(folder / "ant.nrrd"),
                 "-o", str(folder / "ant.bones")]) == 0
    insect_bvh(folder / "insect.bvh")
    return folder


def test_the_ant_walks_an_insect_s_tripod_each_leg_with_its_twin_of_the_clip(ant, tmp_path, capsys):
    """The ant's six legs leave its thorax at one point; they are ordered front to hind by where their hips
    lie along the body, left by up x forward. Each leg of the ant is driven by the clip's leg of the same
    place and side (the step from the thorax to the hip may turn with the clip's thorax, as the clip's own
    does), and the ant's front left foot swings as the insect's does (the clip's own FK)."""
    from volanim_core.io import read_bones

    bones = read_bones(ant / "ant.bones")
    motion = read_bvh(ant / "insect.bvh")
    assert rig_kind(bones) == "many-legged"
    found, why = match_chains(bones, motion)
    assert found is not None, why
    for k, pair in enumerate(found.rig.legs):
        number = 3 - k  # hind first: the ant's and the insect's legs are numbered 1 front .. 3 hind
        for side, path in pair.items():
            for n in path[1:]:
                bone = next(b for b in bones.bones if b.distal == found.rig.names[n])
                assert bone.distal.startswith(f"{side}_") and bone.distal.endswith(str(number))  # the ant's joints
                joint = found.mapping[bone.label]
                if n == path[1] and joint == "Thorax":  # the step leaving the body turns with the body, in both
                    continue
                assert joint.startswith(side) and joint.endswith(str(number)), (bone.label, joint)
    retarget = Retarget.build(bones, motion)
    mats = retarget.matrices()
    foot = _bone_ending(bones, "L_FOOT1")
    ours = bones.joints["L_FOOT1"] @ mats[:, foot, :3, :3] + mats[:, foot, 3, :3]
    thorax = bones.joints["THORAX"] @ mats[:, 0, :3, :3] + mats[:, 0, 3, :3]
    _, pos = motion.forward_kinematics(slice(None))
    theirs = pos[:, motion.index("LTarsus1")] - pos[:, 0]
    assert np.corrcoef((ours - thorax) @ found.rig.forward, theirs[:, 2])[0, 1] > 0.95
    assert main(["bvh2trans", str(ant / "insect.bvh"), "--bones", str(ant / "ant.bones"),
                 "-o", str(tmp_path / "f")]) == 0
    out = capsys.readouterr().out
    assert "# the clip's figure: many-legged: 3 pairs of legs" in out
    assert "the clip's figure is a many-legged, as the rig: yes" in out and "feet below the body: 100%" in out


def test_axes_given_as_the_figure_reads_them_change_nothing_and_a_reversed_forward_walks_backwards(spot):
    folder, bones = spot
    motion = read_bvh(folder / "elephant.bvh")
    auto = Retarget.build(bones, motion)
    assert (auto.up, auto.forward) == ("y", "z")
    assert np.allclose(Retarget.build(bones, motion, up="y", forward="z").matrices(), auto.matrices())
    back = Retarget.build(bones, motion, up="y", forward="-z")
    travel = lambda r: r.matrices()[-1, 0, 3, :3] - r.matrices()[0, 0, 3, :3]  # noqa: E731
    fwd = auto.report["figure"].forward
    assert travel(auto) @ fwd > 0 > travel(back) @ fwd  # the elephant walks +z: Spot walks its own forward


def test_a_tail_as_long_as_the_legs_at_the_point_they_all_leave_is_no_leg():
    """trimesh's rabbit auto-rigged: four legs and the tail leave one point, the tail as long as a leg and
    two segments like them; the tail made a pair with a hind leg, the figure read a quadruped with a tail
    for a leg and up tilted 45 degrees. Pairs must be mirror images across one plane: the rabbit is not read
    (it was not before either), and the same figure with the tail shorter reads with its legs right."""
    from volanim_core.motion.chains import read_figure

    def figure(tail):
        pts = [(0, 0, 10)]  # the point everything leaves (y forward, z up)
        parent = [-1]
        for x, y in ((4, 5), (-4, 5), (4, -5), (-4, -5)):  # legs: out, then down
            pts += [(x, y, 6), (x + 1, y, 0)]
            parent += [0, len(pts) - 2]
        pts += [(0, -4, 8), (0, -4 - tail, 8 - tail)]  # the tail, back and down
        parent += [0, len(pts) - 2]
        pts += [(0, 6, 12), (0, 9, 14)]  # the head, forward and up
        parent += [0, len(pts) - 2]
        return read_figure(np.array(pts, float), np.array(parent))

    fig = figure(tail=3.0)
    assert fig.kind == "quadruped" and fig.reason.startswith("2 pairs of legs")
    assert nearest(fig.up) == "z" and nearest(fig.forward) == "y"
    assert {fig.points[p[-1]][0] > 0 for p in (fig.legs[0]["L"], fig.legs[1]["L"])} == {False}  # left: -x
    assert fig.points[fig.tail[-1]][1] < 0 < fig.points[fig.head[-1]][1]
    long_tail = figure(tail=6.0)  # as long as a leg, two segments like one: still no leg
    tail_end = len(long_tail.points) - 3
    assert long_tail.kind == "quadruped" and all(p[-1] != tail_end for pair in long_tail.legs for p in pair.values())
    # the rabbit's pairing, the tail with a hind leg beside the other pair: no mirror images across one plane
    from volanim_core.motion.chains import _mirrored

    legs = {name: [0, k, k + 1] for name, k in (("fl", 1), ("fr", 3), ("hl", 5), ("hr", 7))}
    tail = [0, 9, 10]
    assert _mirrored(long_tail.points, [(legs["fl"], legs["fr"]), (legs["hl"], legs["hr"])])
    assert not _mirrored(long_tail.points, [(legs["fl"], legs["fr"]), (legs["hl"], tail)])



@pytest.mark.parametrize("apart", [2, 3])  # a lone bone (a path of two points), a chain of two bones
def test_bones_apart_from_the_body_leave_its_figure_read(spot, apart):
    """Review: a rig may be a forest (a bone starting at a joint no bone ends at begins a tree of its own).
    A lone bone beside Spot made ``_end_chains`` give up on the whole figure ("the tree does not fork") and
    a path asked between two trees raised KeyError: bvh2trans would have refused or crashed on Spot."""
    from volanim_core.rig.bones import Bone, BoneSkeleton

    folder, bones = spot
    joints = dict(bones.joints)
    joints.update({f"APART_{k}": np.array([200.0 + 10 * k, 0.0, 0.0]) for k in range(apart)})
    extra = [Bone(f"APART_{k}", f"APART_{k + 1}") for k in range(apart - 1)]
    forest = BoneSkeleton(joints, bones.bones + extra, bones.geometry)
    assert rig_kind(forest) == "quadruped"
    found, why = match_chains(forest, read_bvh(folder / "elephant.bvh"))
    assert found is not None, why
    assert found.mapping == match_chains(bones, read_bvh(folder / "elephant.bvh"))[0].mapping


@pytest.mark.parametrize("size", [160, 320])
def test_the_ant_auto_rigged_at_160_or_320_voxels_reads_as_six_legs_each_with_its_twin_across(size, tmp_path):
    """#86: an auto-rig must not depend on the voxel size. At 320 voxels along its longest side the ant's
    proposal bends its front legs 9 and 8 times: twins were asked for as many segments, so each front leg was
    paired with the one beside it and the figure read "not mirror images" (no clip could drive it). Each pair
    now lies across the body (the line its forks lie on), and the insect's tripod drives it with every check
    holding."""
    from volanim_core import samples
    from volanim_core.io.mesh_files import read_mesh, voxelize
    from volanim_core.rig.autorig import autorig
    from volanim_core.skeleton.skeletonize import skeletonize

    samples.write_sample("ant", tmp_path)
    vol, _ = voxelize(read_mesh(tmp_path / "ant.ply"), size=size)
    bones = autorig(skeletonize(vol > 0)).bones
    fig = rig_figure(bones)
    assert (fig.kind, len(fig.legs)) == ("many-legged", 3), fig.reason
    left = np.cross(fig.up, fig.forward)
    for pair in fig.legs:
        across = fig.points[pair["L"][-1]] - fig.points[pair["R"][-1]]
        assert across @ left > 0.9 * np.linalg.norm(across)  # each twin's foot on its own side, straight across
    insect_bvh(tmp_path / "insect.bvh")
    checks, _ = check_clip(Retarget.build(bones, read_bvh(tmp_path / "insect.bvh")))
    assert all(c.ok for c in checks), [(c.name, c.held) for c in checks]
