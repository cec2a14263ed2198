"""A glTF file's surface (``.glb``, ``.gltf``) as a viewer shows it without its animation: a triangle mesh to voxelize.

    load_gltf (gltf_files.py: the header, the buffers and every accessor checked against its buffer)
      --the nodes' rest transforms, parents first--> each node's world matrix
      --each mesh node's triangle primitives (TRIANGLES; STRIPS and FANS made triangles; points and lines
        skipped): POSITION and indices-->
      --a skinned mesh: each vertex moved by its joints' world matrices times their inverse bind matrices,
        weighted (glTF: the mesh node's own transform is then ignored); else by its node's world matrix-->
      --> vertices (N, 3) float64, faces (M, 3) int64: every mesh of the file, one list

Why our own reader and not VTK's (``vtkGLTFReader``): VTK allocates what a file claims before reading it, and
a truncated or lying file must be refused by name, as every other reader here refuses it (#86: Khronos' Fox,
a real animal's closed skinned surface, rigged by ``volanim autorig`` and walked by its own clip).

**Decided here** (docs/formats.md): the units and axes are the file's (glTF: metres, Y up); the rest pose is
the nodes' own transforms, as the clip reader takes it; every node's mesh is used, once per node that holds it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from volanim_core.io.clip_bake import quaternion_matrices
from volanim_core.io.gltf_files import Gltf, _index, _item, _parents, _rest_local, load_gltf

GLTF_MESH_SUFFIXES = (".glb", ".gltf")
TRIANGLES, STRIP, FAN = 4, 5, 6
COMPRESSED = {"KHR_draco_mesh_compression", "EXT_meshopt_compression"}


def read_gltf_mesh(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """``(vertices (N, 3), faces (M, 3))``: every triangle of the file at its rest pose (module docstring);
    FormatError, naming the file, for one that holds no triangles or indexes a vertex it lacks."""
    g = load_gltf(path)
    packed = sorted(set(g.doc.get("extensionsRequired") or []) & COMPRESSED)
    if packed:  # their accessors have no buffer view of their own: read as they stand, every vertex at 0
        raise g.fail(f"its meshes are compressed ({', '.join(packed)}), which volanim does not read: export "
                     "them uncompressed")
    world = _world_matrices(g)
    verts, faces, n = [], [], 0
    for k, node in enumerate(g.doc.get("nodes") or []):
        if "mesh" not in node:
            continue
        mesh = _item(g, "meshes", node["mesh"])
        skin = _skin_matrices(g, node["skin"], world) if "skin" in node else None
        for p, prim in enumerate(mesh.get("primitives") or []):
            tri = _primitive(g, node["mesh"], p, prim, skin, world[k])
            if tri is None:
                continue
            v, f = tri
            verts.append(v)
            faces.append(f + n)
            n += len(v)
    if not faces:
        raise g.fail("holds no triangles (no mesh primitive of mode TRIANGLES, TRIANGLE_STRIP or TRIANGLE_FAN)")
    return np.concatenate(verts), np.concatenate(faces)


def _world_matrices(g: Gltf) -> np.ndarray:
    """``(nodes, 4, 4)`` each node's world matrix at rest (column vectors, as glTF writes them)."""
    nodes = g.doc.get("nodes") or []
    parent = _parents(g)
    world = np.zeros((len(nodes), 4, 4))
    done = np.zeros(len(nodes), bool)

    def place(k: int) -> None:
        chain = []
        while k >= 0 and not done[k]:
            chain.append(k)
            k = parent[k]
        for j in reversed(chain):
            local = _local_matrix(g, _item(g, "nodes", j))
            world[j] = local if parent[j] < 0 else world[parent[j]] @ local
            done[j] = True

    for k in range(len(nodes)):
        place(k)
    return world


def _local_matrix(g: Gltf, node: dict) -> np.ndarray:
    rest = _rest_local(g, node)
    if not isinstance(rest, tuple):
        return rest
    t, r, s = rest
    m = np.eye(4)
    try:
        m[:3, :3] = quaternion_matrices(r[None])[0] * s[None, :]
    except ValueError as exc:
        raise g.fail(f"a node's rotation: {exc}") from None
    m[:3, 3] = t
    return m


