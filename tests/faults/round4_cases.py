"""Fault cases of the fourth round (#89): the last silent answers (16-bit colour PNG slices read as their
high bytes) and refusals that must say more than the file's name: the other file, the bone and how the two
differ (a .trans of another rig), the data file a detached NRRD looked for, the frame and shard of a damaged
store, the DICOM file and attribute, and what to do. ``Case.says`` holds what each refusal must say.

Files are made by the libraries the field writes them with: PNGs by SimpleITK (ITK's PNG writer keeps 16-bit
colour, Pillow cannot write it), DICOM by pydicom, skeletons by our skeletonize of real shapes.
"""

from __future__ import annotations

import io as stdio
import tempfile
from pathlib import Path

import numpy as np

from .cases import Case
from .round3_cases import _dicom_series
from .store_cases import STORE, _shard, valid_store

CONNECT = ("# volanim connect 1\n# metric: euclid\nRoot: 0 0 0 :: 0 0 10 SPINE\n10 10 10 3 0.9\n"
           "Root: 0 0 10 :: 0 0 20 NECK\n11 10 10 2.5 0.7\nRoot: 0 0 10 :: 5 0 15 ARM\n12 10 10 2 0.5\n")
IDENTITY = "1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n"
BONES = {"SPINE": "0 0 0 :: 0 0 10", "NECK": "0 0 10 :: 0 0 20", "ARM": "0 0 10 :: 5 0 15"}


def _trans(bones: list[tuple[str, str]], matrices: dict[str, str] | None = None) -> bytes:
    """A .trans of ``(name, 'x y z :: x y z')`` bones, each with the identity unless ``matrices`` names it."""
    return ("# volanim trans 1\n" + "".join(f"Root: {seg} {name}\n{(matrices or {}).get(name, IDENTITY)}"
                                            for name, seg in bones)).encode()


def _png(array: np.ndarray) -> bytes:
    import SimpleITK as sitk

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "s.png"
        sitk.WriteImage(sitk.GetImageFromArray(array, isVector=array.ndim == 3), str(path))
        return path.read_bytes()


def _grey16_keyed(key: int) -> bytes:
    from PIL import Image

    buf = stdio.BytesIO()
    Image.fromarray(_ct_slice()).save(buf, format="PNG", transparency=key)
    return buf.getvalue()


def _ct_slice() -> np.ndarray:
    s = np.zeros((5, 6), np.uint16)
    s[1:4, 2:5] = 6000  # a CT's values: their high bytes are 0..23
    return s


def slice_cases() -> list[Case]:
    s = _ct_slice()
    opaque = np.full_like(s, 65535)

    def stack(name, data, expect="refuse", check=None, says=()):
        return Case(f"slices: {name}", "read_volume", {"s/a0.png": data, "s/a1.png": data}, "s", expect, check,
                    says=says)

    return [stack("16-bit RGBA PNG (Pillow keeps the high bytes)", _png(np.dstack([s, s, s, opaque])),
                  says=("a0.png", "16-bit RGBA PNG", "TIFF")),
            stack("16-bit RGB PNG", _png(np.dstack([s, s, s])), says=("a0.png", "16-bit RGB PNG")),
            stack("16-bit grey+alpha PNG", _png(np.dstack([s, opaque])), says=("a0.png", "16-bit grey+alpha")),
            stack("16-bit grey PNG keying its background transparent", _grey16_keyed(0),
                  says=("a0.png", "keys value 0 as transparent")),
            stack("16-bit grey PNG with a key no pixel has", _grey16_keyed(7), "accept", "ct_6000"),
            stack("16-bit grey PNG", _png(s), "accept", "ct_6000")]


def nrrd_cases() -> list[Case]:
    head = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 3 4\nencoding: raw\n"
    return [Case("nrrd: a detached header whose data file is missing", "read_volume",
                 {"a.nhdr": f"{head}data file: a.raw\n\n".encode()}, "a.nhdr",
                 says=("a.nhdr:6", "a.raw is missing", "looked for at", "put the data file there")),
            Case("nrrd: a detached header whose data file is a folder", "read_volume",
                 {"a.nhdr": f"{head}data file: d.raw\n\n".encode(), "d.raw/x": b""}, "a.nhdr",
                 says=("a folder, not a file",)),
            Case("nrrd: data file LIST", "read_volume",
                 {"a.nhdr": f"{head}data file: LIST\nm1.raw\nm2.raw\n".encode(), "m1.raw": bytes(12),
                  "m2.raw": bytes(12)}, "a.nhdr", says=("a.nhdr:6", "a list of files")),
            Case("nrrd: a detached header and its data", "read_volume",
                 {"a.nhdr": f"{head}data file: a.raw\n\n".encode(), "a.raw": bytes(range(24))}, "a.nhdr",
                 "accept", "shape_2_3_4")]


def dicom_cases() -> list[Case]:
    from pydicom.dataelem import RawDataElement
    from pydicom.tag import Tag

    def frames_as_text(ds):  # raw bytes: pydicom's own setter refuses the value
        ds[Tag(0x00280008)] = RawDataElement(Tag(0x00280008), "IS", 4, b"two ", 0, False, True)

    def position_nan(ds):
        ds.ImagePositionPatient = [0, float("nan"), 1]

    return [Case("dicom: NumberOfFrames as text", "read_volume", _dicom_series(frames_as_text), "ct",
                 says=("IM0001.dcm", "NumberOfFrames is 'two'", "leave this file out")),
            Case("dicom: a NaN in ImagePositionPatient", "read_volume", _dicom_series(position_nan), "ct",
                 says=("IM0001.dcm", "ImagePositionPatient", "not three finite numbers"))]


