"""glTF 2.0 clips (``.gltf``, ``.glb``, VRM animations ``.vrma``): a skeleton and one of its animations, read
as a :class:`Motion`, so everything that takes a BVH clip takes them.

    .glb   'glTF' header | JSON chunk | BIN chunk       .gltf  JSON; buffers as data: URIs or files beside it
      --accessors--> arrays, each checked against its buffer (a truncated or lying file is refused, named)
      --joints-----> the skin's joints (else a VRM animation's humanoid bones, else the whole tree that
                     holds the animated nodes), closed to one tree under their common ancestor, parents first
      --sample-----> every needed node's local matrix at the clip's frames (LINEAR, STEP, CUBICSPLINE)
      --world------> world matrices, ancestors outside the joints included (a Z-up wrapper node, a scale)
      --bake-------> a Motion whose rest (every channel zero) is the file's rest pose

**Decided here** (docs/formats.md, glTF clips):

- The rest pose is the nodes' own transforms, what a viewer shows without the animation. BVH's joints rest
  unturned; glTF's rest turned. So a joint's world rotation is taken from its rest, ``G_j(f) = R_j(f)
  R_j(rest)^T``, and its channels hold the turn from its parent's, ``G_p^T G_j`` (Z X Y Euler degrees,
  intrinsic, as ``trans2bvh`` writes them). Its OFFSET is where it sits from its parent at rest, in world
  axes. A joint whose distance from its parent changes (a stretch) also gets position channels.
- Frames: keys 24 or more a second apart (the median step of the densest sampler) are a baked clip, read at
  that rate, a frame per key; sparser keyframes are sampled at 30 frames a second through the file's own
  interpolation. The clip runs from its earliest key to its last.
- Units and axes are the file's (glTF: metres, Y up); the retarget measures both from the figure.
- A file with several animations: ``animation`` picks one by name or index; the first by default.
"""

from __future__ import annotations

import base64
import struct
import urllib.parse
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from volanim_core.errors import FormatError
from volanim_core.io.bvh_files import MAX_JOINTS, MAX_VALUE, Motion
from volanim_core.io.clip_bake import ancestors as _ancestors
from volanim_core.io.clip_bake import bake_motion, frame_times, quaternion_matrices, sample_keys
from volanim_core.io.files import parse_json, regular_file_bytes
from volanim_core.limits import available_bytes, human_bytes

MAX_GLTF_BYTES = 1 << 30
_GLB_JSON, _GLB_BIN = 0x4E4F534A, 0x004E4942
_COMPONENTS = {5120: (np.int8, 127.0), 5121: (np.uint8, 255.0), 5122: (np.int16, 32767.0),
               5123: (np.uint16, 65535.0), 5125: (np.uint32, None), 5126: (np.float32, None)}
_WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}


@dataclass
class Gltf:
    """A parsed file: its JSON and its buffers' bytes."""

    path: Path
    doc: dict
    buffers: list[bytes]

    def fail(self, message: str) -> FormatError:
        return FormatError(self.path, message)

    def accessor(self, index) -> np.ndarray:
        """Accessor ``index`` as a float64 ``(count, width)`` array (normalized integers scaled to [-1, 1])."""
        acc = _item(self, "accessors", index)
        kind, width = acc.get("componentType"), _WIDTH.get(acc.get("type"))
        count = acc.get("count")
        if kind not in _COMPONENTS or width is None or not isinstance(count, int) or count < 1:
            raise self.fail(f"accessor {index}: componentType {kind!r}, type {acc.get('type')!r}, count {count!r} "
                            "is no accessor glTF 2.0 defines")
        if "sparse" in acc:
            raise self.fail(f"accessor {index} is sparse: sparse animation data is not read (export it dense)")
        dtype, norm = _COMPONENTS[kind]
        if "bufferView" not in acc:
            return np.zeros((count, width))
        view = _item(self, "bufferViews", acc["bufferView"])
        data = self.buffers[_index(self, "buffers", view.get("buffer"))]
        item = np.dtype(dtype).itemsize * width
        stride = view.get("byteStride") or item
        start = int(view.get("byteOffset", 0)) + int(acc.get("byteOffset", 0))
        end = start + stride * (count - 1) + item
        view_end = int(view.get("byteOffset", 0)) + int(view.get("byteLength", 0))
        if start < 0 or stride < item or end > min(view_end, len(data)):
            raise self.fail(f"accessor {index}: {count:,} values of {item} bytes from byte {start:,} run past its "
                            f"buffer view or buffer ({len(data):,} bytes): a truncated or damaged file")
        raw = np.lib.stride_tricks.as_strided(np.frombuffer(data, np.uint8, end - start, start),
                                              (count, item), (stride, 1))
        out = np.ascontiguousarray(raw).view(dtype).reshape(count, width).astype(np.float64)
        if norm is not None and acc.get("normalized"):
            out = np.maximum(out / norm, -1.0)
        if not np.isfinite(out).all() or not (np.abs(out) <= MAX_VALUE).all():
            raise self.fail(f"accessor {index} holds NaN, infinite or absurd values (over {MAX_VALUE:g})")
        return out


