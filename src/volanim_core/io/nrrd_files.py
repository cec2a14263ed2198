"""NRRD read/write, our own: every encoding (raw, gzip, bzip2, ascii), detached headers (``.nhdr``),
``line skip``/``byte skip``, full geometry (``space``, ``space directions``, ``space origin``) and
3D Slicer segmentations (``.seg.nrrd``, single-layer or layered).

    header (text, or a .nhdr) --sizes checked against the file and memory--> data (raw/gz/bz2/ascii)
        --x fastest = order "F"--> vol[x, y, z]     + Geometry (LPS) + segment names

Why not pynrrd (which the tests use as the oracle): it allocates what a header claims and inflates
gzip without a cap, so a 200-byte file can take the machine's memory; here the header's sizes are
checked against the input limits and the file before any voxel is read, and compressed data are
inflated with the claimed size as a cap. VTK 9's vtkNrrdReader reads a plain 3-D scalar NRRD as a
2-D image with the first axis as components, so NRRD does not go through VTK either.
"""

from __future__ import annotations

import bz2
import math
import os
import re
from pathlib import Path

import numpy as np

from volanim_core.errors import FormatError
from volanim_core.geometry import IDENTITY, Geometry
from volanim_core.limits import checked_grid, expect_bytes

from ._inflate import inflate_capped
from .atomic import atomic_open
from .text import is_number

_TYPES = {
    "uchar": "u1", "unsigned char": "u1", "uint8": "u1", "uint8_t": "u1",
    "signed char": "i1", "int8": "i1", "int8_t": "i1",
    "short": "i2", "short int": "i2", "signed short": "i2", "signed short int": "i2", "int16": "i2",
    "int16_t": "i2",
    "ushort": "u2", "unsigned short": "u2", "unsigned short int": "u2", "uint16": "u2", "uint16_t": "u2",
    "int": "i4", "signed int": "i4", "int32": "i4", "int32_t": "i4",
    "uint": "u4", "unsigned int": "u4", "uint32": "u4", "uint32_t": "u4",
    "longlong": "i8", "long long": "i8", "long long int": "i8", "signed long long": "i8",
    "signed long long int": "i8", "int64": "i8", "int64_t": "i8",
    "ulonglong": "u8", "unsigned long long": "u8", "unsigned long long int": "u8", "uint64": "u8",
    "uint64_t": "u8",
    "float": "f4", "double": "f8",
}
_WRITE_TYPES = {"u1": "uint8", "i1": "int8", "u2": "uint16", "i2": "int16",
                "u4": "uint32", "i4": "int32", "f4": "float", "f8": "double"}
#: NRRD's named spaces -> the sign of each axis against LPS (x left, y posterior, z superior).
_SPACES = {
    "left-posterior-superior": (1, 1, 1), "lps": (1, 1, 1),
    "right-anterior-superior": (-1, -1, 1), "ras": (-1, -1, 1),
    "left-anterior-superior": (1, -1, 1), "las": (1, -1, 1),
    "scanner-xyz": (1, 1, 1), "3d-right-handed": (1, 1, 1),
}

MAX_HEADER_BYTES = 1 << 20


def _number(text: str) -> float:
    text = text.strip()
    if not is_number(text):
        raise ValueError(text)
    return float(text)


def _vector(text: str) -> list[float]:
    text = text.strip()
    if not (text.startswith("(") and text.endswith(")")):
        raise ValueError(text)
    return [_number(v) for v in text[1:-1].split(",")]


