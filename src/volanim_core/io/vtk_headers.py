"""What a ``.vti``/``.mha``/``.mhd``/``.nii``/``.nii.gz``/``.vtk`` header claims, read without VTK
(and, for meshes, what a ``.ply``/``.stl``/``.vtp`` header claims: :func:`check_mesh_claims`).

VTK allocates whatever a header claims (``std::bad_alloc`` aborts the whole
process, the studio included) and fills a short file with uninitialised
memory. So before VTK sees a file, :func:`check_claims` reads its header
here, checks the claimed grid with :func:`limits.checked_grid` and, where the
format allows, that the file (or its inflated data) really holds that many
bytes. Returns the claimed ``(X, Y, Z)`` so the caller can compare with what
VTK returns.
"""

from __future__ import annotations

import gzip
import math
import re
import struct
import zlib
from pathlib import Path

from volanim_core.errors import FormatError
from volanim_core.limits import available_bytes, checked_grid, expect_bytes, human_bytes, whole_number

from ._inflate import inflate_capped

HEAD_BYTES = 1 << 20
_VTK_TYPES = {"int8": 1, "uint8": 1, "char": 1, "int16": 2, "uint16": 2, "int32": 4, "uint32": 4,
              "int64": 8, "uint64": 8, "float32": 4, "float64": 8, "idtype": 8}
_MET_TYPES = {"MET_CHAR": 1, "MET_UCHAR": 1, "MET_SHORT": 2, "MET_USHORT": 2, "MET_INT": 4, "MET_UINT": 4,
              "MET_LONG": 4, "MET_ULONG": 4, "MET_LONG_LONG": 8, "MET_ULONG_LONG": 8, "MET_FLOAT": 4,
              "MET_DOUBLE": 8}


def _head(path: Path) -> bytes:
    with path.open("rb") as fh:
        return fh.read(HEAD_BYTES)


def check_claims(path: Path, kind: str) -> tuple[int, int, int]:
    """Check the header of a file VTK is about to read; ``kind`` is its suffix (``.nii.gz`` whole)."""
    try:
        if kind == ".vti":
            return _vti(path)
        if kind in (".mha", ".mhd"):
            return _metaimage(path)
        if kind in (".nii", ".nii.gz"):
            return _nifti(path, kind == ".nii.gz")
        if kind == ".vtk":
            return _legacy_vtk(path)
    except OSError as exc:
        raise FormatError(path, f"cannot read file: {exc.strerror or exc}") from exc
    raise FormatError(path, f"unknown VTK format {kind!r}")


def _vti(path: Path) -> tuple[int, int, int]:
    text = _head(path).decode("latin-1")
    tag = re.search(r"<ImageData\b[^>]*>", text)
    if tag is None:
        raise FormatError(path, "not a VTK ImageData file (no <ImageData> element in its first MB)")
    extents = re.findall(r"\bWholeExtent\s*=\s*\"([^\"]*)\"", tag.group(0))
    if not extents:
        raise FormatError(path, "<ImageData> has no WholeExtent")
    types = re.findall(r"<DataArray\b[^>]*\btype\s*=\s*\"(\w+)\"", text)
    itemsize = max((_VTK_TYPES.get(t.lower(), 8) for t in types), default=1)
    dims = None
    for extent in [extents[0], *re.findall(r"<Piece\b[^>]*\bExtent\s*=\s*\"([^\"]*)\"", text)]:
        words = extent.split()
        if len(words) != 6:
            raise FormatError(path, f"an extent must be six whole numbers, got {extent!r}")
        e = [whole_number(path, w, "an extent") for w in words]
        grid = checked_grid(path, [e[1] - e[0] + 1, e[3] - e[2] + 1, e[5] - e[4] + 1], itemsize,
                            what="the extent's sizes")
        dims = dims or grid
    return dims


