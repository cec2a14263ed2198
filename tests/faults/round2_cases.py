"""Fault cases of the second round (#38) besides sequence stores: meshes, project values, BVH values,
a ``.tskel`` matrix cut short, a huge transfer function and hostile sizes given to the command line."""

from __future__ import annotations

import struct

import numpy as np

from paths import ASSETS

from .cases import BONES, BVH, IDENTITY, Case

MANNEQUIN_BONES = ASSETS / "mannequin.bones"

PLY_HEAD = "ply\nformat {fmt} 1.0\nelement vertex {n}\nproperty float x\nproperty float y\nproperty float z\n"


def ply_ascii(faces: str, n: int = 4, vertices: str | None = None, n_faces: int = 1) -> bytes:
    verts = vertices if vertices is not None else "0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
    head = PLY_HEAD.format(fmt="ascii", n=n) + (f"element face {n_faces}\nproperty list uchar int vertex_indices\n"
                                                if n_faces else "") + "end_header\n"
    return (head + verts + faces).encode()


def ply_binary(count: int, indices: list[int], count_type: str = "I", n_faces: int = 1) -> bytes:
    head = (PLY_HEAD.format(fmt="binary_little_endian", n=4) + f"element face {n_faces}\n"
            f"property list {'uint' if count_type == 'I' else 'uchar'} int vertex_indices\nend_header\n").encode()
    verts = struct.pack("<12f", 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1)
    return head + verts + struct.pack("<" + count_type, count) + struct.pack(f"<{len(indices)}i", *indices)