def _read_header(path: Path, fh) -> tuple[dict, dict, dict]:
    """``(fields, line numbers, key/value pairs)`` of the header; ``fh`` is left at the first data
    byte (for a detached ``.nhdr``: at its end).

    Accepts a UTF-8 byte-order mark and CRLF line ends (files from Windows editors).
    """
    first = fh.readline(64)
    if first.startswith(b"\xef\xbb\xbf"):
        first = first[3:]
    if not first.startswith(b"NRRD000"):
        raise FormatError(path, "expected a NRRD file starting with 'NRRD000'", 1)
    fields, lines, pairs, number, used = {}, {}, {}, 1, len(first)
    while True:
        raw = fh.readline(MAX_HEADER_BYTES)
        number += 1
        used += len(raw)
        if used > MAX_HEADER_BYTES:
            raise FormatError(path, f"the NRRD header is longer than {MAX_HEADER_BYTES} bytes", number)
        line = raw.decode("latin-1").rstrip("\r\n")
        if not raw or not line.strip():  # a detached header may end without a blank line
            if not raw and not ("data file" in fields or "datafile" in fields):
                raise FormatError(path, "the NRRD header has no blank line before the data", number)
            return fields, lines, pairs
        if line.startswith("#"):
            continue
        if ":=" in line:
            key, _, value = line.partition(":=")
            pairs[key.strip()] = value.strip()
            continue
        key, sep, value = line.partition(":")
        if not sep:
            raise FormatError(path, f"expected 'field: value', got {line!r}", number)
        fields[key.strip().lower()] = value.strip()
        lines[key.strip().lower()] = number
        if key.strip().lower() in ("data file", "datafile") and value.strip().upper().startswith("LIST"):
            return fields, lines, pairs  # the header's other lines are the listed files' names (refused in _data)


def read_nrrd(path: str | Path, pairs: bool = False):
    """Read a 3-D NRRD: ``(data[x, y, z], Geometry, segments)``.

    ``segments`` maps label values to names for a 3D Slicer segmentation (``.seg.nrrd``; a layered
    one becomes one label volume, segment ``k`` as label ``k + 1``), else it is empty. The header's
    sizes are checked against the input limits and the file size before any voxel is read; gzip
    and bzip2 data are inflated with that size as a cap.
    """
    path = Path(path)
    try:
        with path.open("rb") as fh:
            return _read_nrrd(path, fh, pairs)
    except OSError as exc:
        raise FormatError(getattr(exc, "filename", None) or path, f"cannot read file: {exc.strerror or exc}") from exc


def _read_nrrd(path: Path, fh, with_pairs: bool = False):
    fields, lines, pairs = _read_header(path, fh)
    data, geometry, segments = _read_volume(path, fh, fields, lines, pairs)
    return (data, geometry, segments, pairs) if with_pairs else (data, geometry, segments)


def _read_volume(path: Path, fh, fields: dict, lines: dict, pairs: dict):
    if "type" not in fields or fields["type"].lower() not in _TYPES:
        raise FormatError(path, f"NRRD type {fields.get('type')!r} is missing or not supported", lines.get("type"))
    dtype = np.dtype(_TYPES[fields["type"].lower()])
    if "sizes" not in fields:
        raise FormatError(path, "the NRRD header lacks 'sizes'")
    words = fields["sizes"].split()
    dimension = fields.get("dimension", str(len(words))).strip()
    kinds = fields.get("kinds", "").lower().split()
    # A 4-D NRRD with a non-spatial first axis: RGB colour (3 bytes a voxel) or a layered segmentation.
    first_kind = kinds[0] if len(kinds) == 4 else ""
    layered = dimension == "4" and len(words) == 4 and (first_kind == "list" or _is_segmentation(pairs)) \
        and dtype.kind in "ui"
    channels = 3 if (dimension == "4" and words[:1] == ["3"] and dtype.itemsize == 1 and not layered) else 1
    layers = 1
    if layered:
        layers = int(words[0]) if words[0].isdigit() and 0 < int(words[0]) <= 256 else 0
        if not layers:
            raise FormatError(path, f"a layered segmentation needs 1..256 layers, got {words[0]!r}", lines["sizes"])
        words = words[1:]
    elif channels == 3:
        words = words[1:]
    elif dimension != "3":
        raise FormatError(path, f"expected a 3-D NRRD (or a 4-D one with 3 colour components or segmentation "
                                f"layers first), got dimension {fields.get('dimension')!r}", lines.get("dimension"))
    if len(words) != 3:
        raise FormatError(path, f"'sizes' has {len(words)} values for dimension {dimension}", lines["sizes"])
    sizes = checked_grid(path, words, dtype.itemsize * channels * layers, line=lines["sizes"], what="NRRD sizes")
    endian = fields.get("endian", "little").lower()
    if endian not in ("little", "big"):
        raise FormatError(path, f"NRRD endian must be little or big, got {endian!r}", lines.get("endian"))
    if endian == "big":
        dtype = dtype.newbyteorder(">")
    try:
        geometry = _geometry(fields, extra_axis=layered or channels == 3)
    except (ValueError, IndexError, ZeroDivisionError) as exc:
        raise FormatError(path, "bad 'space', 'space directions', 'spacings' or 'space origin' in the NRRD header: "
                                f"expected three finite, non-zero, orthogonal vectors (x,y,z) ({exc})") from None
    want = math.prod(sizes) * dtype.itemsize * channels * layers
    body = _data(path, fh, fields, lines, want, dtype, math.prod(sizes) * channels * layers)
    data = np.frombuffer(body, dtype).astype(dtype.newbyteorder("="), copy=True) if isinstance(body, bytes) else body
    if channels == 3:  # bytes: channel fastest, then x, y, z
        return data.reshape(*sizes[::-1], 3).transpose(2, 1, 0, 3), geometry, {}
    if layered:
        return _flatten_layers(path, data.reshape(*sizes[::-1], layers).transpose(2, 1, 0, 3), pairs), geometry, \
            _segment_names(pairs, layered=True)
    return data.reshape(sizes, order="F"), geometry, _segment_names(pairs, layered=False)


