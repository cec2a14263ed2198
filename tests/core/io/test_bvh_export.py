"""trans2bvh: our bones and frames as a BVH clip, read back by another project's parser (``bvh``, 20tab)
with forward kinematics written here from the BVH rules, and round-tripped through bvh2trans."""

from __future__ import annotations

import numpy as np
import pytest
from bvh import Bvh
from scipy.spatial.transform import Rotation

from paths import ASSETS, WALK
from runnable import volanim
from volanim_core import io
from volanim_core.io.bvh_export import bvh_text
from volanim_core.io.frame_files import read_frames
from volanim_core.rig.bones import Bone, BoneSkeleton


def clip_joint_positions(text: str) -> dict[str, np.ndarray]:
    """Every joint's place in every frame, by the BVH rules: a joint is its parent's place plus the parent's
    rotation times its OFFSET, or its position channels where it has them; rotations in channel order."""
    clip = Bvh(text)
    names = clip.get_joints_names()
    out, turn = {}, {}
    for name in names:  # parents come first in a BVH file
        parent = clip.joint_parent(name)
        chans = clip.joint_channels(name)
        values = np.array(clip.frames_joint_channels(name, chans), np.float64)
        rot = [c for c in chans if c.endswith("rotation")]
        r = Rotation.from_euler("".join(c[0] for c in rot), values[:, [chans.index(c) for c in rot]], degrees=True)
        if "Xposition" in chans:
            at = values[:, [chans.index(c) for c in ("Xposition", "Yposition", "Zposition")]]
        else:
            at = out[parent.name] + turn[parent.name].apply(np.array(clip.joint_offset(name), np.float64))
        out[name] = at
        turn[name] = r if parent is None else turn[parent.name] * r
    return out


def posed_proximals(bones: BoneSkeleton, mats: np.ndarray) -> np.ndarray:
    rest = bones.segments()[:, 0]
    return np.einsum("fbji,bj->fbi", mats[:, :, :3, :3], rest) + mats[:, :, 3, :3]


@pytest.fixture(scope="module")
def walk_frames(tmp_path_factory):
    d = tmp_path_factory.mktemp("walk")
    r = volanim("bvh2trans", WALK, "--bones", ASSETS / "mannequin.bones", "--frames", "0:400:25", "-o", d)
    assert r.returncode == 0, r.stderr
    return d


# spec: docs/formats.md#bvh-export
def test_the_clip_places_every_joint_where_our_frames_do_read_by_another_parser(walk_frames, tmp_path):
    bones = io.read_bones(ASSETS / "mannequin.bones")
    r = volanim("trans2bvh", ASSETS / "mannequin.bones", walk_frames, "--fps", "12", "-o", tmp_path / "w.bvh")
    assert r.returncode == 0, r.stderr
    assert "18 bones, 16 frames at 12 fps" in r.stdout and "note:" not in r.stdout
    mats, _ = read_frames(walk_frames, bones)
    want = posed_proximals(bones, mats)
    text = (tmp_path / "w.bvh").read_text()
    got = clip_joint_positions(text)
    assert Bvh(text).frame_time == pytest.approx(1 / 12) and Bvh(text).nframes == 16
    assert text.startswith("HIERARCHY\nROOT PELVIS\n")  # one root at the joint the spine and legs leave
    for b, bone in enumerate(bones.bones):
        assert np.abs(got[bone.label] - want[:, b]).max() < 1e-3, bone.label
    hands = [b for b in range(len(bones)) if bones.bones[b].label.endswith("HAND")]
    assert np.ptp(want[:, hands], axis=0).max() > 20  # the hands do move: the check has something to see


def test_a_clip_volanim_wrote_comes_back_through_bvh2trans_unchanged(walk_frames, tmp_path):
    bones = io.read_bones(ASSETS / "mannequin.bones")
    assert volanim("trans2bvh", ASSETS / "mannequin.bones", walk_frames, "-o", tmp_path / "w.bvh").returncode == 0
    back = volanim("bvh2trans", tmp_path / "w.bvh", "--bones", ASSETS / "mannequin.bones", "-o", tmp_path / "back")
    assert back.returncode == 0, back.stderr
    assert "L_PELVIS L_PELVIS  # its own joint" in back.stdout
    a, _ = read_frames(walk_frames, bones)
    b, _ = read_frames(tmp_path / "back", bones)
    assert np.abs(a - b).max() < 1e-4


def test_bones_without_a_shared_root_move_on_their_own_and_stretch_is_reported():
    joints = {"A0": (0, 0, 0), "A1": (0, 0, 10), "B0": (20, 0, 0), "B1": (20, 10, 0), "B2": (20, 20, 0)}
    bones = BoneSkeleton(joints, [Bone("A0", "A1", "A"), Bone("B0", "B1", "B"), Bone("B1", "B2", "C")])
    rng = np.random.default_rng(7)
    mats = np.tile(np.eye(4), (5, 3, 1, 1))
    for f in range(5):
        for b in range(3):
            mats[f, b, :3, :3] = Rotation.from_rotvec(rng.normal(size=3)).as_matrix().T  # row-vector form
    mats[:, 0, 3, :3] = rng.normal(size=(5, 3)) * 5  # chain A moves on its own
    shift = mats[:, 1, 3, :3] = rng.normal(size=(5, 3)) * 5
    # C's joint follows B's distal end exactly: rotate B1 by B, then find C's translation that keeps it there
    b1 = np.array(joints["B1"], float)
    for f in range(5):
        mats[f, 2, 3, :3] = b1 @ mats[f, 1, :3, :3] + shift[f] - b1 @ mats[f, 2, :3, :3]
    text, worst = bvh_text(bones, mats, 30.0)
    assert worst < 1e-9 and text.startswith("HIERARCHY\nROOT ROOT\n")
    got, want = clip_joint_positions(text), posed_proximals(bones, mats)
    for b, label in enumerate("ABC"):
        assert np.abs(got[label] - want[:, b]).max() < 1e-3, label
    mats[:, 2, 3, :3] += 3.0  # C pulled off its parent: BVH cannot hold that, and says so
    assert bvh_text(bones, mats, 30.0)[1] == pytest.approx(np.sqrt(27))
    with pytest.raises(ValueError, match="frame rate"):
        bvh_text(bones, mats, 0.0)
