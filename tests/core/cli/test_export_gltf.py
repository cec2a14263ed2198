"""``volanim export-gltf`` in-process: a real FBX clip (mapped) and .trans frames onto the mannequin's default
rig, the same animation either way; a rig and frames of different bones refused, nothing written. What the
file holds is checked against other readers in tests/core/render/test_skinned_body.py."""

from __future__ import annotations

import numpy as np

from paths import HUESITOS
from their_gltf import load_theirs, their_positions
from volanim_core.cli import main


def test_a_clip_and_its_trans_frames_export_the_same_animation(skeletonized_mannequin, tmp_path, capsys):
    d = skeletonized_mannequin
    rig, bones = tmp_path / "m.connect", d / "mannequin.bones"
    assert main(["connect", str(d / "m.mskel"), str(bones), "--volume", str(d / "mannequin.VOL"), "-o", str(rig)]) == 0
    mapping = str(HUESITOS.with_name("huesitos.mannequin.map"))
    assert main(["export-gltf", str(rig), str(HUESITOS), "--bones", str(bones), "--map", mapping,
                 "-o", str(tmp_path / "clip.glb")]) == 0
    said = capsys.readouterr().out
    assert "skinned to 18 joints by its ownership, 40 frames at 25 fps" in said and "SPINE Bone.001" in said
    assert main(["bvh2trans", str(HUESITOS), "--bones", str(bones), "--map", mapping, "-o", str(tmp_path / "f")]) == 0
    assert main(["export-gltf", str(rig), str(tmp_path / "f"), "--bones", str(bones), "--fps", "25",
                 "--triangles", "20000", "-o", str(tmp_path / "trans.glb")]) == 0
    clip, trans = load_theirs(tmp_path / "clip.glb"), load_theirs(tmp_path / "trans.glb")
    assert trans.accessors[trans.meshes[0].primitives[0].indices].count <= 3 * 20000
    for t in (0.0, 0.4, 1.56):  # the joints from the root: the floor is the surface's, decimated otherwise
        a, b = their_positions(clip, 0, t), their_positions(trans, 0, t)
        moved = [k for k in a if k not in ("body", "volanim")]
        assert len(moved) == 18
        assert all(np.allclose(a[k] - a["volanim"], b[k] - b["volanim"], atol=1e-6) for k in moved)


def test_frames_of_other_bones_are_refused_and_nothing_is_written(skeletonized_mannequin, tmp_path, capsys):
    d = skeletonized_mannequin
    rig = tmp_path / "m.connect"
    assert main(["connect", str(d / "m.mskel"), str(d / "mannequin.bones"), "-o", str(rig)]) == 0
    lines = (d / "mannequin.bones").read_text().splitlines()
    moved = [line.replace("joint L_ELBOW 124 50 178", "joint L_ELBOW 124 50 170") for line in lines]
    (tmp_path / "other.bones").write_text("\n".join(moved) + "\n")
    assert main(["pose", str(tmp_path / "other.bones"), "--rotate", "L_UPPERARM=0,60,0",
                 "-o", str(tmp_path / "f" / "arm.0000.trans")]) == 0
    assert main(["export-gltf", str(rig), str(tmp_path / "f"), "--bones", str(tmp_path / "other.bones"),
                 "-o", str(tmp_path / "x.glb")]) == 2
    assert "L_UPPERARM" in capsys.readouterr().err and not (tmp_path / "x.glb").exists()
