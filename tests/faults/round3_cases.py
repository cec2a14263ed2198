"""Fault cases of the third round (#64): the inputs added since round two (Slicer markups, keys, joint
positions, C3D, DICOM series, meshes to voxelize), symlink loops, and the library's own constructors
given what their files refuse. Built as the corpus builds cases: valid files of each kind, then
broken one way each (real files where we have them: ezc3d's Qualisys.c3d, a series pydicom writes)."""

from __future__ import annotations

import io as stdio
import json
import struct
import tempfile
import warnings
from pathlib import Path

import numpy as np

from paths import REPO

from .cases import Case
from .round2_cases import MANNEQUIN_BONES, PLY_HEAD

QUALISYS = REPO / "tests" / "data" / "c3d" / "Qualisys.c3d"


def _markups(points) -> bytes:
    return json.dumps({"markups": [{"type": "Fiducial", "coordinateSystem": "LPS", "controlPoints": points}]}).encode()


def _point(label, position):
    return {"label": label, "position": position, "positionStatus": "defined"}


def markups_cases() -> list[Case]:
    def case(name, data, expect="refuse", check=None):
        return Case(f"markups: {name}", "read_markups", {"m.mrk.json": data}, "m.mrk.json", expect, check)

    good = [_point("A", [0, 0, 0]), _point("B", [0, 0, 10])]
    return [
        case("controlPoints is a number", json.dumps({"markups": [{"type": "Fiducial", "controlPoints": 7}]}).encode()),
        case("a position of 1e308", _markups([_point("A", [0, 0, 0]), _point("B", [0, 0, 1e308])])),
        case("a position of 1e400 (infinity in JSON)", _markups(good).replace(b"10]", b"1e400]")),
        case("a position of strings", _markups([_point("A", ["0", "0", "0"]), _point("B", [0, 0, 10])])),
        case("a control point that is a list", _markups([[0, 0, 0], _point("B", [0, 0, 10])])),
        case("markups is an object", json.dumps({"markups": {"type": "Fiducial"}}).encode()),
        case("a label of two words", _markups([_point("A B", [0, 0, 0]), _point("C", [0, 0, 10])])),
        case("two joints, one bone", _markups(good), "accept", "one_bone"),
    ]


KEYS_HEAD = "# volanim keys 1\n"


def keys_cases() -> list[Case]:
    def case(name, text):
        return Case(f"keys: {name}", "cli:keys", {"m.keys": text.encode(), "m.bones": MANNEQUIN_BONES.read_bytes()},
                    "keys {d}/m.keys --bones {d}/m.bones -o {d}/out")

    return [case("length 100000", KEYS_HEAD + "length 100000\n0 SPINE 0 0 0\n10 SPINE 0 0 30\n"),
            case("length 10001", KEYS_HEAD + "length 10001\n0 SPINE 0 0 0\n"),
            Case("keys: --length 100000 on the command line", "cli:keys",
                 {"m.keys": (KEYS_HEAD + "0 SPINE 0 0 0\n").encode(), "m.bones": MANNEQUIN_BONES.read_bytes()},
                 "keys {d}/m.keys --bones {d}/m.bones --length 100000 -o {d}/out")]


JOINTS = ("PELVIS", "NECK", "HEAD", "L_SHOULDER", "L_ELBOW")


def positions_cases() -> list[Case]:
    def rows(frame=0, value="1", same=False):
        out = ["frame,joint,x,y,z"]
        for k, j in enumerate(JOINTS):
            out.append(f"{frame},{j},{value if k == 1 else 0},{0 if same else k * 10},{0 if same else 100 + k}")
        return "\n".join(out) + "\n"

    def case(name, text):
        return Case(f"positions: {name}", "cli:positions2trans",
                    {"p.csv": text.encode(), "m.bones": MANNEQUIN_BONES.read_bytes()},
                    "positions2trans {d}/p.csv --bones {d}/m.bones -o {d}/out")

    return [case("a position of 1e20", rows(value="1e20")), case("a position of 1e308", rows(value="1e308")),
            case("a frame number of 10^23", rows(frame="100000000000000000000000")),
            case("every joint at one place", rows(value="0", same=True)),
            case("a negative frame", rows(frame="-5")),
            case("one joint only", "frame,joint,x,y,z\n0,PELVIS,0,0,100\n1,PELVIS,0,5,100\n")]


