"""glTF 2.0 clips (#88) read against another project's reader: pygltflib parses the same files, and the
joints' world positions are composed here from its nodes and keys (scipy's quaternions), independently of
``gltf_files``. Real files: Khronos' Fox (three animations, a quadruped) and pixiv's VRM animation test
(a humanoid); see tests/data/README.md and the Fox's licence beside it in sample_data."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from paths import FOX
from their_gltf import joints_agree, key_times, load_theirs
from volanim_core.errors import FormatError
from volanim_core.io.bvh_files import euler_matrices
from volanim_core.io.clip_bake import zxy_degrees
from volanim_core.io.clip_files import clip_animations, read_clip
from volanim_core.io.gltf_files import read_gltf
from written_clips import tiny_gltf

DATA = Path(__file__).parents[2] / "data" / "gltf"
VRMA = DATA / "test.vrma"


# spec: docs/formats.md#gltf
@pytest.mark.parametrize("path, animation", [(FOX, 0), (FOX, 1), (FOX, 2), (VRMA, 0)],
                         ids=["fox-survey", "fox-walk", "fox-run", "vrm-humanoid"])
def test_joints_at_every_key_are_where_pygltflib_puts_them(path, animation):
    ours = read_gltf(path, animation)
    times = key_times(load_theirs(path), animation)
    assert joints_agree(ours, path, animation) >= min(len(times) - 1, 7)


def test_the_rest_pose_is_the_files_own_and_turns_nothing():
    ours = read_gltf(FOX, "Walk")
    g = load_theirs(FOX)
    assert ours.names[0] == "_rootJoint" and len(ours.names) == len(g.skins[0].joints) == 24
    assert set(ours.names) == {g.nodes[j].name for j in g.skins[0].joints}
    assert all(ours.parents[j] < j for j in range(1, 24))  # parents first
    assert (ours.fps, ours.frames) == (24.0, 18)


def test_animations_are_picked_by_name_or_number_and_a_wrong_one_is_refused_with_the_list():
    assert clip_animations(FOX) == ["Survey", "Walk", "Run"]
    assert read_clip(FOX).animation == "Survey" and read_clip(FOX, "Run").frames == read_clip(FOX, 2).frames
    with pytest.raises(FormatError, match="has no animation 'Trot'; it has Survey, Walk, Run"):
        read_clip(FOX, "Trot")


def test_zxy_degrees_give_their_rotations_back_at_gimbal_lock_too():
    rng = np.random.default_rng(7)
    angles = np.vstack([rng.uniform(-180, 180, (200, 3)), [[30, 90, 40], [-20, -90, 10], [0, 0, 0]]])
    r = euler_matrices("ZXY", angles)
    assert np.abs(euler_matrices("ZXY", zxy_degrees(r)) - r).max() < 1e-9


def _tiny(path: Path, times, rotations, interpolation="LINEAR", **override) -> Path:
    path.write_bytes(tiny_gltf(times, rotations, interpolation, **override))
    return path


def test_sparse_keys_are_sampled_at_30_fps_by_the_files_interpolation(tmp_path):
    half = [0, 0, np.sin(np.pi / 4), np.cos(np.pi / 4)]  # 90 degrees about z
    linear = read_gltf(_tiny(tmp_path / "a.gltf", [0, 1], [[0, 0, 0, 1], half]))
    assert (linear.fps, linear.frames) == (30.0, 31)
    _, pos = linear.forward_kinematics()
    forearm = pos[:, 2] - pos[:, 1]
    angle = np.degrees(np.arctan2(-forearm[:, 0], forearm[:, 1]))  # the arm's turn about z, from +y
    assert np.allclose(angle, np.linspace(0, 90, 31), atol=1e-6)  # slerp: an even turn
    step = read_gltf(_tiny(tmp_path / "b.gltf", [0, 1], [[0, 0, 0, 1], half], "STEP"))
    _, pos = step.forward_kinematics()
    assert np.allclose(pos[:30, 2], [0, 2, 0]) and np.allclose(pos[30, 2], [-1, 1, 0], atol=1e-6)


@pytest.mark.parametrize("make, says", [
    (lambda p: _tiny(p, [0, 1], [[0, 0, 0, 1], [0, 0, np.nan, 1]]), "NaN"),
    (lambda p: _tiny(p, [0, 1, 1], [[0, 0, 0, 1]] * 3), "do not increase"),
    (lambda p: _tiny(p, [0, 1], [[0, 0, 0, 1]] * 2, animations=[]), "has no animation"),
    (lambda p: _tiny(p, [0, 1], [[0, 0, 0, 1]] * 2, buffers=[{"byteLength": 40, "uri": "gone.bin"}]),
     "'gone.bin' is missing"),
    (lambda p: (p.write_bytes(FOX.read_bytes()[:90_000]), p)[1], "truncated"),
], ids=["nan-key", "times-repeat", "no-animation", "missing-buffer", "truncated-glb"])
def test_a_bad_file_is_refused_naming_it_and_what_is_wrong(tmp_path, make, says):
    path = make(tmp_path / "clip.glb")
    with pytest.raises(FormatError, match=says) as info:
        read_clip(path)
    assert str(path) in str(info.value)


def test_cubic_spline_keys_ease_in_and_out_as_the_spec_s_hermite_curve(tmp_path):
    half = [0, 0, np.sin(np.pi / 4), np.cos(np.pi / 4)]
    zero = [0, 0, 0, 0]  # in- and out-tangents: a key held still, the turn eased between
    clip = read_gltf(_tiny(tmp_path / "c.gltf", [0, 1], [zero, [0, 0, 0, 1], zero, zero, half, zero],
                           "CUBICSPLINE"))
    _, pos = clip.forward_kinematics()
    forearm = pos[:, 2] - pos[:, 1]
    angle = np.degrees(np.arctan2(-forearm[:, 0], forearm[:, 1]))
    assert np.isclose(angle[15], 45.0) and np.isclose(angle[-1], 90.0) and (np.diff(angle) >= 0).all()
    assert angle[3] < 0.5 * 9.0  # eased: a tenth of the way in time, under half a tenth of the way in angle
