"""glTF files read by another project: pygltflib parses them and the nodes' world positions are composed
here (scipy's quaternions), independently of volanim's readers. Used to check our glTF and FBX clips in and
the animated glTF we write."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pygltflib
from scipy.spatial.transform import Rotation, Slerp


def load_theirs(path: Path) -> pygltflib.GLTF2:
    binary = path.read_bytes()[:4] == b"glTF"  # a .vrma is a GLB: pygltflib goes by the suffix otherwise
    return (pygltflib.GLTF2().load_binary if binary else pygltflib.GLTF2().load)(str(path))


def accessor_values(g: pygltflib.GLTF2, index: int) -> np.ndarray:
    a = g.accessors[index]
    view = g.bufferViews[a.bufferView]
    width = {"SCALAR": 1, "VEC3": 3, "VEC4": 4, "MAT4": 16}[a.type]
    assert a.componentType == pygltflib.FLOAT and not view.byteStride
    start = (view.byteOffset or 0) + (a.byteOffset or 0)
    return np.frombuffer(g.binary_blob(), np.float32, a.count * width, start).reshape(a.count, width).astype(float)


def _at(times: np.ndarray, values: np.ndarray, t: float, rotation: bool) -> np.ndarray:
    """A LINEAR sampler at ``t``, held past its ends (scipy's Slerp for rotations)."""
    t = float(np.clip(t, times[0], times[-1]))
    if len(times) == 1:
        return values[0]
    if rotation:
        return Slerp(times, Rotation.from_quat(values))(t).as_quat()
    return np.array([np.interp(t, times, v) for v in values.T])


def their_worlds(g: pygltflib.GLTF2, animation: int, t: float) -> list[np.ndarray]:
    """Every node's world matrix at time ``t`` (seconds) of ``animation``, from pygltflib's parse."""
    trs = {k: [n.translation or [0, 0, 0], n.rotation or [0, 0, 0, 1], n.scale or [1, 1, 1]]
           for k, n in enumerate(g.nodes)}
    anim = g.animations[animation]
    for c in anim.channels:
        if c.target.path in ("translation", "rotation", "scale"):
            sampler = anim.samplers[c.sampler]
            assert sampler.interpolation in (None, "LINEAR")
            times, values = accessor_values(g, sampler.input)[:, 0], accessor_values(g, sampler.output)
            trs[c.target.node][("translation", "rotation", "scale").index(c.target.path)] = \
                _at(times, values, t, c.target.path == "rotation")
    parent = {c: k for k, n in enumerate(g.nodes) for c in n.children or []}

    def world(k):
        n = g.nodes[k]
        if n.matrix:
            local = np.asarray(n.matrix, float).reshape(4, 4).T
        else:
            t, r, s = trs[k]
            local = np.eye(4)
            local[:3, :3] = Rotation.from_quat(r).as_matrix() * np.asarray(s)
            local[:3, 3] = t
        return local if k not in parent else world(parent[k]) @ local

    return [world(k) for k in range(len(g.nodes))]


def their_positions(g: pygltflib.GLTF2, animation: int, t: float) -> dict[str, np.ndarray]:
    """Every named node's world position at time ``t`` (seconds) of ``animation``."""
    return {n.name: w[:3, 3] for n, w in zip(g.nodes, their_worlds(g, animation, t)) if n.name}


def their_skinned_vertices(g: pygltflib.GLTF2, t: float, animation: int = 0) -> np.ndarray:
    """The first skinned mesh's vertices at time ``t``, as the specification skins them: each vertex the
    weighted sum of ``world(joint) @ inverseBind(joint)`` over its JOINTS_0 and WEIGHTS_0 (the mesh's node
    at the scene's top with no transform, as glTF asks)."""
    node = next(n for n in g.nodes if n.skin is not None)
    attributes = g.meshes[node.mesh].primitives[0].attributes
    skin = g.skins[node.skin]
    worlds = their_worlds(g, animation, t)
    inverse_bind = accessor_values(g, skin.inverseBindMatrices).reshape(-1, 4, 4).transpose(0, 2, 1)
    joint = np.stack([worlds[j] @ ib for j, ib in zip(skin.joints, inverse_bind)])
    v = np.c_[accessor_values(g, attributes.POSITION), np.ones(g.accessors[attributes.POSITION].count)]
    a = g.accessors[attributes.JOINTS_0]
    view = g.bufferViews[a.bufferView]
    assert a.componentType == pygltflib.UNSIGNED_SHORT
    which = np.frombuffer(g.binary_blob(), np.uint16, a.count * 4, (view.byteOffset or 0) + (a.byteOffset or 0))
    which = which.reshape(-1, 4)
    weights = accessor_values(g, attributes.WEIGHTS_0)
    out = np.zeros((len(v), 4))
    for k in range(4):
        out += weights[:, k:k + 1] * np.einsum("vij,vj->vi", joint[which[:, k]], v)
    return out[:, :3]


def key_times(g: pygltflib.GLTF2, animation: int) -> np.ndarray:
    """Every key time of ``animation``, of all its samplers, in order."""
    return np.unique(np.concatenate([accessor_values(g, s.input)[:, 0] for s in g.animations[animation].samplers]))


def joints_agree(ours, path: Path, animation: int = 0, unit: float = 1.0) -> int:
    """Assert each of ``ours``' joints (a Motion) sits where pygltflib's parse of ``path`` puts the node of its
    name, within 1e-4 of the figure's size, at every key (of any channel) that falls on one of our frames (``unit``: our
    length units a file unit). The number of keys compared."""
    _, positions = ours.forward_kinematics()
    size = np.ptp(ours.rest_positions(), axis=0).max()
    theirs = load_theirs(path)
    times = key_times(theirs, animation)
    checked = 0
    for key, t in enumerate(times):
        frame = (t - times[0]) * ours.fps
        if abs(frame - round(frame)) > 1e-3:  # a key between our frames (the Run's last): interpolated, not a key
            continue
        where = their_positions(theirs, animation, t)
        for j, name in enumerate(ours.names):
            assert np.abs(positions[round(frame), j] - unit * where[name]).max() <= 1e-4 * size, (name, key)
        checked += 1
    return checked
