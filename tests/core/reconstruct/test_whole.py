"""One piece proved from the spheres (whole.py): never said of a frame whose voxels are in pieces, and said
of the walk's frames, so the clip scan needs no voxels for them (#65: `volanim scan` of the walk 22 -> 8 s)."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core import io, samples
from volanim_core.io.bvh_files import read_bvh
from volanim_core.motion.retarget import Retarget
from volanim_core.reconstruct.breakage import components
from volanim_core.reconstruct.engine import reconstruct
from volanim_core.reconstruct.scan import Scanner
from volanim_core.reconstruct.whole import WholeProof
from volanim_core.rig.bones import Bone, BoneSkeleton
from volanim_core.rig.connectivity import Connectivity
from volanim_core.rig.pose import pose_matrices, root_bones
from volanim_core.rig.tskel_tools import coarse_tskel, identity_tskel

ASSETS = __import__("pathlib").Path(__file__).parents[3] / "assets"


def pieces(frame) -> int:
    return len(components(reconstruct(frame, mode="bone", padding=1).volume))


@pytest.fixture(scope="module")
def mannequin():
    conn = io.read_connect(ASSETS / "mannequin.0.50.connect")
    mats = Retarget.build(samples.mannequin_bones(), read_bvh(samples.walk_clip())).matrices()
    return conn, mats


@pytest.mark.parametrize("factor", [1, 2])
def test_what_it_proves_is_one_piece_and_it_proves_the_walk(mannequin, factor):
    """Every 53rd frame of the walk, at the scan's grid and at full size: each proved, each one piece."""
    conn, mats = mannequin
    proof = WholeProof(coarse_tskel(identity_tskel(conn), factor))
    for m in mats[::53]:
        frame = coarse_tskel(conn.posed(m), factor)
        assert proof.proves(frame)
        assert pieces(frame) == 1


def test_a_limb_pulled_off_or_swung_through_the_body_is_never_proved_whole_wrongly(mannequin):
    """Poses that tear (a forearm moved away, step by step past where it parts) and poses that bend hard: where
    it says whole, the voxels are one piece; where the voxels are in pieces it never says whole."""
    conn, _ = mannequin
    bones = samples.mannequin_bones()
    arm = [b.name for b in bones.bones].index("L_FOREARM")
    proof = WholeProof(coarse_tskel(identity_tskel(conn), 2))
    said, broken = [], []
    for shift in np.linspace(0.0, 40.0, 21):  # the forearm slid off the elbow, a voxel of the grid a step
        frame = coarse_tskel(conn.posed(pose_matrices(bones, translations={arm: [shift, 0.0, shift]})), 2)
        said.append(proof.proves(frame))
        broken.append(pieces(frame) > 1)
        assert not (said[-1] and broken[-1])
    for angle in (60.0, 120.0, 170.0):
        frame = coarse_tskel(conn.posed(pose_matrices(bones, {"L_UPPERARM": (0.0, angle, 0.0)})), 2)
        assert not (proof.proves(frame) and pieces(frame) > 1)
    assert said[0] and broken[-1]  # the test spans both: proved at rest, torn at the far end


def chain(gap: float):
    """A big ball and, off its surface, a finger of small spheres (radius 1.2: too small for the pair lemma,
    tested voxel by voxel); ``gap``: how far the finger's first sphere is moved out."""
    joints = {"A": (10, 10, 10), "B": (10, 10, 30)}
    bones = BoneSkeleton(joints, [Bone("A", "B", "BODY")])
    finger = [[10.0, 10.0, 16.0 + gap + k] for k in range(5)]
    points = np.array([[10.0, 10.0, 10.0]] + finger)
    dt = np.array([6.0] + [1.2] * 5)
    return Connectivity(root_bones(bones), points, dt, np.ones(len(dt)), np.zeros(len(dt), np.int32))


@pytest.mark.parametrize("gap", [0.0, 1.0, 2.0, 3.0])
def test_a_finger_of_small_spheres_is_joined_voxel_by_voxel(gap):
    """Touching: proved (the small spheres join one after the other); a gap of empty voxels: not proved, and
    the voxels are indeed two pieces."""
    frame = identity_tskel(chain(gap))
    proved, n = WholeProof(frame).proves(frame), pieces(frame)
    assert not (proved and n > 1)
    assert proved == (n == 1)  # here each answer is exact: both sides of the gap are single runs


def test_the_scan_says_what_the_voxels_say(mannequin):
    """A torn frame among whole ones: the scan's verdicts with the proof equal those counting every frame's
    voxels (a Scanner whose proof is removed)."""
    conn, mats = mannequin
    bones = samples.mannequin_bones()
    arm = [b.name for b in bones.bones].index("L_FOREARM")
    frames = list(mats[::200]) + [pose_matrices(bones, translations={arm: [30.0, 0.0, 0.0]})]
    fast, slow = Scanner(conn, dict(bones.joints)), Scanner(conn, dict(bones.joints))
    slow.whole = None
    got = [fast.verdict(n, m) for n, m in enumerate(frames)]
    assert got == [slow.verdict(n, m) for n, m in enumerate(frames)]
    assert got[-1].pieces > 1 and all(v.pieces == 1 for v in got[:-1])
