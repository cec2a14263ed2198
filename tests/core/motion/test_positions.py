"""positions2trans (ivskelgetrot): bone matrices from joint positions per frame."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from paths import ASSETS, WALK
from runnable import volanim
from volanim_core import io
from volanim_core.io.frame_files import read_frames
from volanim_core.io.positions_files import read_positions, write_positions
from volanim_core.motion.positions import solve
from volanim_core.reconstruct.engine import grid_bounds, reconstruct
from volanim_core.rig.bones import Bone, BoneSkeleton
from volanim_core.rig.pose import joint_positions


def test_a_rigidly_moved_body_comes_back_exactly_twist_included():
    bones = io.read_bones(ASSETS / "mannequin.bones")
    rng = np.random.default_rng(11)
    mats = np.tile(np.eye(4), (6, len(bones), 1, 1))
    for f in range(6):  # the whole body turned about a random axis (twist of every bone) and moved
        mats[f, :, :3, :3] = Rotation.from_rotvec(rng.normal(size=3)).as_matrix().T
        mats[f, :, 3, :3] = rng.normal(size=3) * 30
    names, positions = list(bones.joints), joint_positions(bones, mats)
    got = solve(bones, positions, names)
    assert np.abs(got - mats).max() < 1e-9


def test_a_straight_chain_keeps_the_previous_frames_twist():
    # every joint on one line: no marker tells the twist, so each frame swings the last the least way
    bones = BoneSkeleton({"A": (0, 0, 0), "B": (0, 0, 10), "C": (0, 0, 20)}, [Bone("A", "B"), Bone("B", "C")])
    names = ["A", "B", "C"]
    tilt = [Rotation.from_rotvec([a, 0, 0]).as_matrix() for a in (0.0, 0.3, 0.6)]
    positions = np.array([[r @ np.array(bones.joints[n], float) for n in names] for r in tilt])
    got = solve(bones, positions, names)
    for f in range(3):  # about x only: the least swing from the rest or from the last frame is that tilt itself
        assert np.allclose(got[f, 0, :3, :3].T, tilt[f]) and np.allclose(got[f, 1, :3, :3].T, tilt[f])


def test_the_walks_joints_come_back_exactly_and_the_body_nearly_so(tmp_path):
    bones = io.read_bones(ASSETS / "mannequin.bones")
    r = volanim("bvh2trans", WALK, "--bones", ASSETS / "mannequin.bones", "--frames", "0:300:60", "-o", tmp_path / "w")
    assert r.returncode == 0, r.stderr
    out = volanim("trans2positions", ASSETS / "mannequin.bones", tmp_path / "w", "-o", tmp_path / "j.csv")
    assert out.returncode == 0 and "19 joints in 5 frames" in out.stdout
    back = volanim("positions2trans", tmp_path / "j.csv", "--bones", ASSETS / "mannequin.bones", "-o", tmp_path / "p")
    assert back.returncode == 0, back.stderr
    assert "reading frames" in out.stderr and "solving bones" in back.stderr  # a clip's thousand frames take seconds
    a, _ = read_frames(tmp_path / "w", bones)
    b, _ = read_frames(tmp_path / "p", bones)
    assert np.abs(joint_positions(bones, a) - joint_positions(bones, b)).max() < 1e-4  # what positions hold
    # the twist is an estimate (joints cannot tell it): the posed body still matches the clip's closely
    conn = io.read_connect(ASSETS / "mannequin.0.50.connect")
    for f in (1, 3):
        ta, tb = conn.posed(a[f]), conn.posed(b[f])
        box = grid_bounds([ta, tb], 2)
        va = reconstruct(ta, mode="binary", bounds=box).volume > 0
        vb = reconstruct(tb, mode="binary", bounds=box).volume > 0
        assert 2 * (va & vb).sum() / (va.sum() + vb.sum()) > 0.97


# spec: docs/formats.md#positions
def test_missing_joints_follow_their_parent_and_bad_rows_name_their_line(tmp_path):
    bones = io.read_bones(ASSETS / "mannequin.bones")
    names, positions = list(bones.joints), joint_positions(bones, np.tile(np.eye(4), (2, len(bones), 1, 1)))
    keep = [j for j, n in enumerate(names) if not n.startswith("L_")]  # the left side's markers fell off
    write_positions(tmp_path / "j.csv", [0, 1], [names[j] for j in keep], positions[:, keep])
    frames, read = read_positions(tmp_path / "j.csv", names)
    assert list(frames) == [0, 1] and np.isnan(read[:, names.index("L_KNEE")]).all()
    r = volanim("positions2trans", tmp_path / "j.csv", "--bones", ASSETS / "mannequin.bones", "-o", tmp_path / "p")
    assert r.returncode == 0 and "no data for L_SHOULDER" in r.stdout
    (tmp_path / "bad.csv").write_text("frame,joint,x,y,z\n0,PELVIS,1,2,3\n1,PELVIS,1,2\n")
    bad = volanim("positions2trans", tmp_path / "bad.csv", "--bones", ASSETS / "mannequin.bones", "-o", tmp_path / "x")
    assert bad.returncode == 2 and "bad.csv:3" in bad.stderr and not (tmp_path / "x").exists()


def test_a_positions_file_that_is_no_file_is_refused_not_read_forever(tmp_path):
    r = volanim("positions2trans", "/dev/zero", "--bones", ASSETS / "mannequin.bones", "-o", tmp_path / "p")
    assert r.returncode == 2 and "/dev/zero: is not a regular file" in r.stderr and not (tmp_path / "p").exists()