def _index(g: Gltf, what: str, index) -> int:
    items = g.doc.get(what)
    if not isinstance(index, int) or not isinstance(items, list) or not 0 <= index < len(items):
        raise g.fail(f"refers to {what[:-1]} {index!r}, which the file lacks ({len(items or [])} {what})")
    return index


def _item(g: Gltf, what: str, index) -> dict:
    item = g.doc[what][_index(g, what, index)]
    if not isinstance(item, dict):
        raise g.fail(f"{what[:-1]} {index} is not a JSON object")
    return item


def load_gltf(path: str | Path) -> Gltf:
    """The file's JSON and buffers: a ``.glb`` by its header, else JSON text; FormatError for a truncated
    GLB, a missing or short buffer, or what is no glTF 2.0."""
    path = Path(path)
    data = regular_file_bytes(path, MAX_GLTF_BYTES, "glTF file")
    chunk = None
    if data[:4] == b"glTF":
        if len(data) < 20:
            raise FormatError(path, f"a GLB file of {len(data)} bytes: truncated before its JSON chunk")
        version, length = struct.unpack_from("<II", data, 4)
        if length != len(data):
            raise FormatError(path, f"its GLB header says {length:,} bytes, the file has {len(data):,}: "
                                    f"{'truncated' if length > len(data) else 'bytes after its end'}")
        json_len, json_type = struct.unpack_from("<II", data, 12)
        if json_type != _GLB_JSON or 20 + json_len > len(data):
            raise FormatError(path, "its first GLB chunk is not a JSON chunk of the length it claims")
        text, rest = data[20:20 + json_len], 20 + json_len
        if rest + 8 <= len(data):
            bin_len, bin_type = struct.unpack_from("<II", data, rest)
            if bin_type == _GLB_BIN:
                if rest + 8 + bin_len > len(data):
                    raise FormatError(path, f"its BIN chunk claims {bin_len:,} bytes, the file holds "
                                            f"{len(data) - rest - 8:,}: truncated")
                chunk = data[rest + 8:rest + 8 + bin_len]
    else:
        text = data
    doc = parse_json(path, text)
    if not isinstance(doc, dict) or not str(doc.get("asset", {}).get("version", "")).startswith("2"):
        raise FormatError(path, "not a glTF 2.0 file (its asset.version must be 2.0)")
    g = Gltf(path, doc, [])
    for k, buf in enumerate(doc.get("buffers", [])):
        uri, size = buf.get("uri"), buf.get("byteLength", 0)
        if uri is None:
            if k != 0 or chunk is None:
                raise FormatError(path, f"buffer {k} has no uri and the file has no GLB BIN chunk")
            blob = chunk
        elif uri.startswith("data:"):
            try:
                blob = base64.b64decode(uri.split(",", 1)[1], validate=True)
            except (IndexError, ValueError):
                raise FormatError(path, f"buffer {k}: its data: URI is not base64") from None
        else:
            beside = path.parent / urllib.parse.unquote(uri)
            if not beside.is_file():
                raise FormatError(path, f"buffer {k}: its file {uri!r} is missing (it must lie beside the .gltf)")
            blob = regular_file_bytes(beside, MAX_GLTF_BYTES, "glTF buffer")
        if len(blob) < size:
            raise FormatError(path, f"buffer {k} ({uri or 'the BIN chunk'}) holds {len(blob):,} bytes of the "
                                    f"{size:,} it claims: truncated")
        g.buffers.append(blob)
    return g


def animation_names(g: Gltf) -> list[str]:
    """Each animation's name (``animation 2`` for one without)."""
    return [a.get("name") or f"animation {k}" for k, a in enumerate(g.doc.get("animations") or [])]


