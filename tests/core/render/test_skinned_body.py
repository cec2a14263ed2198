"""The animated glTF we write (#88 item 2) read back by other projects: the Khronos glTF validator (0 errors,
0 warnings), pygltflib and scipy composing the joints and skinning the vertices as the specification says
(their_gltf), and trimesh's scene loader. The joints must be where our bones put them at every frame, and
the skinned surface where our posed volume is: the mannequin, moved by assimp's huesitos.fbx (a real FBX)."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import edt
import numpy as np
import pytest
import trimesh

from paths import HUESITOS
from their_gltf import accessor_values, load_theirs, their_positions, their_skinned_vertices
from volanim_core import samples
from volanim_core.errors import Cancelled
from volanim_core.io.clip_files import read_clip
from volanim_core.io.mapping_files import read_mapping
from volanim_core.motion.retarget import Retarget
from volanim_core.reconstruct.engine import reconstruct
from volanim_core.render.skinned_body import export_gltf, joint_parents
from volanim_core.rig.attach import connect
from volanim_core.rig.connectivity import Trans
from volanim_core.rig.ownership import ownership
from volanim_core.rig.pose import apply_matrices
from volanim_core.rig.tskel_tools import connect_to_tskel
from volanim_core.skeleton.skeletonize import skeletonize

VALIDATOR = Path(sys.prefix) / "npm" / "node_modules" / "gltf-validator"  # make install-test puts it there


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    """The mannequin's default rig (ownership), huesitos.fbx on its spine and arms, written as a .glb."""
    s = samples.mannequin()
    conn = connect(skeletonize(s.mask, min_thinness=0.5), s.bones)[0]
    conn = conn.with_ownership(ownership(s.mask, conn))
    mapping = read_mapping(HUESITOS.with_name("huesitos.mannequin.map"))
    frames = Retarget.build(s.bones.on_cubes(), read_clip(HUESITOS), mapping).matrices()
    path = tmp_path_factory.mktemp("gltf") / "arms.glb"
    held = export_gltf(conn, frames, 25.0, path, "Armature|Action")
    return conn, frames, path, held


# spec: docs/formats.md#gltf-out
def test_the_khronos_validator_finds_nothing_wrong(exported):
    node = shutil.which("node")
    assert node and VALIDATOR.is_dir(), "make install-test installs Node's gltf-validator into .venv/npm"
    script = ("const v = require(process.argv[1]); const fs = require('fs');"
              "v.validateBytes(new Uint8Array(fs.readFileSync(process.argv[2]))).then(r => "
              "console.log(JSON.stringify(r.issues)))")
    out = subprocess.run([node, "-e", script, str(VALIDATOR), str(exported[2])], capture_output=True, text=True,
                         check=True, timeout=120)
    issues = json.loads(out.stdout)
    assert (issues["numErrors"], issues["numWarnings"]) == (0, 0), issues["messages"][:5]


def test_the_joints_are_where_our_bones_put_them_at_every_frame(exported):
    conn, frames, path, held = exported
    g = load_theirs(path)
    axes = held["axes"]
    joints = np.array([b.proximal for b in conn.bones])
    size = np.ptp(np.array([w for w in their_positions(g, 0, 0.0).values()]), axis=0).max()
    for f in range(len(frames)):
        ours = apply_matrices(joints, np.arange(len(joints)), frames[f])
        ours = (axes @ np.c_[ours, np.ones(len(ours))].T).T[:, :3]
        theirs = their_positions(g, 0, f / 25.0)
        for k, b in enumerate(conn.bones):
            assert np.abs(theirs[b.name] - ours[k]).max() <= 1e-6 * size, (b.name, f)
    assert [n.name for n in g.nodes[1:19]] == [b.name for b in conn.bones]
    parents = joint_parents(conn)
    assert parents[[b.name for b in conn.bones].index("L_FOREARM")] == [b.name for b in conn.bones].index("L_UPPERARM")


def test_the_skinned_surface_lies_on_our_posed_body(exported):
    """Each frame's vertices, skinned by the reader, against the boundary of the volume reconstruct poses
    (every owned voxel moved by its bone): most within a voxel; near joints linear blend skinning rounds."""
    conn, frames, path, held = exported
    g = load_theirs(path)
    axes = np.linalg.inv(held["axes"])
    for f in (0, 20, 39):
        v = their_skinned_vertices(g, f / 25.0)
        vox = (axes @ np.c_[v, np.ones(len(v))].T).T[:, :3]
        rec = reconstruct(connect_to_tskel(conn, Trans(conn.bones, frames[f])), mode="binary")
        inside = np.pad(rec.volume > 0, 2)
        to_boundary = np.where(inside, edt.edt(inside.astype(np.uint8)), edt.edt((~inside).astype(np.uint8)))
        k = np.clip(np.rint(vox - np.asarray(rec.origin) + 2).astype(int), 0, np.array(inside.shape) - 1)
        d = to_boundary[k[:, 0], k[:, 1], k[:, 2]]
        assert np.percentile(d, 95) <= 1.5 and np.percentile(d, 99) <= 4.0, (f, np.percentile(d, [95, 99]))


def test_trimesh_loads_the_scene_standing_on_the_floor(exported):
    conn, frames, path, held = exported
    scene = trimesh.load(path)
    mesh = next(iter(scene.geometry.values()))
    assert len(mesh.faces) == held["triangles"] <= 200_000 and mesh.is_winding_consistent
    lo, hi = scene.bounds
    assert lo[1] == pytest.approx(0.0, abs=1e-6) and hi[1] == pytest.approx(0.29, abs=0.01)  # metres, y up


def test_the_rest_frame_skins_to_the_stored_vertices(exported, tmp_path):
    conn = exported[0]
    path = tmp_path / "rest.glb"
    export_gltf(conn, np.tile(np.eye(4), (1, len(conn.bones), 1, 1)), 24.0, path)
    g = load_theirs(path)
    stored = accessor_values(g, g.meshes[0].primitives[0].attributes.POSITION)
    assert np.abs(their_skinned_vertices(g, 0.0) - stored).max() < 1e-6


def test_a_frame_that_shears_is_refused_and_nothing_is_written(exported, tmp_path):
    conn, frames, _, _ = exported
    bad = frames[:2].copy()
    bad[1, 3, 0, 1] = 0.3  # a shear
    with pytest.raises(ValueError, match="not a rigid motion"):
        export_gltf(conn, bad, 25.0, tmp_path / "bad.glb")
    assert not any(tmp_path.iterdir())


def test_cancel_between_stages_writes_nothing(exported, tmp_path):
    conn, frames, _, _ = exported
    asked = []
    with pytest.raises(Cancelled):
        export_gltf(conn, frames, 25.0, tmp_path / "c.glb", cancel=lambda: asked.append(1) or len(asked) > 1)
    assert len(asked) == 2 and not any(tmp_path.iterdir())  # the second stage's check: surface made, not written
