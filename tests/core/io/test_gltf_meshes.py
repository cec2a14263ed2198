"""A glTF file's surface at rest (io/gltf_meshes.py, #86) read against VTK's own glTF reader
(``vtkGLTFReader`` through pyvista), which is written independently of ours: the real Khronos Fox (a skinned
animal), and small files written here in each primitive mode and with a skin that moves its mesh."""

from __future__ import annotations

import base64
import json

import numpy as np
import pytest
import pyvista as pv
from scipy.spatial import cKDTree

from paths import FOX
from volanim_core.cli import main
from volanim_core.errors import FormatError
from volanim_core.io import read_volume
from volanim_core.io.mesh_files import read_mesh, voxelize

# a tetrahedron, its four faces wound outwards; as one strip and as a fan plus the base
TETRA = np.array([[0, 0, 0], [4, 0, 0], [0, 4, 0], [0, 0, 4]], np.float32)
FACES = [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3]


def vtk_surface(path) -> pv.PolyData:
    """VTK's reading of a glTF file (skins applied: the rest pose a viewer draws): every block's triangles,
    coincident points merged. The reader itself, not pyvista's wrapper, which loads the Fox's texture (4 s)."""
    from vtkmodules.vtkIOGeometry import vtkGLTFReader

    reader = vtkGLTFReader()
    reader.SetFileName(str(path))
    reader.ApplyDeformationsToGeometryOn()
    reader.Update()
    return pv.wrap(reader.GetOutput()).combine().extract_surface(algorithm=None).triangulate().clean()


def write_gltf(path, indices, mode=4, skin=None):
    """A one-mesh .gltf (data in a data: URI). ``skin``: (joint translation, inverse bind translation) of one
    joint every vertex follows, the joint a child of a node moved by (0, 1, 0)."""
    idx = np.asarray(indices, np.uint16)
    data = TETRA.tobytes() + idx.tobytes()
    views = [{"buffer": 0, "byteLength": TETRA.nbytes},
             {"buffer": 0, "byteOffset": TETRA.nbytes, "byteLength": idx.nbytes}]
    accessors = [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                  "min": [0, 0, 0], "max": [4, 4, 4]},
                 {"bufferView": 1, "componentType": 5123, "count": len(idx), "type": "SCALAR"}]
    attributes = {"POSITION": 0}
    nodes = [{"mesh": 0}]
    doc = {"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "scene": 0}
    if skin is not None:
        joint_at, bind_at = skin
        ibm = np.eye(4, dtype=np.float32)
        ibm[3, :3] = -np.asarray(bind_at)  # column-major: the translation is the last four numbers
        joints, weights = np.zeros((4, 4), np.uint8), np.tile(np.float32([1, 0, 0, 0]), (4, 1))
        for blob, kind, comp in ((joints, "VEC4", 5121), (weights, "VEC4", 5126), (ibm, "MAT4", 5126)):
            views.append({"buffer": 0, "byteOffset": len(data), "byteLength": blob.nbytes})
            accessors.append({"bufferView": len(views) - 1, "componentType": comp,
                              "count": 1 if kind == "MAT4" else 4, "type": kind})
            data += blob.tobytes()
        attributes.update(JOINTS_0=2, WEIGHTS_0=3)
        nodes = [{"mesh": 0, "skin": 0}, {"translation": [0, 1, 0], "children": [2]},
                 {"translation": list(map(float, np.asarray(joint_at) - [0, 1, 0]))}]
        doc["skins"] = [{"joints": [2], "inverseBindMatrices": 4}]
        doc["scenes"] = [{"nodes": [0, 1]}]
    doc.update(nodes=nodes, meshes=[{"primitives": [{"attributes": attributes, "indices": 1, "mode": mode}]}],
               accessors=accessors, bufferViews=views,
               buffers=[{"byteLength": len(data), "uri": "data:application/octet-stream;base64,"
                         + base64.b64encode(data).decode()}])
    path.write_text(json.dumps(doc))
    return path


def faces_of(mesh: pv.PolyData) -> set:
    """Each triangle as its corners' positions, up to rotation of its corners (the winding kept)."""
    out = set()
    for tri in mesh.regular_faces:
        corners = [tuple(np.round(mesh.points[i], 4)) for i in tri]
        k = corners.index(min(corners))
        out.add(tuple(corners[k:] + corners[:k]))
    return out


def test_the_fox_s_surface_is_where_vtk_s_reader_puts_it_and_voxelizes_to_the_same_body(tmp_path, capsys):
    ours, theirs = read_mesh(FOX), vtk_surface(FOX)
    assert ours.n_cells == theirs.n_cells == 576 and ours.n_points == theirs.n_points == 290
    assert cKDTree(theirs.points).query(ours.points)[0].max() < 1e-4  # float32 skinning, summed another way
    assert cKDTree(ours.points).query(theirs.points)[0].max() < 1e-4
    assert main(["voxelize", str(FOX), str(tmp_path / "fox.nrrd"), "--size", "96"]) == 0
    assert "Fox.glb: 290 vertices, 576 faces" in capsys.readouterr().out
    body = read_volume(tmp_path / "fox.nrrd")
    assert np.array_equal(body > 0, voxelize(theirs, size=96)[0] > 0)
    assert 10_000 < np.count_nonzero(body) < body.size // 2


@pytest.mark.parametrize("indices, mode", [(FACES, 4), ([1, 2, 3, 0, 1, 2], 5)], ids=["triangles", "strip"])
def test_each_primitive_mode_gives_the_triangles_vtk_gives(tmp_path, indices, mode):
    path = write_gltf(tmp_path / "tetra.gltf", indices, mode)
    ours, theirs = read_mesh(path), vtk_surface(path)
    assert len(faces_of(ours)) == 4 and faces_of(ours) == faces_of(theirs)


def test_a_fan_is_the_triangles_around_its_first_vertex(tmp_path):
    fan = read_mesh(write_gltf(tmp_path / "fan.gltf", [0, 1, 2, 3, 1], mode=6))
    tris = write_gltf(tmp_path / "tris.gltf", [0, 1, 2, 0, 2, 3, 0, 3, 1], mode=4)
    assert faces_of(fan) == faces_of(vtk_surface(tris))


def test_a_skinned_mesh_is_drawn_where_its_joint_rests_not_where_it_was_bound(tmp_path):
    path = write_gltf(tmp_path / "skinned.gltf", FACES, skin=([5, 1, 0], [0, 0, 0]))
    ours = read_mesh(path)
    assert np.allclose(np.sort(ours.points, axis=0), np.sort(TETRA + [5, 1, 0], axis=0))
    assert faces_of(ours) == faces_of(vtk_surface(path))


@pytest.mark.parametrize("make, says", [
    (lambda p: p.write_bytes(FOX.read_bytes()[:90_000]), "truncated"),
    (lambda p: write_gltf(p, [0, 1, 7], 4), "names vertex 7 of its 4"),
    (lambda p: write_gltf(p, [0, 1, 2, 3], 1), "holds no triangles"),
    (lambda p: p.write_text(json.dumps({**json.loads(write_gltf(p, FACES).read_text()),
                                        "extensionsRequired": ["KHR_draco_mesh_compression"]})),
     "compressed \\(KHR_draco_mesh_compression\\)"),
], ids=["truncated-glb", "index-past-the-vertices", "lines-only", "draco"])
def test_a_bad_file_is_refused_naming_it(tmp_path, make, says):
    path = tmp_path / "body.gltf"
    make(path)
    with pytest.raises(FormatError, match=says) as info:
        read_mesh(path)
    assert str(path) in str(info.value)
