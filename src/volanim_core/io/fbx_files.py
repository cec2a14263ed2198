"""FBX clips (``.fbx``, binary or ASCII, as Mixamo, Unity, Maya and Blender write them): a skeleton and one of
its animations, read as a :class:`Motion` through the Open Asset Import Library, so everything that takes a
BVH or glTF clip takes them.

    .fbx bytes (checked: a regular file, at most 1 GiB)
      --assimp (impasse)--> node tree, each node's rest local matrix; animations: per node, position,
                            rotation and scaling keys in ticks
      --joints-----> the skin's bones and the animated nodes, closed to one tree under their common ancestor
                     (assimp's ``NAME_$AssimpFbx$_Rotation``-style pivot helpers fold into NAME)
      --sample-----> every node's local matrix at the clip's frames (clip_bake.frame_times, linear keys,
                     quaternions slerped), composed to world matrices
      --bake-------> clip_bake.bake_motion: a Motion whose rest is the file's rest pose

**Decided here** (docs/formats.md, FBX clips):

- The binding: impasse (cffi bindings of assimp's C API, BSD, kept for Python 3, type-hinted) over the
  Debian/Ubuntu library ``libassimp5``. pyassimp 5.2.5, the official port, fails on this very library
  (a NULL pointer reading a skinned mesh's bones); assimp-py's wheels bundle assimp but expose no animation.
- Key times are ticks; seconds are ticks over the animation's ticks a second (25 where the file says 0, as
  assimp's own viewer does). The frame rule is glTF's (clip_bake.frame_times).
- Units: FBX keeps its unit in ``UnitScaleFactor`` (centimetres a unit; 1 by default); positions are read in
  metres (times UnitScaleFactor / 100), as glTF's are. Axes stay the file's: the retarget measures up and
  size from the figure.
- A file with several animations: ``animation`` picks one by name or index; the first by default.
"""

from __future__ import annotations

import ctypes
import io
from pathlib import Path

import numpy as np

from volanim_core.errors import FormatError
from volanim_core.io.bvh_files import MAX_JOINTS, MAX_VALUE, Motion
from volanim_core.io.clip_bake import ancestors as _ancestors
from volanim_core.io.clip_bake import bake_motion, frame_times, quaternion_matrices, sample_keys
from volanim_core.io.files import regular_file_bytes
from volanim_core.limits import available_bytes, human_bytes

MAX_FBX_BYTES = 1 << 30
DEFAULT_TICKS = 25.0
HELPER = "_$AssimpFbx$_"
BINARY_MAGIC = b"Kaydara FBX Binary  \x00"
INSTALL = "reading FBX needs the Open Asset Import Library: sudo apt-get install libassimp5 (Debian, Ubuntu)"


def _assimp():
    """impasse, or FormatError-free ImportError saying how to install assimp."""
    try:
        import impasse
        from impasse.errors import AssimpError
    except (ImportError, OSError) as exc:
        raise ImportError(f"{INSTALL} ({exc})") from None
    except BaseException as exc:  # impasse raises AssimpError (a BaseException) when it finds no library
        if type(exc).__name__ != "AssimpError":
            raise
        raise ImportError(INSTALL) from None
    return impasse, AssimpError


def _error_string() -> str:
    """assimp's own reason for the last failed import (impasse says only 'Could not import file!')."""
    try:
        lib = ctypes.CDLL("libassimp.so.5")
        lib.aiGetErrorString.restype = ctypes.c_char_p
        return (lib.aiGetErrorString() or b"").decode("utf-8", "replace")
    except (OSError, AttributeError):
        return ""


def load_fbx(path: str | Path):
    """The assimp scene of an FBX file; FormatError naming the file, with assimp's reason, when it cannot."""
    path = Path(path)
    data = regular_file_bytes(path, MAX_FBX_BYTES, "FBX file")
    if not (data.startswith(BINARY_MAGIC) or b"FBXHeaderExtension" in data[:4096]):
        # assimp aborts the process on some bytes that are no FBX at all (an empty file): never hand it those
        raise FormatError(path, f"is no FBX file ({len(data):,} bytes): it starts with neither "
                                "'Kaydara FBX Binary' nor an ASCII FBX header")
    impasse, assimp_error = _assimp()
    try:
        return impasse.load(io.BytesIO(data), file_type="fbx", processing=0)
    except assimp_error:
        reason = _error_string() or "assimp cannot read it"
        raise FormatError(path, f"is no FBX file assimp can read: {reason}") from None


def animation_names(scene) -> list[str]:
    return [a.name or f"animation {k}" for k, a in enumerate(scene.animations)]


def _tree(scene) -> tuple[list[str], list[int], np.ndarray]:
    """Every node, parents first: names, parent indices, rest local matrices ``(N, 4, 4)``."""
    names, parent, local = [], [], []
    stack = [(scene.root_node, -1)]
    while stack:
        node, p = stack.pop()
        names.append(node.name)
        parent.append(p)
        local.append(np.asarray(node.transformation, np.float64))
        stack += [(c, len(names) - 1) for c in reversed(node.children)]
    return names, parent, np.asarray(local)


def _owner(name: str) -> str:
    return name.split(HELPER)[0]