def _pick(g: Gltf, animation: str | int | None) -> tuple[str, dict]:
    names = animation_names(g)
    if not names:
        raise g.fail("has no animation: it holds a figure, not a clip")
    if animation is None:
        k = 0
    elif isinstance(animation, int) or str(animation).isdigit():
        k = int(animation)
    else:
        k = names.index(animation) if animation in names else -1
    if not 0 <= k < len(names):
        raise g.fail(f"has no animation {animation!r}; it has {', '.join(names)}")
    return names[k], g.doc["animations"][k]


def _parents(g: Gltf) -> np.ndarray:
    nodes = g.doc.get("nodes") or []
    parent = np.full(len(nodes), -1)
    for k, node in enumerate(nodes):
        for c in node.get("children", []):
            _index(g, "nodes", c)
            if parent[c] != -1 or c == k:
                raise g.fail(f"node {c} has two parents or is its own: the nodes must form trees")
            parent[c] = k
    for k in range(len(nodes)):  # a cycle never reaches a root
        seen, j = 0, k
        while j >= 0 and seen <= len(nodes):
            j, seen = parent[j], seen + 1
        if seen > len(nodes):
            raise g.fail(f"node {k} is in a cycle of children: the nodes must form trees")
    return parent


def _joints(g: Gltf, anim: dict, parent: np.ndarray) -> list[int]:
    """The clip's joints as node indices, one tree, parents first."""
    targets = {c.get("target", {}).get("node") for c in anim.get("channels", [])} - {None}
    skins = g.doc.get("skins") or []
    vrm = (g.doc.get("extensions") or {}).get("VRMC_vrm_animation", {}).get("humanoid", {}).get("humanBones")
    if skins:
        joints = set(max(skins, key=lambda s: len(targets & set(s.get("joints", [])))).get("joints", []))
    elif vrm:
        joints = {b.get("node") for b in vrm.values()}
    else:  # the tree (under a top-level node) holding most of the animated nodes, whole
        top = [(_ancestors(parent, t) or [t])[-1] for t in targets]
        root = max(set(top), key=top.count) if top else None
        joints = {n for n in range(len(parent)) if root is not None and (n == root or root in _ancestors(parent, n))}
    for j in joints:
        _index(g, "nodes", j)
    roots = [j for j in joints if not set(_ancestors(parent, j)) & joints]
    if len(roots) > 1:  # their lowest common ancestor holds them
        common = set(_ancestors(parent, roots[0])).intersection(*(_ancestors(parent, r) for r in roots[1:]))
        if not common:
            raise g.fail(f"the clip's joints form {len(roots)} separate trees with no common node")
        joints.add(max(common, key=lambda a: len(_ancestors(parent, a))))
    if not 0 < len(joints) <= MAX_JOINTS:
        raise g.fail(f"{len(joints)} joints: a clip has 1..{MAX_JOINTS}")
    order = sorted(joints, key=lambda j: (len(_ancestors(parent, j)), j))  # depth first: parents before children
    return order


def _times(g: Gltf, anim: dict) -> tuple[np.ndarray, float]:
    """The frames' times and rate (see the module's "Decided here")."""
    inputs = [g.accessor(s.get("input"))[:, 0] for s in anim.get("samplers", [])]
    if not inputs:
        raise g.fail("its animation has no samplers")
    return frame_times(inputs, g.fail)


def _sample(g: Gltf, sampler: dict, times: np.ndarray, rotation: bool) -> np.ndarray:
    t = g.accessor(sampler.get("input"))[:, 0]
    v = g.accessor(sampler.get("output"))
    how = sampler.get("interpolation", "LINEAR")
    cubic = how == "CUBICSPLINE"
    if how not in ("LINEAR", "STEP", "CUBICSPLINE") or len(v) != len(t) * (3 if cubic else 1):
        raise g.fail(f"a sampler ({how}) has {len(t)} key times and {len(v)} values")
    tangent_in, v, tangent_out = (v[0::3], v[1::3], v[2::3]) if cubic else (None, v, None)
    return sample_keys(t, v, times, how, rotation, tangent_in, tangent_out)


