"""Fault cases of the fifth round (#88): glTF and FBX clips (and, #86, a glTF file's surface to voxelize).
A truncated GLB, a buffer file that is not there, NaN
keys, a count of keys the buffer does not hold, key times that span years, nodes that loop, a file with no
animation; FBX files cut short, empty (assimp aborts the process on it: refused before assimp sees it) and
holding a box but no skeleton. Real bytes where they exist: Khronos' Fox and assimp's huesitos cut short,
assimp's box; the rest are small glTF documents written here, as exporters write them."""

from __future__ import annotations

from paths import ASSETS, FBX, FOX, HUESITOS
from written_clips import tiny_gltf as gltf

from .cases import Case


def round5_cases() -> list[Case]:
    fox, huesitos = FOX.read_bytes(), HUESITOS.read_bytes()
    bones = (ASSETS / "mannequin.bones").read_bytes()
    loop = [{"name": "a", "children": [1]}, {"name": "b", "children": [0]}]

    def clip(name, data, says=(), expect="refuse", check=None, file="c.gltf"):
        return Case(f"gltf: {name}", "read_clip", {file: data}, file, expect, check, says=says)

    return [
        clip("a GLB cut short", fox[:100_000], ("truncated",), file="Fox.glb"),
        clip("a GLB whose header claims more", fox[:12].replace(fox[8:12], (10**9).to_bytes(4, "little")) + fox[12:],
             ("header says 1,000,000,000 bytes",), file="Fox.glb"),
        clip("a buffer file that is not there", gltf(buffers=[{"byteLength": 44, "uri": "wave.bin"}]),
             ("'wave.bin' is missing",)),
        clip("NaN keys", gltf(quats=((0, 0, 0, 1), (0, 0, float("nan"), 1))), ("NaN",)),
        clip("10^9 keys claimed", gltf(count=10**9), ("run past",)),
        clip("key times over 30 years", gltf(times=(0.0, 1e9)), ("are its key times in seconds",)),
        clip("key times that go back", gltf(times=(1.0, 0.0)), ("do not increase",)),
        clip("nodes that are each other's child", gltf(nodes=loop), ("cycle of children",)),
        clip("no animation", gltf(animations=[]), ("has no animation",)),
        clip("a zero quaternion", gltf(quats=((0, 0, 0, 0), (0, 0, 0, 1))), ("zero quaternion",)),
        clip("an arm turned 90 degrees", gltf(), expect="accept", check="gltf_arm_turned"),
        Case("fbx: a file cut short", "read_clip", {"c.fbx": huesitos[:60_000]}, "c.fbx",
             says=("assimp can read: FBX-Tokenize",)),
        Case("fbx: its magic only", "read_clip", {"c.fbx": b"Kaydara FBX Binary  \x00"}, "c.fbx",
             says=("assimp can read",)),
        Case("fbx: an empty file (assimp aborts the process on it)", "read_clip", {"c.fbx": b""}, "c.fbx",
             says=("is no FBX file (0 bytes)",)),
        Case("fbx: a box with no skeleton", "read_clip", {"c.fbx": (FBX / "box.fbx").read_bytes()}, "c.fbx",
             says=("no skeleton",)),
        Case("bvh2trans: an FBX cut short", "cli:bvh2trans", {"c.fbx": huesitos[:60_000], "m.bones": bones},
             "bvh2trans {d}/c.fbx --bones {d}/m.bones -o {d}/out", says=("FBX-Tokenize",)),
        Case("bvh2trans: a GLB cut short", "cli:bvh2trans", {"Fox.glb": fox[:100_000], "m.bones": bones},
             "bvh2trans {d}/Fox.glb --bones {d}/m.bones -o {d}/out", says=("truncated",)),
        *voxelize_cases(fox, loop),
    ]


def voxelize_cases(fox: bytes, loop: list) -> list[Case]:
    """A glTF file's surface to fill (#86, io/gltf_meshes.py): the clip reader's checks, and a file with no mesh."""
    def case(name, data, says, file="m.gltf"):
        return Case(f"voxelize: {name}", "cli:voxelize", {file: data}, f"voxelize {{d}}/{file} {{d}}/o.nrrd", says=says)

    return [case("a GLB cut short", fox[:100_000], ("truncated",), file="Fox.glb"),
            case("a GLB whose header claims more", fox[:8] + (10**9).to_bytes(4, "little") + fox[12:],
                 ("header says 1,000,000,000 bytes",), file="Fox.glb"),
            case("a glTF clip with no mesh", gltf(), ("holds no triangles",)),
            case("nodes that are each other's child", gltf(nodes=loop), ("cycle of children",))]