def metaimage_header(path: Path) -> tuple[dict[str, str], int]:
    """A MetaImage header's ``Key = Value`` fields (keys lower-case) and the offset of its first data
    byte (the end of the ElementDataFile line), from the file's first MB."""
    fields, offset = {}, 0
    for raw in _head(path).splitlines(keepends=True):
        offset += len(raw)
        line = raw.decode("latin-1").strip()
        if not line:
            continue
        key, sep, value = line.partition("=")
        if not sep:
            raise FormatError(path, f"expected 'Key = Value' in the MetaImage header, got {line[:60]!r}")
        fields[key.strip().lower()] = value.strip()
        if key.strip().lower() == "elementdatafile":
            return fields, offset
    raise FormatError(path, "the MetaImage header has no ElementDataFile line (is the file truncated?)")


def _metaimage(path: Path) -> tuple[int, int, int]:
    fields, end = metaimage_header(path)
    sizes = fields.get("dimsize", "").split()
    if fields.get("ndims", "3").strip() != "3" or len(sizes) != 3:
        raise FormatError(path, f"expected a 3-D MetaImage, got NDims {fields.get('ndims')!r}, "
                                f"DimSize {fields.get('dimsize')!r}")
    element = fields.get("elementtype", "").upper()
    if element not in _MET_TYPES:
        raise FormatError(path, f"MetaImage ElementType {fields.get('elementtype')!r} is missing or not supported")
    channels = whole_number(path, fields.get("elementnumberofchannels", "1"), "ElementNumberOfChannels")
    if not 1 <= channels <= 16:
        raise FormatError(path, f"ElementNumberOfChannels must be 1..16, got {channels}")
    itemsize = _MET_TYPES[element] * channels
    dims = checked_grid(path, sizes, itemsize, what="DimSize")
    want = math.prod(dims) * itemsize
    compressed = fields.get("compresseddata", "false").lower() == "true"
    data_file = fields["elementdatafile"]
    if data_file.upper() == "LOCAL":
        have = path.stat().st_size - end
        if compressed:
            if have <= 0:
                raise FormatError(path, "the MetaImage has no compressed data after its header")
            _inflated_size_at_least(path, path, end, want)
        else:
            expect_bytes(path, have, want, "the MetaImage data")
        return dims
    if data_file.upper().startswith("LIST") or "%" in data_file:
        raise FormatError(path, f"MetaImage ElementDataFile {data_file!r} (slice lists) is not supported")
    data_path = path.parent / data_file
    if not data_path.is_file():
        raise FormatError(path, f"its data file {data_path} does not exist")
    if compressed:
        _inflated_size_at_least(path, data_path, 0, want)
    else:
        expect_bytes(path, data_path.stat().st_size, want, f"its data file {data_path.name}")
    return dims


def _inflated_size_at_least(path: Path, data_path: Path, offset: int, want: int) -> None:
    """Inflate (and throw away) compressed data, refusing it when it holds fewer than ``want`` bytes."""
    with data_path.open("rb") as fh:
        fh.seek(offset)
        got = sum(len(chunk) for chunk in inflate_capped(path, fh, want))
    if got < want:
        raise FormatError(path, f"its compressed data holds {got:,} bytes, the header says {want:,} "
                                "(the file is truncated)")


_NIFTI_TYPES = {2: 1, 4: 2, 8: 4, 16: 4, 64: 8, 256: 1, 512: 2, 768: 4, 1024: 8, 1280: 8, 128: 3, 2304: 4}