def _skin_matrices(g: Gltf, index, world: np.ndarray) -> np.ndarray:
    """``(joints, 4, 4)`` each joint's world matrix times its inverse bind matrix."""
    skin = _item(g, "skins", index)
    joints = [_index(g, "nodes", j) for j in skin.get("joints") or []]
    if not joints:
        raise g.fail(f"skin {index} has no joints")
    if "inverseBindMatrices" in skin:
        ibm = g.accessor(skin["inverseBindMatrices"])
        if ibm.shape != (len(joints), 16):
            raise g.fail(f"skin {index}: {len(ibm)} inverse bind matrices of {ibm.shape[1]} numbers for "
                         f"{len(joints)} joints (one 4 x 4 each)")
        ibm = ibm.reshape(-1, 4, 4).transpose(0, 2, 1)  # column-major
    else:
        ibm = np.tile(np.eye(4), (len(joints), 1, 1))
    return world[joints] @ ibm


def _primitive(g: Gltf, mesh: int, p: int, prim: dict, skin, node_world) -> tuple[np.ndarray, np.ndarray] | None:
    mode = prim.get("mode", TRIANGLES)
    if mode not in (TRIANGLES, STRIP, FAN):
        return None  # points and lines bound no volume
    attrs = prim.get("attributes") or {}
    if "POSITION" not in attrs:
        raise g.fail(f"mesh {mesh} primitive {p} has no POSITION")
    v = g.accessor(attrs["POSITION"])
    if v.shape[1] != 3:
        raise g.fail(f"mesh {mesh} primitive {p}: POSITION holds {v.shape[1]} numbers a vertex, not 3")
    idx = g.accessor(prim["indices"])[:, 0] if "indices" in prim else np.arange(len(v), dtype=np.float64)
    if idx.size and (idx.min() < 0 or idx.max() >= len(v) or not np.all(idx == np.rint(idx))):
        raise g.fail(f"mesh {mesh} primitive {p}: an index names vertex {int(idx.max())} of its {len(v)}")
    idx = idx.astype(np.int64)
    faces = _triangles(idx, mode)
    if not len(faces):
        return None
    hom = np.c_[v, np.ones(len(v))]
    if skin is None:
        return (hom @ node_world.T)[:, :3], faces
    joints = g.accessor(attrs["JOINTS_0"]).astype(np.int64) if "JOINTS_0" in attrs else None
    weights = g.accessor(attrs["WEIGHTS_0"]) if "WEIGHTS_0" in attrs else None
    if joints is None or weights is None or joints.shape != (len(v), 4) or weights.shape != (len(v), 4):
        raise g.fail(f"mesh {mesh} primitive {p} is skinned but lacks JOINTS_0 and WEIGHTS_0 of 4 values a vertex")
    if joints.min() < 0 or joints.max() >= len(skin):
        raise g.fail(f"mesh {mesh} primitive {p}: JOINTS_0 names joint {int(joints.max())} of its skin's {len(skin)}")
    total = weights.sum(axis=1, keepdims=True)
    if np.any(total <= 0):
        raise g.fail(f"mesh {mesh} primitive {p}: vertex {int(np.argmax(total[:, 0] <= 0))} has no weight")
    blend = np.einsum("vk,vkij->vij", weights / total, skin[joints])  # what a viewer draws at rest
    return np.einsum("vij,vj->vi", blend, hom)[:, :3], faces


def _triangles(idx: np.ndarray, mode: int) -> np.ndarray:
    if mode == TRIANGLES:
        return idx[: len(idx) // 3 * 3].reshape(-1, 3)
    k = np.arange(max(len(idx) - 2, 0))
    if mode == FAN:
        return np.c_[np.full(len(k), idx[0] if len(idx) else 0), idx[k + 1], idx[k + 2]]
    even = (k % 2) == 0  # a strip's every other triangle turns the other way: keep the winding
    return np.c_[idx[k], np.where(even, idx[k + 1], idx[k + 2]), np.where(even, idx[k + 2], idx[k + 1])]