def _data(path: Path, fh, fields: dict, lines: dict, want: int, dtype, count: int):
    """The data's bytes (or, for ascii, the parsed array), from this file or a detached one."""
    data_file = fields.get("data file", fields.get("datafile"))
    if data_file is not None:
        name = data_file.strip()
        if name.upper().startswith("LIST") or len(name.split()) > 1:
            raise FormatError(path, f"NRRD 'data file: {name}' (a list of files) is not supported; "
                                    "give a single data file", lines.get("data file", lines.get("datafile")))
        data_path = path.parent / name
        if not data_path.is_file():
            what = "a folder, not a file" if data_path.is_dir() else "missing"
            raise FormatError(path, f"its data file {name} is {what} (looked for at {data_path.absolute()}): "
                                    "the header's 'data file:' line names it relative to the header's own folder; "
                                    "put the data file there (a detached header and its data travel together), "
                                    "or correct the line",
                              lines.get("data file", lines.get("datafile")))
        with data_path.open("rb") as dfh:
            return _read_body(data_path, dfh, fields, lines, want, dtype, count)
    return _read_body(path, fh, fields, lines, want, dtype, count)


def _read_body(path: Path, fh, fields: dict, lines: dict, want: int, dtype, count: int):
    line_skip = _skip(path, fields, lines, "line skip")
    for _ in range(line_skip):
        if not fh.readline(MAX_HEADER_BYTES):
            raise FormatError(path, f"'line skip: {line_skip}' skips past the end of the file")
    byte_skip = _skip(path, fields, lines, "byte skip", allow_minus_one=True)
    encoding = fields.get("encoding", "raw").lower()
    if encoding in ("gzip", "gz", "bzip2", "bz2"):
        if byte_skip > 0:
            fh.seek(byte_skip, os.SEEK_CUR)
        body = b"".join(_inflate(path, fh, want, bzip=encoding.startswith("b")))
        if len(body) > want:
            raise FormatError(path, f"the {encoding} NRRD data inflate to more than the {want:,} bytes its header says")
        if len(body) < want:
            raise FormatError(path, f"the {encoding} NRRD data end early ({len(body):,} of {want:,} bytes)")
        return body
    if encoding == "raw":
        size = os.fstat(fh.fileno()).st_size
        if byte_skip == -1:  # the data are the file's last bytes
            if size < want:
                expect_bytes(path, size, want, "the NRRD data")
            fh.seek(size - want)
        elif byte_skip:
            fh.seek(byte_skip, os.SEEK_CUR)
        expect_bytes(path, size - fh.tell(), want, "the NRRD data")
        return fh.read(want)
    if encoding in ("ascii", "text", "txt"):
        size = os.fstat(fh.fileno()).st_size - fh.tell()
        if size > 64 * want + (1 << 20):  # a number and its separator: far fewer than 64 bytes a byte of data
            raise FormatError(path, f"its ascii data are {size:,} bytes, far more than {count:,} numbers need")
        words = fh.read().split()
        if len(words) != count:
            raise FormatError(path, f"its ascii data hold {len(words):,} numbers, the header says {count:,}")
        try:
            return np.array([float(w) for w in words]).astype(dtype.newbyteorder("="))
        except ValueError:
            raise FormatError(path, "its ascii data hold something that is not a number") from None
    raise FormatError(path, f"NRRD encoding {encoding!r} is not supported (raw, gzip, bzip2, ascii)",
                      lines.get("encoding"))


