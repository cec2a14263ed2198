"""The fault corpus: hostile (and a few legitimate-but-unusual) files, one class of problem each.

A case writes its files into a folder and names a target: a reader (run in the
fault worker, see ``worker.py``) or a ``volanim`` command (run as a process).
``expect`` is "refuse" (a clean error naming the file, and saying each of ``says``) or
"accept" (works; for readers an optional ``check`` of the result, by name, in ``worker.CHECKS``).
``mutations`` turns valid text files into hostile ones; the runner draws them
with hypothesis.
"""

from __future__ import annotations

import gzip
import json
import struct
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

BIG = "4294967296"  # 2**32: an int64 product of two of these wraps to 0


@dataclass
class Case:
    name: str
    target: str  # a reader name, or "cli:<command>"
    files: dict[str, bytes]  # relative name -> content
    arg: str  # the file (relative) the target reads, or the CLI arguments (space separated, {d} = folder)
    expect: str = "refuse"
    check: str | None = None
    sparse: dict[str, int] = field(default_factory=dict)  # name -> size of a sparse file to create
    links: dict[str, str] = field(default_factory=dict)  # name -> what the symbolic link points at
    says: tuple[str, ...] = ()  # a refusal must say each of these too (the other file, the bone, what to do)

    def write(self, folder: Path) -> None:
        for rel, data in self.files.items():
            (folder / rel).parent.mkdir(parents=True, exist_ok=True)
            (folder / rel).write_bytes(data)
        for rel, size in self.sparse.items():
            with open(folder / rel, "wb") as fh:
                fh.truncate(size)
        for rel, target in self.links.items():
            (folder / rel).symlink_to(target)


def vol_header(x, y, z) -> bytes:
    return f"{x} {y} {z}".encode().ljust(99, b" ") + b"\n"


def nrrd(sizes: str, body: bytes = b"", extra: str = "", encoding: str = "raw", eol: str = "\n",
         bom: bool = False) -> bytes:
    head = eol.join(["NRRD0004", "type: uchar", "dimension: 3", f"sizes: {sizes}", f"encoding: {encoding}",
                     *([extra] if extra else []), "", ""])
    return (b"\xef\xbb\xbf" if bom else b"") + head.encode() + body


def vti(extent: str, body: str = "") -> bytes:
    return (f'<?xml version="1.0"?>\n<VTKFile type="ImageData" version="1.0" byte_order="LittleEndian">\n'
            f'<ImageData WholeExtent="{extent}" Origin="0 0 0" Spacing="1 1 1">\n<Piece Extent="{extent}">\n'
            f'<PointData Scalars="v"><DataArray type="UInt8" Name="v" format="ascii">{body}</DataArray>'
            f'</PointData>\n</Piece>\n</ImageData>\n</VTKFile>\n').encode()


def mha(dims: str, data: bytes = b"", data_file: str = "LOCAL", element: str = "MET_UCHAR") -> bytes:
    return (f"ObjectType = Image\nNDims = 3\nDimSize = {dims}\nElementType = {element}\n"
            f"ElementDataFile = {data_file}\n").encode() + data


def nifti(dims, datatype=2, bitpix=8, data: bytes = b"", vox_offset=352.0) -> bytes:
    head = bytearray(348)
    struct.pack_into("<i", head, 0, 348)
    struct.pack_into("<8h", head, 40, 3, *dims, 1, 1, 1, 1)
    struct.pack_into("<hh", head, 70, datatype, bitpix)
    struct.pack_into("<f", head, 108, vox_offset)
    struct.pack_into("<8f", head, 76, 1, 1, 1, 1, 1, 1, 1, 1)
    head[344:348] = b"n+1\0"
    return bytes(head) + b"\0" * 4 + data


def valid_vti(shape=(3, 4, 5)) -> bytes:
    values = " ".join(str(v % 200) for v in range(int(np.prod(shape))))
    return vti(f"0 {shape[0] - 1} 0 {shape[1] - 1} 0 {shape[2] - 1}", values)