def _c3d(mutate) -> bytes:
    data = bytearray(QUALISYS.read_bytes())
    mutate(data)
    return bytes(data)


def c3d_cases() -> list[Case]:
    head = np.frombuffer(QUALISYS.read_bytes()[:24], "<u2")
    start = (int(head[8]) - 1) * 512  # the first frame's first marker's x (float32)

    def case(name, data, expect="refuse", check=None):
        return Case(f"c3d: {name}", "read_c3d", {"m.c3d": data}, "m.c3d", expect, check)

    def counts(points, last):
        def mutate(d):
            d[2:4] = struct.pack("<H", points)
            d[8:10] = struct.pack("<H", last)
        return mutate

    def marker(value):
        def mutate(d):
            d[start:start + 4] = struct.pack("<f", value)
        return mutate

    whole = QUALISYS.read_bytes()
    return [
        case("truncated in its data", whole[: len(whole) * 3 // 5]),
        case("header counts 32767 points, last frame 65535, of a truncated file", _c3d(counts(32767, 65535))[:150_000]),
        case("a header block only", whole[:512]),
        case("a marker at +inf reads as missing", _c3d(marker(float("inf"))), "accept", "c3d_first_marker_missing"),
        case("a marker at 1e30 reads as missing", _c3d(marker(1e30)), "accept", "c3d_first_marker_missing"),
        case("the real file", whole, "accept", "c3d_qualisys"),
    ] + c3d_label_cases()


_WRITE_C3D = """
import json, sys
import ezc3d, numpy as np
for k, labels in enumerate(json.loads(sys.argv[2])):
    c = ezc3d.c3d()
    c["parameters"]["POINT"]["RATE"]["value"] = [100]
    c["parameters"]["POINT"]["LABELS"]["value"] = labels
    points = np.ones((4, len(labels), 5))
    points[:3] = np.arange(3 * len(labels) * 5).reshape(3, len(labels), 5) * 10.0
    c["data"]["points"] = points
    c.write(f"{sys.argv[1]}/{k}.c3d")
"""


def _written_c3ds(label_lists: list[list[str]]) -> list[bytes]:
    """Small C3D files written by ezc3d: each list's markers moving apart, 10 units a step, 5 frames at
    100 Hz. In a process of its own: once SimpleITK is imported (another test module does), ezc3d's
    writer fails -- the two SWIG modules share one type table -- while its reader is unaffected."""
    import subprocess
    import sys

    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run([sys.executable, "-c", _WRITE_C3D, tmp, json.dumps(label_lists)], check=True)
        return [Path(f"{tmp}/{k}.c3d").read_bytes() for k in range(len(label_lists))]


def c3d_label_cases() -> list[Case]:
    """Labels through ``positions2trans``: none of them a joint, or too few to pose a bone, is refused."""
    cases = [("labels none of which names a joint", ["FOO", "BAR", "BAZ"], "refuse"),
             ("one marker", ["PELVIS"], "refuse"),
             ("an accented and an empty label", ["PEL\xe9VIS", ""], "refuse"),
             ("two markers: one bone posed, the rest follow", ["PELVIS", "NECK"], "accept")]
    files = _written_c3ds([labels for _, labels, _ in cases])
    return [Case(f"c3d: {name}", "cli:positions2trans", {"m.c3d": data, "m.bones": MANNEQUIN_BONES.read_bytes()},
                 "positions2trans {d}/m.c3d --bones {d}/m.bones -o {d}/out", expect)
            for (name, _, expect), data in zip(cases, files)]


def _dicom_series(mutate=None) -> dict[str, bytes]:
    import pydicom

    from volanim_core.geometry import Geometry
    from volanim_core.io.dicom_files import write_dicom_series

    vol = np.zeros((8, 6, 4), np.int16)
    vol[2:6, 1:5, 1:3] = 300
    with tempfile.TemporaryDirectory() as tmp, warnings.catch_warnings():
        warnings.simplefilter("ignore")  # pydicom warns of the very values the cases write (RescaleSlope "NaN")
        paths = write_dicom_series(tmp, vol, Geometry((0.5, 0.5, 1.0)))
        out = {}
        for k, p in enumerate(sorted(paths)):
            ds = pydicom.dcmread(p)
            if mutate and k == 1:
                mutate(ds)
            buf = stdio.BytesIO()
            ds.save_as(buf)
            out[f"ct/{Path(p).name}"] = buf.getvalue()
    return out


def dicom_cases() -> list[Case]:
    def case(name, mutate, expect="refuse", check=None):
        return Case(f"dicom: {name}", "read_volume", _dicom_series(mutate), "ct", expect, check)

    def drop_pixels(ds):
        del ds.PixelData

    def bits_8(ds):
        ds.BitsAllocated, ds.BitsStored, ds.HighBit = 8, 8, 7

    def slope_nan(ds):
        ds.RescaleSlope = "NaN"

    return [case("a slice without PixelData", drop_pixels), case("BitsAllocated 8 on 16-bit pixels", bits_8),
            case("RescaleSlope NaN", slope_nan), case("the series as written", None, "accept", "shape_8_6_4"),
            *[Case(f"dicom: {cmd} of a series with a slice without PixelData", f"cli:{cmd}",
                   _dicom_series(drop_pixels), arg)
              for cmd, arg in (("info", "info {d}/ct"), ("skeletonize", "skeletonize {d}/ct -o {d}/s.mskel"))]]


def mesh_cases() -> list[Case]:
    def ply(vertex: str) -> bytes:
        head = PLY_HEAD.format(fmt="ascii", n=4) + ("element face 4\nproperty list uchar int vertex_indices\n"
                                                    "end_header\n")
        return (head + f"0 0 0\n1 0 0\n0 1 0\n{vertex}\n3 0 1 2\n3 0 1 3\n3 0 2 3\n3 1 2 3\n").encode()

    def ply_binary_nan() -> bytes:
        head = (PLY_HEAD.format(fmt="binary_little_endian", n=4) + "element face 4\n"
                "property list uchar int vertex_indices\nend_header\n").encode()
        verts = struct.pack("<12f", 0, 0, 0, 1, 0, 0, 0, 1, 0, float("nan"), 0, 1)
        faces = b"".join(struct.pack("<B3i", 3, *f) for f in ((0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)))
        return head + verts + faces

    def case(name, files, arg, sparse=None):
        return Case(f"voxelize: {name}", "cli:voxelize", files, arg, sparse=sparse or {})

    return [case("a PLY vertex at inf", {"m.ply": ply("0 0 inf")}, "voxelize {d}/m.ply {d}/o.nrrd"),
            case("a PLY vertex at 1e300", {"m.ply": ply("0 0 1e300")}, "voxelize {d}/m.ply {d}/o.nrrd"),
            case("a binary PLY vertex at NaN", {"m.ply": ply_binary_nan()}, "voxelize {d}/m.ply {d}/o.nrrd"),
            case("a sparse 3 GB OBJ", {}, "voxelize {d}/m.obj {d}/o.nrrd", {"m.obj": 3 << 30})]


def autorig_cases() -> list[Case]:
    far = "# volanim mskel 1\n# metric: euclid\n10 10 10 8 1\n1073741000 10 10 8 1\n"
    return [Case("autorig: two balls 2^30 voxels apart", "cli:autorig", {"m.mskel": far.encode()},
                 "autorig {d}/m.mskel -o {d}/m.bones")]


def loop_cases() -> list[Case]:
    return [Case(f"{cmd}: a .zarr that is a symlink loop", f"cli:{cmd}", {}, arg, links={"a.zarr": "b", "b": "a.zarr"})
            for cmd, arg in (("render", "render {d}/a.zarr -o {d}/m.mp4"),
                             ("view", "view {d}/a.zarr --screenshot {d}/o.png --size 64x48"))]


# the library's constructors, given what the files' readers refuse: the file names the call
API = ("write_frames with a NaN matrix", "a TransferFunction with a NaN value", "a Camera at NaN",
       "build_palette with a negative count", "a BoneSkeleton with a joint at infinity", "a Trans of a NaN matrix",
       "a 2-channel volume drawn")


def api_cases() -> list[Case]:
    return [Case(f"api: {name}", "api", {"call.txt": name.encode()}, "call.txt") for name in API]


def round3_cases() -> list[Case]:
    return markups_cases() + keys_cases() + positions_cases() + c3d_cases() + dicom_cases() + mesh_cases() + \
        autorig_cases() + loop_cases() + api_cases()