def _skip(path: Path, fields: dict, lines: dict, key: str, allow_minus_one: bool = False) -> int:
    text = fields.get(key, fields.get(key.replace(" ", ""), "0")).strip()
    lowest = -1 if allow_minus_one else 0
    if not re.fullmatch(r"-?[0-9]{1,12}", text) or int(text) < lowest:
        raise FormatError(path, f"'{key}' must be a whole number >= {lowest}, got {text!r}", lines.get(key))
    return int(text)


def _inflate(path: Path, fh, want: int, *, bzip: bool):
    """Inflated chunks, stopping after ``want + 1`` bytes: a bomb is refused without inflating it."""
    if not bzip:
        yield from inflate_capped(path, fh, want + 1)
        return
    inflater, done = bz2.BZ2Decompressor(), 0
    try:
        while done <= want and not inflater.eof:
            chunk = fh.read(1 << 20) if inflater.needs_input else b""
            if inflater.needs_input and not chunk:
                return
            out = inflater.decompress(chunk, max_length=min(want + 1 - done, 4 << 20))
            done += len(out)
            yield out
    except (OSError, EOFError, ValueError) as exc:
        raise FormatError(path, f"its bzip2 data are corrupt: {exc}") from None


def _geometry(fields: dict, *, extra_axis: bool) -> Geometry:
    """The grid's :class:`Geometry` in LPS from ``space``, ``space directions``/``spacings`` and ``space origin``."""
    if "space directions" in fields:
        text = re.sub(r"^\s*none\s+", "", fields["space directions"]) if extra_axis else fields["space directions"]
        vecs = re.findall(r"\([^()]*\)", text)
        if len(vecs) != 3 or re.sub(r"\([^()]*\)", "", text).strip():
            raise ValueError("need three vectors and nothing else")
        columns = np.array([_vector(v) for v in vecs], np.float64).T  # column k: index axis k in space
        if columns.shape != (3, 3):
            raise ValueError("need three components")
    else:
        spacing = [1.0, 1.0, 1.0]
        if "spacings" in fields:
            words = fields["spacings"].split()
            spacing = [_number(s) for s in (words[1:] if extra_axis and len(words) == 4 else words)]
        if len(spacing) != 3:
            raise ValueError("need three spacings")
        columns = np.diag(spacing)
    origin = np.array(_vector(fields["space origin"]) if "space origin" in fields else [0.0, 0.0, 0.0])
    if origin.shape != (3,) or not np.isfinite(origin).all() or not np.isfinite(columns).all():
        raise ValueError("need three finite values")
    space = fields.get("space", "left-posterior-superior").strip().lower()
    if space not in _SPACES:
        raise ValueError(f"space {space!r} is not a 3-D patient space volanim knows")
    signs = np.array(_SPACES[space], np.float64)  # this space's axes in LPS
    affine = np.eye(4)
    affine[:3, :3] = columns * signs[:, None]
    affine[:3, 3] = origin * signs
    return Geometry.from_affine(affine)


def _is_segmentation(pairs: dict) -> bool:
    return any(re.fullmatch(r"Segment\d+_Name", k) for k in pairs)