MSKEL = "# metric: euclid\n10 10 10 3 0.9\n11 10 10 2.5 0.7\n12 10 10 2 0.5\n"
BONES = "joint A 0 0 0\njoint B 0 0 10\njoint C 0 0 20\nbone A B\nbone B C\n"
CONNECT = "# metric: euclid\nRoot: 0 0 0 :: 0 0 10\n10 10 10 3 0.9\nRoot: 0 0 10 :: 0 0 20\n11 10 10 2.5 0.7\n"
IDENTITY = "1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n"
CAMERA = "# volanim camera 1\nposition 10 -300 20\nfocal_point 10 20 20\nview_up 0 0 1\nview_angle 30\n"
TF = "# volanim tf 1\n0 0 0 0 0\n80 0.5 0.4 0.3 0.1\n255 1 1 1 0.9\n"
PALETTE = "# volanim palette 1\n0 0 0\n222 170 140\n178 48 46\n"
ALPHA = "# volanim alpha 1\n0 0\n1 0.02\n254 0.6\n"
TSKEL = f"# metric: euclid\nRoot: 0 0 0 :: 0 0 10\n{IDENTITY}10 10 10 3 0.9\n11 10 10 2.5\n"


BVH = ("HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation "
       "Yrotation\nJOINT Arm\n{\nOFFSET 0 10 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n"
       "End Site\n{\nOFFSET 0 5 0\n}\n}\n}\n"
       "MOTION\nFrames: 1\nFrame Time: 0.04\n0 0 0 0 0 0 0 0 0\n")


def deep_bvh(n: int) -> bytes:
    """A chain ``n`` joints deep (more than a reader may hold; recursion would overflow long before)."""
    head = "HIERARCHY\nROOT J0\n{\nOFFSET 0 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n"
    body = "".join(f"JOINT J{i}\n{{\nOFFSET 0 1 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n" for i in range(1, n))
    return (head + body + "}\n" * n + "MOTION\nFrames: 1\nFrame Time: 0.1\n" + "0 " * 3 * n + "\n").encode()


def chain_bones(n: int) -> bytes:
    """A chain of ``n`` bones listed leaf first (the recursion trap)."""
    joints = "".join(f"joint J{i} 0 0 {i}\n" for i in range(n + 1))
    bones = "".join(f"bone J{i} J{i + 1}\n" for i in reversed(range(n)))
    return (joints + bones).encode()


def project(**fields) -> bytes:
    return json.dumps({"format": "volanim project", **fields}).encode()


