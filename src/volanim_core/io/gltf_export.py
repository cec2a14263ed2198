"""An animated, skinned glTF 2.0 binary (``.glb``) written from arrays: one mesh skinned to a tree of joints
and one animation of those joints (docs/formats.md#gltf-out). What to put in it is
:mod:`volanim_core.render.skinned_body`'s; this module only lays the arrays out as the Khronos
specification says, so any viewer opens it.

    SkinnedMesh (vertices, normals, triangles, JOINTS_0 / WEIGHTS_0)  ─┐
    JointAnimation (names, parents, rest locals, times, T and R keys) ─┼─> JSON + one BIN buffer --> .glb
    axes (the scene root's matrix: our voxels -> metres, Y up)       ─┘      (atomic: a temporary, renamed)

Layout: node 0 is the scene root holding ``axes``; the joints are its descendants (parents first, node
``1 + b`` for joint b); the mesh's node sits at the scene's top with no transform, as the specification
asks of a skinned mesh. Inverse bind matrices are the joints' rest world matrices inverted, so the rest
pose is the vertices as stored.
"""

from __future__ import annotations

import json
import struct
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from volanim_core.io.atomic import atomic_write_bytes

FLOAT, UINT16, UINT32 = 5126, 5123, 5125
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963


@dataclass
class SkinnedMesh:
    """Vertices (scene space: metres, Y up) ``(V, 3)``, unit normals ``(V, 3)``, triangles ``(T, 3)``, and for
    each vertex up to four joints ``(V, 4)`` with weights ``(V, 4)`` summing to 1."""

    vertices: np.ndarray
    normals: np.ndarray
    triangles: np.ndarray
    joints: np.ndarray
    weights: np.ndarray


@dataclass
class JointAnimation:
    """A tree of joints and their motion: ``parents[b] < b`` (-1: a child of the scene root); ``rest``
    ``(B, 4, 4)`` each joint's local matrix at rest; ``times`` ``(F,)`` seconds; ``translations``
    ``(F, B, 3)`` and ``rotations`` ``(F, B, 4)`` (quaternions ``x, y, z, w``) the local motion."""

    names: list[str]
    parents: list[int]
    rest: np.ndarray
    times: np.ndarray
    translations: np.ndarray
    rotations: np.ndarray
    name: str = "clip"


class _Buffer:
    """The BIN chunk and the JSON's bufferViews and accessors that describe it."""

    def __init__(self):
        self.blob = bytearray()
        self.views: list[dict] = []
        self.accessors: list[dict] = []

    def add(self, array: np.ndarray, component: int, kind: str, target: int | None = None,
            bounds: bool = False) -> int:
        dtype = {FLOAT: "<f4", UINT16: "<u2", UINT32: "<u4"}[component]
        data = np.ascontiguousarray(array, dtype)
        self.blob += b"\0" * (-len(self.blob) % 4)  # every view starts 4-aligned
        view = {"buffer": 0, "byteOffset": len(self.blob), "byteLength": data.nbytes}
        if target is not None:
            view["target"] = target
        self.blob += data.tobytes()
        self.views.append(view)
        count = len(data)
        accessor = {"bufferView": len(self.views) - 1, "componentType": component, "count": count, "type": kind}
        if bounds:  # POSITION and animation inputs must say their bounds
            flat = data.reshape(count, -1).astype(np.float64)
            accessor["min"], accessor["max"] = flat.min(0).tolist(), flat.max(0).tolist()
        self.accessors.append(accessor)
        return len(self.accessors) - 1


def _column_major(m: np.ndarray) -> list[float]:
    return [float(v) for v in np.asarray(m, np.float64).T.ravel()]