def _joints(path: Path, scene, anim, names: list[str], parent: list[int]) -> list[int]:
    """The clip's joints as node indices, one tree, parents first; pivot helpers are no joints."""
    real = {n: k for k, n in enumerate(names) if HELPER not in n}
    animated = {_owner(c.node_name) for c in anim.channels} & set(real)
    skinned = {b.name for m in scene.meshes for b in m.bones} & set(real)
    if skinned:
        joints = {real[n] for n in skinned | animated}
    else:  # the tree (under a top-level node) holding most of the animated nodes, whole
        top = [(_ancestors(parent, real[n])[-2:-1] or [real[n]])[0] for n in animated]
        root = max(set(top), key=top.count) if top else None
        joints = {k for k in real.values() if root is not None and (k == root or root in _ancestors(parent, k))}
    if not joints:
        raise FormatError(path, "has no skeleton: no skinned bones and no animated node")
    roots = [j for j in joints if not set(_ancestors(parent, j)) & joints]
    if len(roots) > 1:  # their lowest real common ancestor holds them
        common = set(_ancestors(parent, roots[0])).intersection(*(_ancestors(parent, r) for r in roots[1:]))
        common = [a for a in common if HELPER not in names[a]]
        joints.add(max(common, key=lambda a: len(_ancestors(parent, a))))
    if len(joints) > MAX_JOINTS:
        raise FormatError(path, f"{len(joints):,} joints: a clip has 1..{MAX_JOINTS:,}")
    return sorted(joints)  # _tree lists parents first


def _locals(path: Path, anim, names: list[str], rest: np.ndarray, times: np.ndarray, tps: float) -> np.ndarray:
    """``(F, N, 4, 4)`` local matrices at ``times``: an animated node's keys replace its rest transform."""
    need = len(times) * len(names) * 16 * 8 * 3
    free = available_bytes()
    if free is not None and need > free:
        raise FormatError(path, f"{len(times):,} frames of {len(names)} nodes need {human_bytes(need)}, "
                                "more than the memory free")
    out = np.repeat(rest[None], len(times), 0)
    where = {n: k for k, n in enumerate(names)}
    for c in anim.channels:
        k = where.get(c.node_name)
        if k is None:
            continue
        t, r, s = (_keys(path, c.node_name, keys, width, tps)
                   for keys, width in ((c.position_keys, 3), (c.rotation_keys, 4), (c.scaling_keys, 3)))
        rot = sample_keys(r[0], r[1][:, [1, 2, 3, 0]], times, rotation=True)  # assimp: (w, x, y, z)
        try:
            out[:, k, :3, :3] = quaternion_matrices(rot) * sample_keys(s[0], s[1], times)[:, None, :]
        except ValueError as exc:
            raise FormatError(path, f"node {c.node_name!r}: {exc}") from None
        out[:, k, :3, 3] = sample_keys(t[0], t[1], times)
    return out


def _keys(path: Path, node: str, keys, width: int, tps: float) -> tuple[np.ndarray, np.ndarray]:
    """One channel's key times (seconds) and values, checked."""
    if len(keys) == 0:
        raise FormatError(path, f"node {node!r} is animated with no keys")
    t = np.array([k.time for k in keys], np.float64) / tps
    v = np.array([np.asarray(k.value, np.float64).reshape(-1)[:width] for k in keys])
    if not (np.isfinite(t).all() and np.isfinite(v).all() and (np.abs(v) <= MAX_VALUE).all()):
        raise FormatError(path, f"node {node!r} has NaN, infinite or absurd keys (over {MAX_VALUE:g})")
    if len(t) > 1 and not (np.diff(t) > 0).all():
        raise FormatError(path, f"node {node!r}: its key times do not increase")
    return t, v


def _world(parent: list[int], local: np.ndarray) -> np.ndarray:
    world = np.empty_like(local)
    for k, p in enumerate(parent):  # parents come first
        world[:, k] = local[:, k] if p < 0 else world[:, p] @ local[:, k]
    return world


def _unit(scene) -> float:
    """Metres a file unit (FBX: UnitScaleFactor centimetres)."""
    try:
        factor = float(dict(scene.metadata).get("UnitScaleFactor", 1.0))
    except (TypeError, ValueError):
        factor = 1.0
    return factor / 100.0 if np.isfinite(factor) and factor > 0 else 0.01


def read_fbx(path: str | Path, animation: str | int | None = None) -> Motion:
    """One animation of an FBX file as a :class:`Motion` (see the module's "Decided here"); FormatError
    naming the file for anything it cannot read."""
    path = Path(path)
    scene = load_fbx(path)
    names_all = animation_names(scene)
    if not names_all:
        raise FormatError(path, "has no animation and no skeleton moves in it: it holds a figure, not a clip")
    k = 0 if animation is None else (int(animation) if str(animation).isdigit() else
                                     names_all.index(animation) if animation in names_all else -1)
    if not 0 <= k < len(names_all):
        raise FormatError(path, f"has no animation {animation!r}; it has {', '.join(names_all)}")
    anim = scene.animations[k]
    tps = float(anim.ticks_per_second) or DEFAULT_TICKS
    names, parent, rest_local = _tree(scene)
    joints = _joints(path, scene, anim, names, parent)
    key_times = [_keys(path, c.node_name, keys, 3, tps)[0] for c in anim.channels
                 for keys in (c.position_keys, c.rotation_keys, c.scaling_keys) if len(keys)]
    times, rate = frame_times(key_times, lambda message: FormatError(path, message))
    rest = _world(parent, rest_local[None])[0, joints]
    world = _world(parent, _locals(path, anim, names, rest_local, times, tps))[:, joints]
    unit = _unit(scene)
    rest[:, :3, 3] *= unit
    world[..., :3, 3] *= unit
    jparent = [next((joints.index(a) for a in _ancestors(parent, j) if a in joints), -1) for j in joints]
    try:
        return bake_motion([names[j] for j in joints], jparent, rest, world, rate, names_all[k])
    except ValueError as exc:
        raise FormatError(path, f"animation {names_all[k]!r}: {exc}") from None