def store_cases() -> list[Case]:
    base = valid_store()
    bad = dict(base)
    shard = bytearray(base[_shard(base, 1)])
    shard[len(shard) // 2] ^= 0xFF  # one byte of frame 1's data: the shard's checksum no longer matches
    bad[_shard(base, 1)] = bytes(shard)
    says = ("frame 11 (index 1)", "shard 0/c/1/", "--force")
    return [Case("store: a shard with a bad checksum", "read_sequence", bad, STORE, says=says),
            Case("render: a shard with a bad checksum (read in a worker process)", "cli:render", bad,
                 f"render {{d}}/{STORE} -o {{d}}/o.gif --size 64x48", says=says)]


def rig_cases() -> list[Case]:
    """A .trans of another rig with a .connect, through connect2tskel and scan: both files, the bone, how."""
    order = list(BONES.items())
    fix = "written for another bone skeleton"

    def pair(name, trans, says, both=True):  # both: the two files differ (else the .trans alone is wrong)
        return Case(f"connect2tskel: {name}", "cli:connect2tskel", {"c.connect": CONNECT.encode(), "t.trans": trans},
                    "connect2tskel {d}/c.connect {d}/t.trans -o {d}/o.tskel",
                    says=(*(("c.connect", "t.trans") if both else ()), *says))

    zero = "0 0 0 0\n0 0 0 0\n0 0 0 0\n0 0 0 1\n"
    grown = "1000 0 0 0\n0 1000 0 0\n0 0 1000 0\n0 0 0 1\n"
    return [pair("bones swapped", _trans([order[0], order[2], order[1]]), ("other orders", "NECK", "ARM")),
            pair("a bone moved", _trans([order[0], ("NECK", "0 0 10 :: 0 0 25"), order[2]]),
                 ("bone 1 differs", "NECK", "moved by up to 5", fix)),
            pair("a bone extra", _trans([*order, ("LEG", "0 0 0 :: 0 5 -10")]), ("LEG", "only in the .trans", fix)),
            pair("one bone only", _trans(order[:1]), ("NECK", "ARM", "only in the .connect", fix)),
            pair("a singular matrix", _trans(order, {"NECK": zero}), ("t.trans:8", "NECK", "singular"), False),
            pair("a scale of 1000", _trans(order, {"SPINE": grown}), ("t.trans:3", "SPINE", "by 1e+03"), False),
            Case("connect2tskel: the rig's own frame", "cli:connect2tskel",
                 {"c.connect": CONNECT.encode(), "t.trans": _trans(order)},
                 "connect2tskel {d}/c.connect {d}/t.trans -o {d}/o.tskel", "accept"),
            Case("scan: frames of mixed rigs", "cli:scan",
                 {"c.connect": CONNECT.encode(), "f1.trans": _trans(order),
                  "f2.trans": _trans([*order, ("LEG", "0 0 0 :: 0 5 -10")])},
                 "scan {d}/c.connect {d}/f1.trans {d}/f2.trans", says=("f2.trans", "c.connect", "LEG", fix))]


def _mskel(volume: np.ndarray) -> bytes:
    from volanim_core.io import write_mskel
    from volanim_core.skeleton.skeletonize import skeletonize

    with tempfile.TemporaryDirectory() as tmp:
        write_mskel(Path(tmp) / "m.mskel", skeletonize(volume > 0))
        return (Path(tmp) / "m.mskel").read_bytes()


def autorig_cases() -> list[Case]:
    two = np.zeros((40, 40, 40), np.uint8)
    two[5:15, 5:15, 5:15] = two[25:35, 25:35, 25:35] = 1
    sheet = np.zeros((40, 40, 20), np.uint8)
    sheet[5:35, 5:35, 10] = 1
    rod = np.zeros((30, 30, 60), np.uint8)
    rod[13:17, 13:17, 5:55] = 1

    def case(name, mskel, says):
        return Case(f"autorig: {name}", "cli:autorig", {"m.mskel": mskel}, "autorig {d}/m.mskel -o {d}/m.bones",
                    says=says)

    bend = ("nothing to bend", "draw the bones in the studio")
    return [case("two points", b"# volanim mskel 1\n# metric: euclid\n10 10 10 3 1\n11 10 10 3 1\n", bend),
            case("two separate boxes", _mskel(two), ("2 pieces", "rig each body separately")),
            case("a thin sheet", _mskel(sheet), bend),
            Case("autorig: a rod 4 voxels wide (thinned away whole by scikit-image)", "cli:autorig",
                 {"m.mskel": _mskel(rod)}, "autorig {d}/m.mskel -o {d}/m.bones", "accept")]


def mesh_cases() -> list[Case]:
    def ply(points: str, faces: list[str]) -> bytes:
        n = len(points.strip().splitlines())
        return (f"ply\nformat ascii 1.0\nelement vertex {n}\nproperty float x\nproperty float y\nproperty float z\n"
                f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n{points}"
                + "".join(f"3 {f}\n" for f in faces)).encode()

    def case(name, data, says):
        return Case(f"voxelize: {name}", "cli:voxelize", {"m.ply": data}, "voxelize {d}/m.ply {d}/o.nrrd", says=says)

    tet = "0 0 0\n10 0 0\n0 10 0\n0 0 10\n"
    return [case("an open tetrahedron", ply(tet, ["0 1 2", "0 1 3", "0 2 3"]),
                 ("3 open edges, one from", "close its holes")),
            case("a mesh that is all one point", ply("5 5 5\n5 5 5\n5 5 5\n", ["0 1 2"]),
                 ("no volume", "all at one point"))]


def round4_cases() -> list[Case]:
    return slice_cases() + nrrd_cases() + dicom_cases() + store_cases() + rig_cases() + autorig_cases() + \
        mesh_cases()