def glb_bytes(mesh: SkinnedMesh, anim: JointAnimation, axes: np.ndarray, generator: str = "volanim") -> bytes:
    """The ``.glb`` file's bytes (see the module's layout)."""
    n = len(anim.names)
    if not (len(anim.parents) == n and all(-1 <= p < b for b, p in enumerate(anim.parents))):
        raise ValueError("joints must list parents first (parents[b] < b, -1 for a child of the root)")
    buf = _Buffer()
    index_type = UINT16 if len(mesh.vertices) <= 65535 else UINT32
    attributes = {
        "POSITION": buf.add(mesh.vertices.reshape(-1, 3), FLOAT, "VEC3", ARRAY_BUFFER, bounds=True),
        "NORMAL": buf.add(mesh.normals.reshape(-1, 3), FLOAT, "VEC3", ARRAY_BUFFER),
        "JOINTS_0": buf.add(mesh.joints.reshape(-1, 4), UINT16, "VEC4", ARRAY_BUFFER),
        "WEIGHTS_0": buf.add(mesh.weights.reshape(-1, 4), FLOAT, "VEC4", ARRAY_BUFFER),
    }
    indices = buf.add(mesh.triangles.reshape(-1), index_type, "SCALAR", ELEMENT_ARRAY_BUFFER)
    world = np.empty((n, 4, 4))
    for b, p in enumerate(anim.parents):  # rest world matrices, under the root's axes
        world[b] = (axes if p < 0 else world[p]) @ anim.rest[b]
    inverse_bind = buf.add(np.linalg.inv(world).transpose(0, 2, 1).reshape(n, 16), FLOAT, "MAT4")
    nodes = [{"name": "volanim", "matrix": _column_major(axes),
              "children": [1 + b for b, p in enumerate(anim.parents) if p < 0]}]
    for b, name in enumerate(anim.names):
        node = {"name": name, "translation": [float(v) for v in anim.rest[b][:3, 3]],
                "rotation": _rest_quaternion(anim.rest[b])}
        kids = [1 + c for c, p in enumerate(anim.parents) if p == b]
        if kids:
            node["children"] = kids
        nodes.append(node)
    nodes.append({"name": "body", "mesh": 0, "skin": 0})
    times = buf.add(anim.times.reshape(-1, 1) - anim.times[0], FLOAT, "SCALAR", bounds=True)
    samplers, channels = [], []
    for b in range(n):
        for path, values, kind in (("translation", anim.translations[:, b], "VEC3"),
                                   ("rotation", anim.rotations[:, b], "VEC4")):
            samplers.append({"input": times, "output": buf.add(values, FLOAT, kind), "interpolation": "LINEAR"})
            channels.append({"sampler": len(samplers) - 1, "target": {"node": 1 + b, "path": path}})
    doc = {
        "asset": {"version": "2.0", "generator": generator},
        "scene": 0,
        "scenes": [{"nodes": [0, len(nodes) - 1]}],
        "nodes": nodes,
        "meshes": [{"name": "body", "primitives": [{"attributes": attributes, "indices": indices, "mode": 4,
                                                     "material": 0}]}],
        "materials": [{"name": "body", "pbrMetallicRoughness": {"baseColorFactor": [0.87, 0.72, 0.53, 1.0],
                                                               "metallicFactor": 0.0, "roughnessFactor": 0.8}}],
        "skins": [{"joints": list(range(1, n + 1)), "inverseBindMatrices": inverse_bind, "skeleton": 0}],
        "animations": [{"name": anim.name, "samplers": samplers, "channels": channels}],
        "buffers": [{"byteLength": len(buf.blob) + (-len(buf.blob) % 4)}],
        "bufferViews": buf.views,
        "accessors": buf.accessors,
    }
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    blob = bytes(buf.blob) + b"\0" * (-len(buf.blob) % 4)
    total = 12 + 8 + len(text) + 8 + len(blob)
    return (struct.pack("<4sII", b"glTF", 2, total) + struct.pack("<II", len(text), 0x4E4F534A) + text
            + struct.pack("<II", len(blob), 0x004E4942) + blob)


def _rest_quaternion(m: np.ndarray) -> list[float]:
    from scipy.spatial.transform import Rotation

    return [float(v) for v in Rotation.from_matrix(m[:3, :3]).as_quat()]


def write_glb(path: str | Path, mesh: SkinnedMesh, anim: JointAnimation, axes: np.ndarray) -> None:
    """Write the ``.glb`` atomically: a reader never sees half a file."""
    atomic_write_bytes(Path(path), glb_bytes(mesh, anim, axes))