def mesh_cases() -> list[Case]:
    def case(name, files, arg, expect="refuse", check=None):
        return Case(f"mesh: {name}", "read_mesh", files, arg, expect, check)

    return [
        case("a PLY face naming vertex 99999999 of 4", {"m.ply": ply_ascii("3 0 1 99999999\n")}, "m.ply"),
        case("a PLY face with a negative index", {"m.ply": ply_ascii("3 0 -1 2\n")}, "m.ply"),
        case("a binary PLY face list count of 2^32-1", {"m.ply": ply_binary(2**32 - 1, [0, 1, 2])}, "m.ply"),
        case("a binary PLY face naming vertex 99999999", {"m.ply": ply_binary(3, [0, 1, 99999999], "B")}, "m.ply"),
        case("a PLY claiming 3000 vertices holding 4 (padded with a comment)",
             {"m.ply": ply_ascii("3 0 1 2\n", n=3000).replace(b"end_header", b"comment " + b"x" * 40000 +
                                                              b"\nend_header")}, "m.ply"),
        case("an ASCII PLY face of words", {"m.ply": ply_ascii("three a b c\n")}, "m.ply"),
        case("an ASCII PLY face list count of NaN", {"m.ply": ply_ascii("nan 0 1 2\n")}, "m.ply"),
        case("a PLY without faces", {"m.ply": ply_ascii("", n_faces=0)}, "m.ply"),
        case("an OBJ of vertices only", {"m.obj": b"v 0 0 0\nv 1 0 0\nv 0 1 0\n"}, "m.obj"),
        case("an OBJ face naming vertex 99999999", {"m.obj": b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999\n"},
             "m.obj"),
        case("an OBJ face with a negative index past the start", {"m.obj": b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -9\n"},
             "m.obj"),
        case("one OBJ face of 900 000 corners",
             {"m.obj": b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf " + b"1 2 3 " * 300_000 + b"\n"}, "m.obj"),
        case("a valid OBJ with relative indices", {"m.obj": b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf -4 -3 -2\n"
                                                            b"f 1/1 2/2 4/4\n"}, "m.obj", "accept", "two_cells"),
        case("a valid ASCII PLY", {"m.ply": ply_ascii("3 0 1 2\n")}, "m.ply", "accept", "one_cell"),
        case("a valid binary PLY", {"m.ply": ply_binary(3, [0, 1, 3], "B")}, "m.ply", "accept", "one_cell"),
        Case("view: a PLY face naming vertex 99999999", "cli:view", {"m.ply": ply_ascii("3 0 1 99999999\n")},
             "view {d}/m.ply --screenshot {d}/o.png --size 64x48"),
    ]


def project_cases() -> list[Case]:
    big = "9" * 401
    cases = []
    for key, text in (("an angle", '"pose": {"angles": [["A", "B", BIG, 0, 0]]}'), ("the thinness", '"thinness": BIG'),
                      ("a segmentation value", '"segmentation": {"lo": BIG}'),
                      ("a key's frame length", '"timeline": {"length": BIG}')):
        body = ('{"format": "volanim project", ' + text.replace("BIG", big) + "}").encode()
        cases.append(Case(f"project: a 401-digit number for {key}", "read_project", {"p.volanim": body}, "p.volanim"))
    cases.append(Case("project: NaN for the thinness", "read_project",
                      {"p.volanim": b'{"format": "volanim project", "thinness": NaN}'}, "p.volanim"))
    cases.append(Case("project: bones named /dev/zero", "open_project",
                      {"p.volanim": b'{"format": "volanim project", "version": 3, "bones": "/dev/zero"}'}, "p.volanim"))
    # a clip that cannot be loaded opens the project with a warning (the clip is referenced, not part of it)
    cases.append(Case("project: a clip named /dev/zero (a warning)", "open_project",
                      {"p.volanim": b'{"format": "volanim project", "version": 3, "bones": "m.bones", "timeline": '
                                    b'{"clip": {"kind": "bvh", "path": "/dev/zero"}}}', "m.bones": BONES.encode()},
                      "p.volanim", "accept", "warns_dev_zero"))
    return cases


def bvh_cases() -> list[Case]:
    def motion(values: str) -> bytes:
        return BVH.replace("0 0 0 0 0 0 0 0 0\n", values + "\n").encode()

    return [
        Case("bvh: NaN in a channel", "read_bvh", {"m.bvh": motion("0 0 0 nan 0 0 0 0 0")}, "m.bvh"),
        Case("bvh: a 1e308 position", "read_bvh", {"m.bvh": motion("1e308 0 0 0 0 0 0 0 0")}, "m.bvh"),
        Case("bvh: a 1e308 rotation", "read_bvh", {"m.bvh": motion("0 0 0 1e308 0 0 0 0 0")}, "m.bvh"),
        Case("bvh: a 1e300 offset", "read_bvh", {"m.bvh": BVH.replace("OFFSET 0 10 0", "OFFSET 0 1e300 0").encode()},
             "m.bvh"),
        Case("bvh: a NUL byte in a joint name", "read_bvh", {"m.bvh": BVH.replace("JOINT Arm", "JOINT A\0rm").encode()},
             "m.bvh"),
        Case("bvh2trans: a 1e20 root displacement", "cli:bvh2trans",
             {"m.bvh": motion("1e20 0 0 0 0 0 0 0 0"), "m.bones": MANNEQUIN_BONES.read_bytes()},
             "bvh2trans {d}/m.bvh --bones {d}/m.bones -o {d}/out"),
    ]


def tskel_cases() -> list[Case]:
    three_rows = "\n".join(IDENTITY.splitlines()[:3]) + "\n"
    text = f"# metric: euclid\nRoot: 0 0 0 :: 0 0 10\n{three_rows}10 10 10 3 0.9\n11 10 10 2.5 0.7\n"
    counted = (f"# volanim tskel 1\n# points: 2\nRoot: 0 0 0 :: 0 0 10\n{three_rows}"
               "10 10 10 1\n11 10 10 2.5\n")
    return [Case("tskel: a 3-row matrix followed by a point line", "read_tskel", {"m.tskel": text.encode()},
                 "m.tskel"),
            Case("tskel: a 3-row matrix followed by a point of dt 1, counted", "read_tskel",
                 {"m.tskel": counted.encode()}, "m.tskel")]


def tf_cases() -> list[Case]:
    rows = "".join(f"{i * 255 / 99_999:.6f} 0.5 0.5 0.5 0.1\n" for i in range(100_000))
    return [Case("tf: 100 000 points", "read_transfer_function", {"m.tf": ("# volanim tf 1\n" + rows).encode()},
                 "m.tf")]


def png(pixels: np.ndarray, mode: str) -> bytes:
    from io import BytesIO

    from PIL import Image

    out = BytesIO()
    Image.fromarray(pixels, mode).save(out, format="PNG")
    return out.getvalue()


def alpha_cases() -> list[Case]:
    rgba = np.full((6, 5, 4), 200, np.uint8)
    rgba[0, 0, 3] = 0  # one pixel masked out, its colour left as painted
    la = np.full((4, 5, 2), 200, np.uint8)
    la[..., 1] = 128
    return [Case("slices: RGBA with a transparent pixel", "read_volume",
                 {"s/a0.png": png(rgba, "RGBA"), "s/a1.png": png(rgba, "RGBA")}, "s"),
            Case("slices: grey+alpha half transparent, 4 rows high", "read_volume",
                 {"s/a0.png": png(la, "LA"), "s/a1.png": png(la, "LA")}, "s")]


def round2_cases() -> list[Case]:
    return mesh_cases() + project_cases() + bvh_cases() + tskel_cases() + tf_cases() + alpha_cases()
