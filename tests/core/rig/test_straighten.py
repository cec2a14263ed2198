"""`volanim straighten`: a chain of bones laid straight along its principal axis, the thesis's colon uncoiled
(section 5.3), checked against the straight tube the curved one should become."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core.reconstruct.engine import reconstruct
from volanim_core.rig.attach import connect_nearest
from volanim_core.rig.bones import Bone, BoneSkeleton
from volanim_core.rig.connectivity import Trans
from volanim_core.rig.pose import least_rotation, posed_joints, root_bones
from volanim_core.rig.straighten import chain, principal_axis, straighten
from volanim_core.rig.tskel_tools import connect_to_tskel
from volanim_core.samples import TUBE_RADIUS, curved_tube
from volanim_core.skeleton.skeletonize import skeletonize


def test_least_rotation_takes_a_to_b_without_a_twist():
    rng = np.random.default_rng(5)
    for _ in range(20):
        a, b = rng.normal(size=3), rng.normal(size=3)
        a, b = a / np.linalg.norm(a), b / np.linalg.norm(b)
        r = least_rotation(a, b)
        assert np.allclose(r @ a, b) and np.allclose(r.T @ r, np.eye(3)) and np.isclose(np.linalg.det(r), 1)
        axis = np.cross(a, b)  # the least rotation turns about a x b, which it leaves where it is
        assert np.allclose(r @ axis, axis)
    assert np.allclose(least_rotation(np.array([1.0, 0, 0]), np.array([-1.0, 0, 0])) @ [1, 0, 0], [-1, 0, 0])


def test_the_chain_and_its_axis():
    tube = curved_tube()
    assert [tube.bones.bones[i].label for i in chain(tube.bones)] == [b.label for b in tube.bones.bones]
    branched = BoneSkeleton({"a": np.zeros(3), "b": np.ones(3), "c": np.array([2.0, 0, 0]), "d": np.array([0, 2.0, 0])},
                            [Bone("a", "b"), Bone("b", "c"), Bone("b", "d")])
    with pytest.raises(ValueError, match="not one chain"):
        chain(branched)
    assert chain(branched, "a-b", "b-d") == [0, 2]
    with pytest.raises(ValueError, match="does not hang below"):
        chain(branched, "b-c", "b-d")
    line = np.array([[0, 0, 0], [1, 0.1, 0], [2, -0.1, 0], [3, 0, 0.0]])
    assert np.allclose(principal_axis(line), [1, 0, 0], atol=0.03)
    assert np.allclose(principal_axis(line[::-1]), [-1, 0, 0], atol=0.03)  # pointing from the first to the last


def test_the_curved_tube_is_reconstructed_straight():
    """The tube bends through a half circle; straightened, its joints lie on one line, bone lengths kept, the
    first joint where it was; the reconstruction is one piece lying around that line, as long as the chain, and
    matches the straight tube (the true shape) within a voxel at its surface."""
    tube = curved_tube()
    matrices, u, ids = straighten(tube.bones)
    assert ids == chain(tube.bones)
    joints = posed_joints(tube.bones, matrices)
    order = [tube.bones.bones[0].proximal] + [b.distal for b in tube.bones.bones]
    start = tube.bones.joints[order[0]]
    assert np.allclose(joints[order[0]], start)
    lengths = [np.linalg.norm(tube.bones.joints[b.distal] - tube.bones.joints[b.proximal]) for b in tube.bones.bones]
    along = np.array([np.dot(joints[j] - start, u) for j in order])
    off = np.array([np.linalg.norm(joints[j] - start - np.dot(joints[j] - start, u) * u) for j in order])
    assert np.allclose(along, np.concatenate(([0], np.cumsum(lengths)))) and off.max() < 1e-9
    conn = connect_nearest(skeletonize(tube.mask), tube.bones)
    r = reconstruct(connect_to_tskel(conn, Trans(root_bones(tube.bones), matrices)), mode="binary")
    vox = np.argwhere(r.volume) + r.origin
    t = (vox - start) @ u
    radial = np.linalg.norm((vox - start) - np.outer(t, u), axis=1)
    total = float(np.sum(lengths))
    assert radial.max() <= TUBE_RADIUS + 2.0  # no lump: nothing far off the straight line
    assert t.min() >= -TUBE_RADIUS - 2.0 and t.max() <= total + TUBE_RADIUS + 2.0
    # the true straight tube, a cylinder of the tube's radius round the straightened line. Each bone carries its
    # part of the arc rigidly, so the centre line stays off its chord by the arc's sagitta (0.77 voxels here)
    sagitta = 40.0 * (1 - np.cos(np.pi / 16))
    outer = TUBE_RADIUS + sagitta + np.sqrt(3) / 2
    assert np.mean((radial <= outer) & (t >= -outer) & (t <= total + outer)) > 0.995  # nothing outside it
    lo = np.floor(start + np.minimum(0, total * u) - TUBE_RADIUS).astype(int)
    grid = np.argwhere(np.ones((int(total) + 20,) * 3, bool)) + lo - 10  # a box round the straight tube
    gt = (grid - start) @ u
    inner = (np.linalg.norm((grid - start) - np.outer(gt, u), axis=1) <= TUBE_RADIUS - 1.5) & (gt >= 2) & \
        (gt <= total - 2)
    cells = grid[inner] - r.origin
    inside = np.all((cells >= 0) & (cells < r.volume.shape), axis=1)
    assert inside.all() and r.volume[tuple(cells.T)].mean() > 0.995  # and its core is all there: no hole
    body = int(tube.mask.sum())
    assert abs(len(vox) - body) / body < 0.08  # as much tube as before
    from scipy import ndimage

    assert ndimage.label(r.volume, np.ones((3, 3, 3)))[1] == 1


def test_the_command_writes_the_straight_pose_and_names_a_chain_it_needs(tmp_path):
    from runnable import volanim
    from volanim_core import io, samples

    for name in ("curved-tube", "mannequin"):
        samples.write_sample(name, tmp_path)
    r = volanim("straighten", tmp_path / "curved-tube.bones", "-o", tmp_path / "s.trans")
    assert r.returncode == 0, r.stderr
    assert "straightened 8 bones (S1 .. S8)" in r.stdout
    want, _, _ = straighten(io.read_bones(tmp_path / "curved-tube.bones").on_cubes())
    assert np.allclose(io.read_trans(tmp_path / "s.trans").matrices, want, atol=1e-9)
    many = volanim("straighten", tmp_path / "mannequin.bones", "-o", tmp_path / "x.trans")
    assert many.returncode == 2 and "not one chain" in many.stderr and not (tmp_path / "x.trans").exists()
    arm = volanim("straighten", tmp_path / "mannequin.bones", "--chain", "L_UPPERARM", "L_HAND", "-o",
                  tmp_path / "arm.trans")
    assert arm.returncode == 0 and "straightened 3 bones (L_UPPERARM .. L_HAND)" in arm.stdout
    typo = volanim("straighten", tmp_path / "mannequin.bones", "--chain", "L_UPPERAM", "L_HAND", "-o",
                   tmp_path / "y.trans")
    assert typo.returncode == 2 and "no bone named 'L_UPPERAM'; bones are" in typo.stderr
