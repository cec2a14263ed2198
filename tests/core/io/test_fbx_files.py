"""FBX clips (#88) read against another reader: assimp writes the same scene as glTF 2.0 and pygltflib
parses that, the joints' world positions composed from its nodes and keys by ``their_gltf`` (scipy's
quaternions), independently of ``fbx_files`` and ``gltf_files``. Real files of the assimp repository's test
models: ``huesitos.fbx`` (Blender 2.79, a branching rig, 40 keys at 25 fps; shipped as ``volanim samples
huesitos``) and ``animation_with_skeleton.fbx`` (15 bones); see tests/data/README.md."""

from __future__ import annotations

from pathlib import Path

import impasse
import numpy as np
import pytest

from paths import FBX, HUESITOS
from their_gltf import joints_agree
from volanim_core.errors import FormatError
from volanim_core.io.clip_files import clip_animations, read_clip
from volanim_core.io.fbx_files import read_fbx

SKELETON = FBX / "animation_with_skeleton.fbx"


def _as_gltf(path: Path, folder: Path) -> Path:
    """assimp's own glTF 2.0 of the file: the same scene, for another project's reader."""
    out = folder / f"{path.stem}.glb"
    impasse.export(impasse.load(str(path), processing=0), str(out), "glb2")
    return out


# spec: docs/formats.md#fbx
@pytest.mark.parametrize("path, joints, frames, keys", [(HUESITOS, 10, 40, 40), (SKELETON, 15, 21, 14)],
                         ids=["huesitos", "animation-with-skeleton"])
def test_joints_at_every_key_are_where_the_same_scene_as_gltf_puts_them(tmp_path, path, joints, frames, keys):
    ours = read_fbx(path)
    assert (len(ours.names), ours.frames) == (joints, frames)
    assert all(ours.parents[j] < j for j in range(1, joints))  # parents first
    # the FBX unit is a centimetre (UnitScaleFactor 1): ours are metres, assimp's glTF keeps file units
    assert joints_agree(ours, _as_gltf(path, tmp_path), 0, unit=0.01) == keys


def test_the_clip_rests_as_the_file_rests_at_its_key_rate():
    ours = read_clip(HUESITOS)
    assert ours.animation == "Armature|Action" and ours.fps == 25.0  # 40 keys at 25 a second: a baked clip
    assert ours.names[0] == "Armature" and "Bone.006_end" not in ours.names  # skinned bones and animated nodes
    rest = ours.rest_positions()
    assert np.ptp(rest, axis=0).max() == pytest.approx(4.62, abs=0.01)  # metres: FBX centimetres read as metres


def test_animations_are_picked_by_name_or_number_and_a_wrong_one_is_refused_with_the_list():
    assert clip_animations(HUESITOS) == ["Armature|Action"]
    assert read_clip(HUESITOS, 0).frames == read_clip(HUESITOS, "Armature|Action").frames == 40
    with pytest.raises(FormatError, match=r"huesitos.fbx: has no animation 'Walk'; it has Armature\|Action"):
        read_clip(HUESITOS, "Walk")


@pytest.mark.parametrize("make, says", [
    (lambda p: HUESITOS.read_bytes()[:50_000], "is no FBX file assimp can read: FBX-Tokenize"),
    (lambda p: b"", r"is no FBX file \(0 bytes\)"),
    (lambda p: HUESITOS.read_bytes()[:30], "is no FBX file assimp can read"),
    (lambda p: (FBX / "box.fbx").read_bytes(), "has no animation and no skeleton"),  # a figure, not a clip
], ids=["truncated", "empty", "its-header-only", "a-box-with-no-skeleton"])
def test_a_bad_file_is_refused_naming_it_and_what_is_wrong(tmp_path, make, says):
    path = tmp_path / "clip.fbx"
    path.write_bytes(make(path))
    with pytest.raises(FormatError, match=str(path).replace(".", r"\.") + ": " + says):
        read_clip(path)


def test_keys_that_are_nan_or_absurd_are_refused_naming_the_node(tmp_path):
    """Whatever assimp hands over is checked before it becomes a Motion (no real FBX here carries such keys)."""
    from types import SimpleNamespace

    from volanim_core.io.fbx_files import _keys

    path = tmp_path / "c.fbx"
    for bad in (float("nan"), float("inf"), 1e30):
        keys = [SimpleNamespace(time=0.0, value=[0.0, 0.0, 0.0]), SimpleNamespace(time=1.0, value=[bad, 0.0, 0.0])]
        with pytest.raises(FormatError, match=r"c\.fbx: node 'Bone' has NaN, infinite or absurd keys"):
            _keys(path, "Bone", keys, 3, 25.0)
    keys = [SimpleNamespace(time=1.0, value=[0.0] * 3), SimpleNamespace(time=1.0, value=[0.0] * 3)]
    with pytest.raises(FormatError, match="its key times do not increase"):
        _keys(path, "Bone", keys, 3, 25.0)