def hand_written() -> list[Case]:
    t = str.encode
    gz_bomb = gzip.compress(b"\0" * (64 << 20), 9)  # 64 MB of zeros in ~64 kB; the header says 1000 bytes
    cases = [
        # --- sizes that overflow, are negative or zero, or cannot be allocated
        Case("VOL header 2^32 x 2^32 x 1", "read_volume", {"f.VOL": vol_header(BIG, BIG, 1)}, "f.VOL"),
        Case("VOL header -4 3 2", "read_volume", {"f.VOL": vol_header(-4, 3, 2) + b"\0" * 24}, "f.VOL"),
        Case("VOL header full-width digits", "read_volume", {"f.VOL": vol_header("１２", 3, 2) + b"\0" * 72},
             "f.VOL"),
        Case(".vol name 2^32 x 2^32 x 1", "read_volume", {f"f.{BIG}x{BIG}x1.vol": b"\0" * 8},
             f"f.{BIG}x{BIG}x1.vol"),
        Case("NRRD sizes 2^32 2^32 1", "read_volume", {"f.nrrd": nrrd(f"{BIG} {BIG} 1")}, "f.nrrd"),
        Case("NRRD sizes -4 3 2", "read_volume", {"f.nrrd": nrrd("-4 3 2", b"\0" * 24)}, "f.nrrd"),
        Case("NRRD sizes 0 3 2", "read_volume", {"f.nrrd": nrrd("0 3 2")}, "f.nrrd"),
        Case("NRRD gzip bomb", "read_volume", {"f.nrrd": nrrd("10 10 10", gz_bomb, encoding="gzip")}, "f.nrrd"),
        Case("NRRD raw body truncated", "read_volume", {"f.nrrd": nrrd("10 10 10", b"\0" * 500)}, "f.nrrd"),
        Case("NRRD space directions 2 components", "read_volume",
             {"f.nrrd": nrrd("2 2 2", b"\0" * 8, "space directions: (1,0) (0,1,0) (0,0,1)")}, "f.nrrd"),
        Case("NRRD space directions NaN", "read_volume",
             {"f.nrrd": nrrd("2 2 2", b"\0" * 8, "space directions: (nan,0,0) (0,1,0) (0,0,1)")}, "f.nrrd"),
        Case("NRRD spacings zero", "read_volume", {"f.nrrd": nrrd("2 2 2", b"\0" * 8, "spacings: 0 1 1")}, "f.nrrd"),
        Case("vti WholeExtent 2^32", "read_volume", {"f.vti": vti("0 4294967295 0 4294967295 0 0")}, "f.vti"),
        Case("vti negative extent", "read_volume", {"f.vti": vti("0 -5 0 3 0 3")}, "f.vti"),
        Case("vti truncated", "read_volume", {"f.vti": valid_vti()[:200]}, "f.vti"),
        Case("vti empty", "read_volume", {"f.vti": b""}, "f.vti"),
        Case("mha DimSize 2^32", "read_volume", {"f.mha": mha(f"{BIG} {BIG} 1")}, "f.mha"),
        Case("mha DimSize -4 3 2", "read_volume", {"f.mha": mha("-4 3 2", b"\0" * 24)}, "f.mha"),
        Case("mha data truncated", "read_volume", {"f.mha": mha("10 10 10", b"\7" * 500)}, "f.mha"),
        Case("mha header only", "read_volume", {"f.mha": b"ObjectType = Image\nNDims = 3\nDimSize = 4 4 4\n"},
             "f.mha"),
        Case("mha empty", "read_volume", {"f.mha": b""}, "f.mha"),
        Case("mha data file missing", "read_volume", {"f.mha": mha("4 4 4", data_file="gone.raw")}, "f.mha"),
        Case("mhd data file short", "read_volume", {"f.mhd": mha("4 4 4", data_file="f.raw"), "f.raw": b"\0" * 10},
             "f.mhd"),
        Case("nii dims 32767^3", "read_volume", {"f.nii": nifti((32767, 32767, 32767))}, "f.nii"),
        Case("nii negative dims", "read_volume", {"f.nii": nifti((-4, 3, 2), data=b"\0" * 24)}, "f.nii"),
        Case("nii data truncated", "read_volume", {"f.nii": nifti((10, 10, 10), data=b"\7" * 500)}, "f.nii"),
        Case("nii header only", "read_volume", {"f.nii": nifti((4, 4, 4))[:348]}, "f.nii"),
        Case("nii empty", "read_volume", {"f.nii": b""}, "f.nii"),
        Case("nii.gz truncated", "read_volume",
             {"f.nii.gz": gzip.compress(nifti((10, 10, 10), data=b"\7" * 900))[:-200]}, "f.nii.gz"),
        Case("nii.gz data short", "read_volume", {"f.nii.gz": gzip.compress(nifti((10, 10, 10), data=b"\7" * 500))},
             "f.nii.gz"),
        Case("legacy vtk huge DIMENSIONS", "read_volume",
             {"f.vtk": b"# vtk DataFile Version 3.0\nx\nBINARY\nDATASET STRUCTURED_POINTS\n"
                       b"DIMENSIONS 4294967296 4294967296 1\n"}, "f.vtk"),
        Case("a folder named like a volume", "read_volume", {"f.vti/empty.txt": b""}, "f.vti"),
        Case("3 GB sparse text file", "read_mskel", {}, "big.mskel", sparse={"big.mskel": 3 << 30}),
        # --- legitimate input that must be accepted
        Case("valid vti", "read_volume", {"f.vti": valid_vti()}, "f.vti", "accept", "shape_3_4_5"),
        Case("NRRD with BOM and CRLF", "read_volume", {"f.nrrd": nrrd("2 3 4", bytes(range(24)), eol="\r\n", bom=True)},
             "f.nrrd", "accept", "shape_2_3_4"),
        Case("mskel with BOM", "read_mskel", {"f.mskel": b"\xef\xbb\xbf" + t(MSKEL)}, "f.mskel", "accept", "len_3"),
        Case("mskel with CRLF", "read_mskel", {"f.mskel": t(MSKEL.replace("\n", "\r\n"))}, "f.mskel", "accept",
             "len_3"),
        Case("connections with BOM", "read_connections", {"f.connections": b"\xef\xbb\xbfA B\nB C\n"},
             "f.connections", "accept", "first_pair_A_B"),
        Case("3000-bone chain leaf first", "read_bones", {"chain.bones": chain_bones(3000)}, "chain.bones", "accept",
             "len_3000"),
        # --- garbage that must not be accepted silently
        Case("mskel NaN thinness", "read_mskel", {"f.mskel": t(MSKEL.replace("0.9", "nan"))}, "f.mskel"),
        Case("mskel coordinate 3e9", "read_mskel", {"f.mskel": t(MSKEL.replace("10 10 10", "3000000000 10 10"))},
             "f.mskel"),
        Case("mskel coordinate 1e300", "read_mskel", {"f.mskel": t(MSKEL.replace("10 10 10", "1e300 10 10"))},
             "f.mskel"),
        Case("mskel full-width digits", "read_mskel", {"f.mskel": t(MSKEL.replace("10 10 10", "１２ 10 10"))},
             "f.mskel"),
        Case("mskel underscore digits", "read_mskel", {"f.mskel": t(MSKEL.replace("10 10 10", "1_2 10 10"))},
             "f.mskel"),
        Case("connect coordinate 3e9", "read_connect", {"f.connect": t(CONNECT.replace("10 10 10", "3000000000 1 1"))},
             "f.connect"),
        Case("bones cycle A->B, B->A", "read_bones", {"f.bones": b"joint A 0 0 0\njoint B 0 0 1\nbone A B\nbone B A\n"},
             "f.bones"),
        Case("bones joint full-width", "read_bones", {"f.bones": t(BONES.replace("0 0 10", "0 0 １０"))}, "f.bones"),
        Case("connect Root twice", "read_connect",
             {"f.connect": t(CONNECT.replace("Root: 0 0 10 :: 0 0 20", "Root: 0 0 0 :: 0 0 10"))}, "f.connect"),
        Case("connections pair twice", "read_connections", {"f.connections": b"A B\nB C\nA B\n"}, "f.connections"),
        Case("connections self pair", "read_connections", {"f.connections": b"A A\n"}, "f.connections"),
        Case("tskel 3-row matrix then Root", "read_tskel",
             {"f.tskel": t("Root: 0 0 0 :: 0 0 10\n1 0 0 0\n0 1 0 0\n0 0 1 0\nRoot: 0 0 10 :: 0 0 20\n" + IDENTITY)},
             "f.tskel"),
        Case("tskel 3-row matrix then point", "read_tskel",
             {"f.tskel": t("Root: 0 0 0 :: 0 0 10\n1 0 0 0\n0 1 0 0\n0 0 1 0\n10 10 10 3 0.9\n")}, "f.tskel"),
        Case("tskel NaN matrix", "read_tskel", {"f.tskel": t(TSKEL.replace("0 0 0 1\n", "nan 0 0 1\n", 1))}, "f.tskel"),
        Case("trans non-affine matrix", "read_trans",
             {"f.trans": t("Root: 0 0 0 :: 0 0 10\n1 0 0 0.5\n0 1 0 0\n0 0 1 0\n0 0 0 1\n")}, "f.trans"),
        Case("project volume is a number", "read_project", {"p.volanim": project(volume=5)}, "p.volanim"),
        Case("project volume is a list", "read_project", {"p.volanim": project(volume=["a"])}, "p.volanim"),
        Case("project nested 100000 deep", "read_project", {"p.volanim": b"[" * 100000 + b"]" * 100000},
             "p.volanim"),
        Case("project thinness NaN", "read_project", {"p.volanim": b'{"format": "volanim project", "thinness": NaN}'},
             "p.volanim"),
        Case("project volume_dims 2^32", "read_project", {"p.volanim": project(volume_dims=[2**32, 2**32, 1])},
             "p.volanim"),
        Case("project newer version", "read_project", {"p.volanim": project(version=99)}, "p.volanim"),
        Case("project data file hash mismatch", "read_project",
             {"p.volanim": project(version=3, bones="p.volanim.d/bones-0.bones", sha256={"bones": "0" * 64}),
              "p.volanim.d/bones-0.bones": t(BONES)}, "p.volanim"),
        Case("project 20 MB", "read_project", {}, "p.volanim", sparse={"p.volanim": 20 << 20}),
        Case("project timeline is a list", "read_project", {"p.volanim": project(timeline=[1])}, "p.volanim"),
        Case("project key frame 10^12", "read_project",
             {"p.volanim": project(timeline={"keys": {"1000000000000": []}})}, "p.volanim"),
        Case("project key frame negative", "read_project", {"p.volanim": project(timeline={"keys": {"-3": []}})},
             "p.volanim"),
        Case("project key angle 1e300", "read_project",
             {"p.volanim": project(timeline={"keys": {"0": [["A", "B", 1e300, 0, 0, 0, 0, 0]]}})}, "p.volanim"),
        Case("project key angle NaN", "read_project",
             {"p.volanim": b'{"format": "volanim project", '
                           b'"timeline": {"keys": {"0": [["A", "B", NaN, 0, 0, 0, 0, 0]]}}}'},
             "p.volanim"),
        Case("project timeline length 10^12", "read_project", {"p.volanim": project(timeline={"length": 10**12})},
             "p.volanim"),
        Case("project timeline fps NaN", "read_project",
             {"p.volanim": b'{"format": "volanim project", "timeline": {"fps": NaN}}'}, "p.volanim"),
        Case("project clip kind unknown", "read_project",
             {"p.volanim": project(timeline={"clip": {"kind": "exe", "path": "/bin/sh"}})}, "p.volanim"),
        Case("project clip mapping a list", "read_project",
             {"p.volanim": project(timeline={"clip": {"kind": "bvh", "path": "a.bvh", "mapping": ["x"]}})},
             "p.volanim"),
        Case("bvh Frames 10^12", "read_bvh", {"f.bvh": t(BVH.replace("Frames: 1", "Frames: 1000000000000"))}, "f.bvh"),
        Case("bvh NaN channel", "read_bvh", {"f.bvh": t(BVH.replace("0 0 0 0 0 0 0 0 0\n", "0 0 0 nan 0 0 0 0 0\n"))},
             "f.bvh"),
        Case("bvh 20000 joints deep", "read_bvh", {"f.bvh": deep_bvh(20000)}, "f.bvh"),
        Case("bvh empty", "read_bvh", {"f.bvh": b""}, "f.bvh"),
        Case("bvh with BOM and CRLF", "read_bvh", {"f.bvh": b"\xef\xbb\xbf" + t(BVH.replace("\n", "\r\n"))}, "f.bvh",
             "accept", "len_frames_1"),
        # --- the command line
        Case("count: VOL header overflow", "cli:count", {"f.VOL": vol_header(BIG, BIG, 1)}, "count {d}/f.VOL"),
        Case("rmheader: VOL header overflow", "cli:rmheader", {"f.VOL": vol_header(BIG, BIG, 1)},
             "rmheader {d}/f.VOL {d}/out.vol"),
        Case("addheader: name overflow", "cli:addheader", {f"f.{BIG}x{BIG}x1.vol": b"\0" * 8},
             f"addheader {{d}}/f.{BIG}x{BIG}x1.vol {{d}}/out.VOL"),
        Case("info: vti huge extent", "cli:info", {"f.vti": vti("0 4294967295 0 4294967295 0 0")}, "info {d}/f.vti"),
        Case("info: nii truncated", "cli:info", {"f.nii": nifti((10, 10, 10), data=b"\7" * 500)}, "info {d}/f.nii"),
        Case("bounds: radius 1e300", "cli:bounds", {"f.tskel": t(TSKEL.replace(" 3 0.9", " 1e300 0.9"))},
             "bounds {d}/f.tskel"),
        Case("reconstruct: radius 1e6", "cli:reconstruct", {"f.tskel": t(TSKEL.replace(" 3 0.9", " 1000000 0.9"))},
             "reconstruct {d}/f.tskel -o {d}/o.vti"),
        Case("reconstruct: radius 1e6 in small bounds", "cli:reconstruct",
             {"f.tskel": t(TSKEL.replace(" 3 0.9", " 1000000 0.9"))},
             "reconstruct {d}/f.tskel --bounds 0 0 0 20 20 20 -o {d}/o.vti", "accept"),
        Case("reconstruct: NaN matrix", "cli:reconstruct", {"f.tskel": t(TSKEL.replace("0 0 0 1\n", "0 0 0 nan\n"))},
             "reconstruct {d}/f.tskel -o {d}/o.vti"),
        Case("connect: coordinate 3e9", "cli:connect",
             {"f.mskel": t(MSKEL.replace("10 10 10", "3000000000 1 1")), "f.bones": t(BONES)},
             "connect {d}/f.mskel {d}/f.bones -o {d}/o.connect"),
        Case("connect: bone cycle", "cli:connect",
             {"f.mskel": t(MSKEL), "f.bones": b"joint A 0 0 0\njoint B 0 0 1\nbone A B\nbone B A\n"},
             "connect {d}/f.mskel {d}/f.bones -o {d}/o.connect"),
        Case("pose: 3000-bone chain leaf first", "cli:pose", {"chain.bones": chain_bones(3000)},
             "pose {d}/chain.bones --rotate J0-J1=10,0,0 -o {d}/o.trans", "accept"),
        Case("skeletonize: --min-thinness -inf", "cli:skeletonize", {"f.nrrd": nrrd("6 6 6", b"\1" * 216)},
             "skeletonize {d}/f.nrrd -o {d}/o.mskel --min-thinness -inf", "accept"),
        Case("skeletonize: --min-thinness nan", "cli:skeletonize", {"f.nrrd": nrrd("6 6 6", b"\1" * 216)},
             "skeletonize {d}/f.nrrd -o {d}/o.mskel --min-thinness nan"),
        Case("count: --dims full-width", "cli:count", {"f.vol": b"\0" * 24}, "count {d}/f.vol --dims １２ 1 2"),
        # --- render inputs and settings
        Case("camera: focal point is the position", "read_camera",
             {"c.camera": b"position 1 2 3\nfocal_point 1 2 3\n"}, "c.camera"),
        Case("camera: view_up along the line of sight", "read_camera",
             {"c.camera": b"position 0 -9 0\nfocal_point 0 0 0\nview_up 0 5 0\n"}, "c.camera"),
        Case("camera: parallel_scale 0", "read_camera",
             {"c.camera": t(CAMERA + "parallel_scale 0\n")}, "c.camera"),
        Case("camera: a vector with 4 numbers", "read_camera",
             {"c.camera": b"position 0 -9 0 1\nfocal_point 0 0 0\n"}, "c.camera"),
        Case("camera: binary junk", "read_camera", {"c.camera": b"\x89PNG\r\n\x1a\n\0\0"}, "c.camera"),
        Case("tf: one point is enough", "read_transfer_function", {"a.tf": b"7 1 0 0 1\n"}, "a.tf", "accept"),
        Case("tf: values repeat", "read_transfer_function", {"a.tf": b"0 0 0 0 0\n0 1 1 1 1\n"}, "a.tf"),
        Case("tf: colour 255 (0..1 expected)", "read_transfer_function", {"a.tf": b"0 255 0 0 1\n"}, "a.tf"),
        Case("render: a folder that is no sequence", "cli:render", {"x.zarr/zarr.json": b"{}"},
             "render {d}/x.zarr -o {d}/o.png"),
        Case("render: a sequence whose plan is junk", "cli:render",
             {"s.zarr/volanim-plan.json": b"\0\1not json"}, "render {d}/s.zarr -o {d}/o"),
        Case("render: a volume to an .avi", "cli:render", {"f.nrrd": nrrd("6 6 6", b"\1" * 216)},
             "render {d}/f.nrrd -o {d}/o.avi"),
        Case("render: a volume with a nan cut", "cli:render", {"f.nrrd": nrrd("6 6 6", b"\1" * 216)},
             "render {d}/f.nrrd -o {d}/o.png --cut 1 1 1 nan 0 0"),
        Case("render: a zero cut normal", "cli:render", {"f.nrrd": nrrd("6 6 6", b"\1" * 216)},
             "render {d}/f.nrrd -o {d}/o.png --cut 1 1 1 0 0 0"),
        Case("render: one volume to a png", "cli:render", {"f.nrrd": nrrd("6 6 6", b"\1" * 216)},
             "render {d}/f.nrrd -o {d}/o.png --size 64x48", "accept"),
        # --- colour: RGB volumes, palettes, alpha maps and the commands that read them
        Case("rgb vol: 3 bytes a voxel reads (as grey)", "read_volume", {"c.2x3x4.vol": bytes(range(72))},
             "c.2x3x4.vol", "accept", "grey_of_rgb_2_3_4"),
        Case("rgb vol: 2 bytes a voxel", "read_volume", {"c.2x3x4.vol": b"\1" * 48}, "c.2x3x4.vol"),
        Case("rgb VOL: a byte short", "read_volume", {"c.VOL": b"2 3 4".ljust(99) + b"\n" + b"\1" * 71}, "c.VOL"),
        Case("rgb nrrd: 3 components of 16 bits", "read_volume",
             {"c.nrrd": b"NRRD0004\ntype: short\ndimension: 4\nsizes: 3 2 2 2\nencoding: raw\n\n" + b"\0" * 48},
             "c.nrrd"),
        Case("palette: no colours", "read_palette", {"p.txt": b"# volanim palette 1\n"}, "p.txt"),
        Case("palette: 257 colours", "read_palette", {"p.txt": b"1 2 3\n" * 257}, "p.txt"),
        Case("palette: a negative value", "read_palette", {"p.txt": b"1 2 3\n-1 2 3\n"}, "p.txt"),
        Case("palette: a fraction", "read_palette", {"p.txt": b"1 2 3.5\n"}, "p.txt"),
        Case("palette: four numbers", "read_palette", {"p.txt": b"1 2 3 4\n"}, "p.txt"),
        Case("palette: binary junk", "read_palette", {"p.txt": b"\x89PNG\r\n\x1a\n\0\0"}, "p.txt"),
        Case("palette: 256 colours with CRLF and a BOM", "read_palette",
             {"p.txt": b"\xef\xbb\xbf" + b"1 2 3\r\n" * 256}, "p.txt", "accept"),
        Case("alpha: indices descend", "read_alpha_map", {"a.alpha": b"5 0\n3 1\n"}, "a.alpha"),
        Case("alpha: nan", "read_alpha_map", {"a.alpha": b"0 nan\n"}, "a.alpha"),
        Case("alpha: one number", "read_alpha_map", {"a.alpha": b"0\n"}, "a.alpha"),
        Case("palette apply: a grey volume", "cli:palette", {"g.VOL": b"2 2 2".ljust(99) + b"\n" + b"\1" * 8,
                                                             "p.txt": b"1 2 3\n"},
             "palette apply {d}/g.VOL {d}/p.txt -o {d}/i.VOL"),
        Case("palette apply: a truncated RGB file", "cli:palette",
             {"c.VOL": b"4 4 4".ljust(99) + b"\n" + b"\1" * 100, "p.txt": b"1 2 3\n"},
             "palette apply {d}/c.VOL {d}/p.txt -o {d}/i.VOL"),
        Case("palette build: 0 colours", "cli:palette", {"c.2x2x2.vol": b"\7" * 24},
             "palette build {d}/c.2x2x2.vol -o {d}/p.txt --colours 0"),
        Case("palette build: a tiny RGB volume", "cli:palette", {"c.2x2x2.vol": bytes(range(24))},
             "palette build {d}/c.2x2x2.vol -o {d}/p.txt", "accept"),
        Case("palette sort: a palette of one colour", "cli:palette", {"p.txt": b"1 2 3\n"},
             "palette sort {d}/p.txt -o {d}/s.txt --remap {d}/r.txt", "accept"),
        Case("palette sort: an index volume past the palette", "cli:palette",
             {"p.txt": b"1 2 3\n4 5 6\n", "i.2x2x2.vol": b"\5" * 8},
             "palette sort {d}/p.txt -o {d}/s.txt --remap {d}/r.txt --volume {d}/i.2x2x2.vol"),
        Case("alpha merge: an alpha map of words", "cli:alpha", {"p.txt": b"1 2 3\n", "a.alpha": b"zero one\n"},
             "alpha merge {d}/p.txt {d}/a.alpha -o {d}/t.tf"),
        Case("alpha merge: --clear past the palette", "cli:alpha", {"p.txt": b"1 2 3\n"},
             "alpha merge {d}/p.txt 0.5 --clear 9 -o {d}/t.tf"),
        Case("mesh: empty file", "read_mesh", {"m.ply": b""}, "m.ply"),
        Case("mesh: a ply header with no faces", "read_mesh",
             {"m.ply": b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n1\n"}, "m.ply"),
        Case("mesh: binary junk as .stl", "read_mesh", {"m.stl": b"\x89PNG\r\n\x1a\n" + b"\xff" * 300}, "m.stl"),
        Case("mesh: an .obj of words", "read_mesh", {"m.obj": b"v one two three\nf a b c\n"}, "m.obj"),
        Case("mesh: a ply claiming 2^31 vertices", "read_mesh",
             {"m.ply": b"ply\nformat binary_little_endian 1.0\nelement vertex 2147483647\nproperty float x\n"
                       b"property float y\nproperty float z\nend_header\n" + b"\0" * 24}, "m.ply"),
        Case("mesh: a .vtp claiming 2^40 points", "read_mesh",
             {"m.vtp": b'<VTKFile type="PolyData"><PolyData><Piece NumberOfPoints="1099511627776" '
                       b'NumberOfPolys="1"></Piece></PolyData></VTKFile>'}, "m.vtp"),
        Case("view: a mesh that is not one", "cli:view", {"m.vtp": b"<VTKFile junk"},
             "view {d}/m.vtp --screenshot {d}/o.png"),
        Case("view: a volume to a picture", "cli:view", {"f.nrrd": nrrd("6 6 6", b"\1" * 216)},
             "view {d}/f.nrrd --screenshot {d}/o.png --size 64x48", "accept"),
    ]
    return cases


# Mutations of valid text files, drawn by hypothesis in the runner: (name, function(text) -> text)
HOSTILE_NUMBERS = ["nan", "NaN", "inf", "-inf", "1e300", "-1e300", "3000000000", "１２", "1_2", "0x10", "1e",
                   "--1", "9" * 400]


def replace_number(text: str, k: int, value: str) -> str:
    """Replace the k-th numeric token (cycling) by ``value``."""
    lines = text.split("\n")
    spots = [(i, j) for i, line in enumerate(lines) if not line.startswith("#")
             for j, tok in enumerate(line.split()) if tok.lstrip("+-").replace(".", "", 1).isdigit()]
    i, j = spots[k % len(spots)]
    toks = lines[i].split()
    toks[j] = value
    lines[i] = " ".join(toks)
    return "\n".join(lines)


def mutated(kind: str, k: int, value: str) -> Case:
    """A valid file of ``kind`` with one number made hostile."""
    base = {"mskel": MSKEL, "bones": BONES, "connect": CONNECT, "tskel": TSKEL, "camera": CAMERA, "tf": TF,
            "palette": PALETTE, "alpha": ALPHA}[kind]
    text = replace_number(base, k, value)
    reader = {"tf": "read_transfer_function", "alpha": "read_alpha_map"}.get(kind, f"read_{kind}")
    return Case(f"{kind}: number #{k} -> {value[:12]}", reader, {f"m.{kind}": text.encode()}, f"m.{kind}")
