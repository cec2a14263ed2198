"""NRRD read/write (raw and gzip encodings), our own.

VTK 9's vtkNrrdReader reads a plain 3-D scalar NRRD as a 2-D image with the
first axis as components, so NRRD does not go through VTK. The format is a
text header, a blank line, then the voxels with the first axis fastest --
exactly our ``order="F"`` layout.
"""

from __future__ import annotations

import math
import os
import re
from pathlib import Path

import numpy as np

from volanim_core.errors import FormatError
from volanim_core.limits import checked_grid, expect_bytes

from ._atomic import atomic_open
from ._inflate import inflate_capped
from ._text import is_number

_TYPES = {
    "uchar": "u1", "unsigned char": "u1", "uint8": "u1", "uint8_t": "u1",
    "signed char": "i1", "int8": "i1", "int8_t": "i1",
    "short": "i2", "short int": "i2", "signed short": "i2", "int16": "i2", "int16_t": "i2",
    "ushort": "u2", "unsigned short": "u2", "uint16": "u2", "uint16_t": "u2",
    "int": "i4", "signed int": "i4", "int32": "i4", "int32_t": "i4",
    "uint": "u4", "unsigned int": "u4", "uint32": "u4", "uint32_t": "u4",
    "float": "f4", "double": "f8",
}
_WRITE_TYPES = {"u1": "uint8", "i1": "int8", "u2": "uint16", "i2": "int16",
                "u4": "uint32", "i4": "int32", "f4": "float", "f8": "double"}


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


def _read_header(path: Path, fh) -> tuple[dict, dict]:
    """``(fields, line numbers)`` of the header; ``fh`` is left at the first data byte.

    Accepts a UTF-8 byte-order mark and CRLF line ends (files from Windows editors).
    """
    first = fh.readline(64)
    if first.startswith(b"\xef\xbb\xbf"):
        first = first[3:]
    if not first.startswith(b"NRRD000"):
        raise FormatError(path, "expected a NRRD file starting with 'NRRD000'", 1)
    fields, lines, number, used = {}, {}, 1, len(first)
    while True:
        raw = fh.readline(MAX_HEADER_BYTES)
        number += 1
        used += len(raw)
        if used > MAX_HEADER_BYTES:
            raise FormatError(path, f"the NRRD header is longer than {MAX_HEADER_BYTES} bytes", number)
        if not raw:
            raise FormatError(path, "the NRRD header has no blank line before the data", number)
        line = raw.decode("latin-1").rstrip("\r\n")
        if not line.strip():
            return fields, lines
        if line.startswith("#") or ":=" in line:
            continue
        key, sep, value = line.partition(":")
        if not sep:
            raise FormatError(path, f"expected 'field: value', got {line!r}", number)
        fields[key.strip().lower()] = value.strip()
        lines[key.strip().lower()] = number


def _inflate(path: Path, fh, want: int) -> bytes:
    """Inflate gzip data, refusing (without inflating further) as soon as it exceeds ``want`` bytes."""
    body = b"".join(inflate_capped(path, fh, want + 1))
    if len(body) > want:
        raise FormatError(path, f"the gzip-encoded NRRD data inflates to more than the {want:,} bytes its header says")
    if len(body) < want:
        raise FormatError(path, f"the gzip-encoded NRRD data ends early ({len(body):,} of {want:,} bytes)")
    return body


def read_nrrd(path: str | Path):
    """Read a 3-D NRRD: ``(data[x, y, z], origin, spacing)``.

    The header's sizes are checked against the input limits and the file size
    before any voxel is read; gzip data are inflated with that size as a cap.
    """
    path = Path(path)
    try:
        with path.open("rb") as fh:
            return _read_nrrd(path, fh)
    except OSError as exc:
        raise FormatError(path, f"cannot read file: {exc.strerror or exc}") from exc