def _segments(pairs: dict) -> list[dict]:
    """``[{'name', 'label', 'layer'}]`` of a ``.seg.nrrd``'s ``SegmentN_*`` pairs, in N order."""
    out = []
    for key in sorted((k for k in pairs if re.fullmatch(r"Segment\d+_Name", k)), key=lambda k: int(k[7:-5])):
        n = key[7:-5]
        label = pairs.get(f"Segment{n}_LabelValue", str(int(n) + 1)).strip()
        layer = pairs.get(f"Segment{n}_Layer", "0").strip()
        out.append({"name": pairs[key].strip() or f"Segment{n}",
                    "label": int(label) if label.isdigit() else int(n) + 1,
                    "layer": int(layer) if layer.isdigit() else 0})
    return out


def _segment_names(pairs: dict, *, layered: bool) -> dict[int, str]:
    segs = _segments(pairs)
    if layered:  # _flatten_layers numbers the segments 1, 2, ...
        return {k + 1: s["name"] for k, s in enumerate(segs)}
    return {s["label"]: s["name"] for s in segs}


def _flatten_layers(path: Path, layers: np.ndarray, pairs: dict) -> np.ndarray:
    """One label volume from a layered segmentation ``[x, y, z, layer]``: segment k (file order) as
    label k + 1; where segments overlap (they may, on different layers) the later one wins."""
    segs = _segments(pairs)
    if not segs:  # a plain list of label layers: the first non-zero layer's label
        out = np.zeros(layers.shape[:3], layers.dtype, order="F")
        for k in range(layers.shape[3] - 1, -1, -1):
            out = np.where(layers[..., k] != 0, layers[..., k], out)
        return np.asfortranarray(out)
    dtype = np.uint8 if len(segs) < 256 else np.uint16
    out = np.zeros(layers.shape[:3], dtype, order="F")
    for k, s in enumerate(segs):
        if not 0 <= s["layer"] < layers.shape[3]:
            raise FormatError(path, f"segment {s['name']!r} is on layer {s['layer']}, the file has "
                                    f"{layers.shape[3]} layers")
        out[layers[..., s["layer"]] == s["label"]] = k + 1
    return out


def write_nrrd(path: str | Path, vol: np.ndarray, geometry: Geometry = IDENTITY, pairs: dict | None = None) -> None:
    """Write a 3-D NRRD (raw encoding, little endian, LPS space) atomically; ``pairs``: ``key:=value`` lines.

    ``[x, y, z, 3]``: uint8 is RGB colour; floats are a vector per voxel in LPS (a displacement field,
    which 3D Slicer opens as a grid transform and ITK as a DisplacementFieldTransform)."""
    name = _WRITE_TYPES.get(vol.dtype.str[1:])
    if name is None:
        raise ValueError(f"cannot write {vol.dtype} to .nrrd")
    cols = geometry.matrix * np.asarray(geometry.spacing)
    dirs = " ".join("(" + ",".join(repr(float(v)) for v in cols[:, k]) + ")" for k in range(3))
    o = ",".join(repr(float(v)) for v in geometry.origin)
    rgb = vol.ndim == 4  # [x, y, z, 3]: written with the colour axis first, as NRRD readers expect
    kind = "RGB-color " if vol.dtype == np.uint8 else "vector "
    header = (
        "NRRD0004\n# written by volanim\n"
        f"type: {name}\ndimension: {4 if rgb else 3}\nspace: left-posterior-superior\n"
        f"sizes: {'3 ' if rgb else ''}{vol.shape[0]} {vol.shape[1]} {vol.shape[2]}\n"
        f"space directions: {'none ' if rgb else ''}{dirs}\n"
        f"kinds: {kind if rgb else ''}domain domain domain\nendian: little\nencoding: raw\n"
        f"space origin: ({o})\n"
        + "".join(f"{k}:={v}\n" for k, v in (pairs or {}).items()) + "\n"
    )
    data = vol.transpose(2, 1, 0, 3) if rgb else vol.T
    with atomic_open(path, "wb", size=len(header) + vol.nbytes) as fh:
        fh.write(header.encode("ascii"))
        fh.write(np.ascontiguousarray(data).astype(vol.dtype.newbyteorder("<")).tobytes())
