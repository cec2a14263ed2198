"""NRRD read/write (raw and gzip encodings), our own.

VTK 9's vtkNrrdReader reads a plain 3-D scalar NRRD as a 2-D image with the
first axis as components, so NRRD does not go through VTK. The format is a
text header, a blank line, then the voxels with the first axis fastest --
exactly our ``order="F"`` layout.
"""

from __future__ import annotations

import gzip
import re
import zlib
from pathlib import Path

import numpy as np

from volanim_core.errors import FormatError

from ._atomic import atomic_open

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


def _vector(text: str) -> list[float]:
    return [float(v) for v in text.strip("() ").split(",")]


def read_nrrd(path: str | Path):
    """Read a 3-D NRRD: ``(data[x, y, z], origin, spacing)``."""
    path = Path(path)
    raw = path.read_bytes()
    if not raw.startswith(b"NRRD000"):
        raise FormatError(path, "expected a NRRD file starting with 'NRRD000'", 1)
    end = raw.find(b"\n\n")
    if end < 0:
        raise FormatError(path, "the NRRD header has no blank line before the data")
    fields = {}
    for number, line in enumerate(raw[:end].decode("latin-1").splitlines()[1:], start=2):
        if line.startswith("#") or not line.strip() or ":=" in line:
            continue
        key, sep, value = line.partition(":")
        if not sep:
            raise FormatError(path, f"expected 'field: value', got {line!r}", number)
        fields[key.strip().lower()] = value.strip()
    try:
        dtype = np.dtype(_TYPES[fields["type"].lower()])
        sizes = [int(s) for s in fields["sizes"].split()]
    except KeyError as exc:
        raise FormatError(path, f"NRRD header lacks or has an unknown {exc}") from None
    except ValueError:
        raise FormatError(path, f"bad NRRD sizes {fields.get('sizes')!r}") from None
    if len(sizes) != 3:
        raise FormatError(path, f"expected a 3-D NRRD, got sizes {sizes}")
    if fields.get("endian", "little") == "big":
        dtype = dtype.newbyteorder(">")
    body = raw[end + 2 :]
    if "data file" in fields or "datafile" in fields:
        raise FormatError(path, "detached NRRD data files are not supported")
    encoding = fields.get("encoding", "raw").lower()
    if encoding in ("gzip", "gz"):
        try:
            body = gzip.decompress(body)
        except (OSError, EOFError, zlib.error) as exc:
            raise FormatError(path, f"the gzip-encoded NRRD data is corrupt: {exc}") from None
    elif encoding != "raw":
        raise FormatError(path, f"NRRD encoding {encoding!r} is not supported (raw, gzip)")
    want = int(np.prod(sizes)) * dtype.itemsize
    if len(body) != want:
        raise FormatError(path, f"NRRD data has {len(body)} bytes, expected {want} for sizes {sizes}")
    data = np.frombuffer(body, dtype).astype(dtype.newbyteorder("="), copy=True).reshape(sizes, order="F")
    try:
        origin, spacing = _geometry(fields)
    except (ValueError, IndexError):
        raise FormatError(path, "bad 'space directions', 'spacings' or 'space origin' in the NRRD header") from None
    return data, origin, spacing


def _geometry(fields: dict) -> tuple[tuple, tuple]:
    spacing = [1.0, 1.0, 1.0]
    if "space directions" in fields:
        vecs = re.findall(r"\(([^)]*)\)", fields["space directions"])
        spacing = [float(np.linalg.norm(_vector(v))) for v in vecs[:3]] or spacing
    elif "spacings" in fields:
        spacing = [float(s) for s in fields["spacings"].split()]
    origin = _vector(fields["space origin"]) if "space origin" in fields else [0.0, 0.0, 0.0]
    if len(origin) != 3 or len(spacing) != 3:
        raise ValueError("need three values")
    return tuple(origin), tuple(spacing)


def write_nrrd(path: str | Path, vol: np.ndarray, origin=(0, 0, 0), spacing=(1, 1, 1)) -> None:
    """Write a 3-D NRRD (raw encoding, little endian) atomically."""
    name = _WRITE_TYPES.get(vol.dtype.str[1:])
    if name is None:
        raise ValueError(f"cannot write {vol.dtype} to .nrrd")
    sx, sy, sz = (float(s) for s in spacing)
    header = (
        "NRRD0004\n# written by volanim\n"
        f"type: {name}\ndimension: 3\nspace dimension: 3\n"
        f"sizes: {vol.shape[0]} {vol.shape[1]} {vol.shape[2]}\n"
        f"space directions: ({sx!r},0,0) (0,{sy!r},0) (0,0,{sz!r})\n"
        "kinds: domain domain domain\nendian: little\nencoding: raw\n"
        f"space origin: ({float(origin[0])!r},{float(origin[1])!r},{float(origin[2])!r})\n\n"
    )
    with atomic_open(path, "wb") as fh:
        fh.write(header.encode("ascii"))
        fh.write(np.ascontiguousarray(vol.T).astype(vol.dtype.newbyteorder("<")).tobytes())