def _read_nrrd(path: Path, fh):
    fields, lines = _read_header(path, fh)
    if "type" not in fields or fields["type"].lower() not in _TYPES:
        raise FormatError(path, f"NRRD type {fields.get('type')!r} is missing or not supported", lines.get("type"))
    dtype = np.dtype(_TYPES[fields["type"].lower()])
    if "sizes" not in fields:
        raise FormatError(path, "the NRRD header lacks 'sizes'")
    words = fields["sizes"].split()
    # An RGB volume is 4-D with the colour axis first (kinds: RGB-color domain domain domain).
    channels = 3 if fields.get("dimension", "").strip() == "4" and words[:1] == ["3"] and dtype.itemsize == 1 else 1
    if channels == 3:
        words = words[1:]
    elif fields.get("dimension", "3").strip() != "3":
        raise FormatError(path, f"expected a 3-D NRRD (or a 4-D one with 3 colour components first), got "
                                f"dimension {fields['dimension']!r}", lines["dimension"])
    sizes = checked_grid(path, words, dtype.itemsize * channels, line=lines["sizes"], what="NRRD sizes")
    endian = fields.get("endian", "little").lower()
    if endian not in ("little", "big"):
        raise FormatError(path, f"NRRD endian must be little or big, got {endian!r}", lines.get("endian"))
    if endian == "big":
        dtype = dtype.newbyteorder(">")
    if "data file" in fields or "datafile" in fields:
        raise FormatError(path, "detached NRRD data files are not supported")
    try:
        origin, spacing = _geometry(fields)
    except (ValueError, IndexError, ZeroDivisionError):
        raise FormatError(path, "bad 'space directions', 'spacings' or 'space origin' in the NRRD header: "
                                "expected three finite vectors (x,y,z) with non-zero length") from None
    want = math.prod(sizes) * dtype.itemsize * channels
    encoding = fields.get("encoding", "raw").lower()
    if encoding in ("gzip", "gz"):
        body = _inflate(path, fh, want)
    elif encoding == "raw":
        have = os.fstat(fh.fileno()).st_size - fh.tell()
        expect_bytes(path, have, want, "the NRRD data")
        body = fh.read(want)
    else:
        raise FormatError(path, f"NRRD encoding {encoding!r} is not supported (raw, gzip)", lines.get("encoding"))
    expect_bytes(path, len(body), want, "the NRRD data")
    data = np.frombuffer(body, dtype).astype(dtype.newbyteorder("="), copy=True)
    if channels == 3:  # bytes: channel fastest, then x, y, z
        return data.reshape(*sizes[::-1], 3).transpose(2, 1, 0, 3), origin, spacing
    return data.reshape(sizes, order="F"), origin, spacing


def _geometry(fields: dict) -> tuple[tuple, tuple]:
    spacing = [1.0, 1.0, 1.0]
    if "space directions" in fields:
        text = re.sub(r"^\s*none\s+", "", fields["space directions"])  # a colour axis has no direction
        vecs = re.findall(r"\([^()]*\)", text)
        if len(vecs) != 3 or re.sub(r"\([^()]*\)", "", text).strip():
            raise ValueError("need three vectors and nothing else")
        spacing = []
        for v in vecs:
            vec = _vector(v)
            if len(vec) != 3:
                raise ValueError("need three components")
            spacing.append(math.sqrt(sum(c * c for c in vec)))
    elif "spacings" in fields:
        spacing = [_number(s) for s in fields["spacings"].split()]
    origin = _vector(fields["space origin"]) if "space origin" in fields else [0.0, 0.0, 0.0]
    if len(origin) != 3 or len(spacing) != 3:
        raise ValueError("need three values")
    if not all(math.isfinite(v) for v in (*origin, *spacing)) or min(spacing) <= 0:
        raise ValueError("need finite values and positive spacings")
    return tuple(origin), tuple(spacing)


def write_nrrd(path: str | Path, vol: np.ndarray, origin=(0, 0, 0), spacing=(1, 1, 1)) -> None:
    """Write a 3-D NRRD (raw encoding, little endian) atomically."""
    name = _WRITE_TYPES.get(vol.dtype.str[1:])
    if name is None:
        raise ValueError(f"cannot write {vol.dtype} to .nrrd")
    sx, sy, sz = (float(s) for s in spacing)
    rgb = vol.ndim == 4  # [x, y, z, 3]: written with the colour axis first, as NRRD readers expect
    header = (
        "NRRD0004\n# written by volanim\n"
        f"type: {name}\ndimension: {4 if rgb else 3}\nspace dimension: 3\n"
        f"sizes: {'3 ' if rgb else ''}{vol.shape[0]} {vol.shape[1]} {vol.shape[2]}\n"
        f"space directions: {'none ' if rgb else ''}({sx!r},0,0) (0,{sy!r},0) (0,0,{sz!r})\n"
        f"kinds: {'RGB-color ' if rgb else ''}domain domain domain\nendian: little\nencoding: raw\n"
        f"space origin: ({float(origin[0])!r},{float(origin[1])!r},{float(origin[2])!r})\n\n"
    )
    data = vol.transpose(2, 1, 0, 3) if rgb else vol.T
    with atomic_open(path, "wb") as fh:
        fh.write(header.encode("ascii"))
        fh.write(np.ascontiguousarray(data).astype(vol.dtype.newbyteorder("<")).tobytes())