def _rest_local(g: Gltf, node: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray] | np.ndarray:
    if "matrix" in node:
        m = np.asarray(node["matrix"], np.float64)
        if m.shape != (16,):
            raise g.fail("a node's matrix must hold 16 numbers")
        return m.reshape(4, 4).T  # column-major
    t = np.asarray(node.get("translation", [0, 0, 0]), np.float64)
    r = np.asarray(node.get("rotation", [0, 0, 0, 1]), np.float64)
    s = np.asarray(node.get("scale", [1, 1, 1]), np.float64)
    if t.shape != (3,) or r.shape != (4,) or s.shape != (3,):
        raise g.fail("a node's translation, rotation and scale must hold 3, 4 and 3 numbers")
    return t, r, s


def _locals(g: Gltf, anim: dict, nodes: list[int], times: np.ndarray | None) -> np.ndarray:
    """``(F, len(nodes), 4, 4)`` local matrices at ``times`` (None: the rest pose, one frame)."""
    n_frames = 1 if times is None else len(times)
    need = n_frames * len(nodes) * 16 * 8 * 4
    free = available_bytes()
    if free is not None and need > free:
        raise g.fail(f"{n_frames:,} frames of {len(nodes)} nodes need {human_bytes(need)}, more than the memory free")
    where = {n: k for k, n in enumerate(nodes)}
    trs = {}
    for k, n in enumerate(nodes):
        rest = _rest_local(g, g.doc["nodes"][n])
        trs[k] = [np.tile(p, (n_frames, 1)) for p in rest] if isinstance(rest, tuple) else rest
    if times is not None:
        samplers = anim.get("samplers", [])
        for c in anim.get("channels", []):
            target = c.get("target", {})
            k, path = where.get(target.get("node")), target.get("path")
            if k is None or path not in ("translation", "rotation", "scale"):
                continue  # another node's, or morph weights
            if not isinstance(trs[k], list):
                raise g.fail(f"node {nodes[k]} is animated but has a matrix (glTF allows TRS only there)")
            value = _sample(g, samplers[_pick_sampler(g, samplers, c.get("sampler"))], times, path == "rotation")
            if value.shape[1] != (4 if path == "rotation" else 3):
                raise g.fail(f"a {path} channel's values have {value.shape[1]} components")
            trs[k][("translation", "rotation", "scale").index(path)] = value
    out = np.zeros((n_frames, len(nodes), 4, 4))
    for k, m in trs.items():
        if isinstance(m, list):
            t, r, s = m
            try:
                out[:, k, :3, :3] = quaternion_matrices(r) * s[:, None, :]
            except ValueError as exc:
                raise g.fail(f"node {nodes[k]}: {exc}") from None
            out[:, k, :3, 3] = t
            out[:, k, 3, 3] = 1.0
        else:
            out[:, k] = m
    return out


def _pick_sampler(g: Gltf, samplers: list, index) -> int:
    if not isinstance(index, int) or not 0 <= index < len(samplers):
        raise g.fail(f"a channel names sampler {index!r}; its animation has {len(samplers)}")
    return index


def _world(parent: np.ndarray, nodes: list[int], local: np.ndarray) -> np.ndarray:
    where = {n: k for k, n in enumerate(nodes)}
    world = np.empty_like(local)
    for k, n in enumerate(nodes):  # ancestors come first
        p = where.get(parent[n])
        world[:, k] = local[:, k] if p is None else world[:, p] @ local[:, k]
    return world


def read_gltf(path: str | Path, animation: str | int | None = None) -> Motion:
    """One animation of a glTF 2.0 file as a :class:`Motion` (see the module's "Decided here"); FormatError
    naming the file for anything it cannot read."""
    g = load_gltf(path)
    name, anim = _pick(g, animation)
    parent = _parents(g)
    joints = _joints(g, anim, parent)
    nodes = sorted({a for j in joints for a in _ancestors(parent, j)} | set(joints),
                   key=lambda n: (len(_ancestors(parent, n)), n))
    times, rate = _times(g, anim)
    pick = [nodes.index(j) for j in joints]
    rest = _world(parent, nodes, _locals(g, anim, nodes, None))[:, pick]
    world = _world(parent, nodes, _locals(g, anim, nodes, times))[:, pick]
    jparent = [next((joints.index(a) for a in _ancestors(parent, j) if a in joints), -1) for j in joints]
    names = [g.doc["nodes"][j].get("name") or f"node{j}" for j in joints]
    try:
        return bake_motion(names, jparent, rest[0], world, rate, name)
    except ValueError as exc:
        raise g.fail(f"animation {name!r}: {exc}") from None