def _nifti(path: Path, gz: bool) -> tuple[int, int, int]:
    opener = gzip.open if gz else open
    try:
        with opener(path, "rb") as fh:
            head = fh.read(544)
    except (OSError, EOFError, zlib.error) as exc:
        raise FormatError(path, f"cannot read the NIfTI header: {exc}") from None
    if len(head) < 348:
        raise FormatError(path, f"has {len(head)} header bytes; a NIfTI header has 348 (the file is truncated)")
    for endian in "<>":
        size = struct.unpack(endian + "i", head[:4])[0]
        if size in (348, 540):
            break
    else:
        raise FormatError(path, "not a NIfTI file (sizeof_hdr is neither 348 nor 540)")
    if size == 348:
        dim = struct.unpack(endian + "8h", head[40:56])
        datatype, bitpix = struct.unpack(endian + "hh", head[70:74])
        vox_offset = struct.unpack(endian + "f", head[108:112])[0]
        magic = head[344:347]
    else:
        if len(head) < 540:
            raise FormatError(path, "the NIfTI-2 header is truncated")
        datatype, bitpix = struct.unpack(endian + "hh", head[12:16])
        dim = struct.unpack(endian + "8q", head[16:80])
        vox_offset = struct.unpack(endian + "q", head[168:176])[0]
        magic = head[4:7]
    if not 1 <= dim[0] <= 7:
        raise FormatError(path, f"NIfTI dim[0] (the number of dimensions) must be 1..7, got {dim[0]}")
    sizes = [dim[i] if i <= dim[0] else 1 for i in (1, 2, 3)]
    extra = [dim[i] for i in range(4, dim[0] + 1)]
    if any(d != 1 for d in extra):
        raise FormatError(path, f"a NIfTI with more than three dimensions ({dim[1:dim[0] + 1]}) is not supported")
    if datatype not in _NIFTI_TYPES:
        raise FormatError(path, f"NIfTI datatype {datatype} is not supported")
    itemsize = _NIFTI_TYPES[datatype]
    dims = checked_grid(path, sizes, itemsize, what="NIfTI dimensions")
    want = math.prod(dims) * itemsize
    if magic in (b"ni1", b"ni2"):
        raise FormatError(path, "a NIfTI header/image pair (.hdr + .img) is not supported; convert to .nii")
    if not (math.isfinite(vox_offset) and 0 <= vox_offset < 2**40):
        raise FormatError(path, f"NIfTI vox_offset {vox_offset} is not a valid byte offset")
    start = max(int(vox_offset), size + 4 if size == 348 else size)
    if gz:
        _inflated_size_at_least(path, path, 0, start + want)
    else:
        have = path.stat().st_size - start
        if have < want:
            expect_bytes(path, have, want, "the NIfTI data")
    return dims


def _legacy_vtk(path: Path) -> tuple[int, int, int]:
    text = _head(path)[:4096].decode("latin-1")
    m = re.search(r"^DIMENSIONS\s+(\S+)\s+(\S+)\s+(\S+)", text, re.MULTILINE)
    if "STRUCTURED_POINTS" not in text or m is None:
        raise FormatError(path, "expected a legacy VTK STRUCTURED_POINTS file with DIMENSIONS")
    return checked_grid(path, m.groups(), 8, what="DIMENSIONS")


#: A mesh element takes at least a byte in .ply and .stl; compressed .vtp data may inflate, so its
#: counts get this much room over the file's size (and must still fit in memory).
_VTP_INFLATION = 1024


def check_mesh_claims(path: Path) -> None:
    """Refuse counts a mesh header claims but its file cannot hold, before VTK allocates for them
    (a PLY claiming 2^31 vertices made VTK abort the process). ``.obj`` has no counts to check."""
    path = Path(path)
    size = path.stat().st_size
    head = _head(path)
    suffix = path.suffix.lower()
    claims: list[tuple[str, int, int]] = []  # (what, count, the most the file can hold)
    if suffix == ".ply":
        end = head.find(b"end_header")
        if not head.startswith(b"ply") or end < 0:
            raise FormatError(path, "is not a PLY file (it must start with 'ply' and have an end_header)")
        for m in re.finditer(rb"^element\s+(\S+)\s+(\d+)", head[:end], flags=re.M):
            claims.append((f"{m[1].decode('ascii', 'replace')} elements", int(m[2]), size))
    elif suffix == ".stl" and not head.lstrip().startswith(b"solid"):  # binary: 80 bytes, a count, 50 a triangle
        if size < 84:
            raise FormatError(path, f"is {size} bytes: too short for a binary STL (84 bytes of header)")
        expect_bytes(path, size, 84 + 50 * int.from_bytes(head[80:84], "little"), "the binary STL")
    elif suffix == ".vtp":
        for m in re.finditer(rb'NumberOf(Points|Verts|Lines|Strips|Polys)="(\d+)"', head):
            claims.append((m[1].decode().lower(), int(m[2]), size * _VTP_INFLATION))
    free = available_bytes()
    for what, count, most in claims:
        if count > most:
            raise FormatError(path, f"claims {count} {what}, more than its {size} bytes can hold")
        if free is not None and 24 * count > free:
            raise FormatError(path, f"claims {count} {what} ({human_bytes(24 * count)}), more than the memory free")
