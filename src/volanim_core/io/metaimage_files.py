"""MetaImage (``.mha`` with its data, ``.mhd`` beside a raw file), read and written here.

    KEY = VALUE header lines ... ElementDataFile = LOCAL | name
        --sizes checked (vtk_headers.check_claims)--> raw or zlib data --x fastest--> vol[x, y, z]
        + Geometry from ElementSpacing, Offset and TransformMatrix

VTK's reader drops the direction matrix (a scan with oblique or flipped axes lands mis-placed), and
SimpleITK, which reads it right, is a 260 MB dependency for a ten-line text header; the tests
compare this reader with SimpleITK's on files SimpleITK writes. ``TransformMatrix`` lists the index
axes' direction vectors one after the other (ITK's MetaImageIO), i.e. the direction matrix by
columns.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from volanim_core.errors import FormatError
from volanim_core.geometry import IDENTITY, Geometry

from ._inflate import inflate_capped
from .atomic import atomic_open
from .vtk_headers import check_claims, metaimage_header

_MET_DTYPES = {"MET_CHAR": "i1", "MET_UCHAR": "u1", "MET_SHORT": "i2", "MET_USHORT": "u2", "MET_INT": "i4",
               "MET_UINT": "u4", "MET_LONG": "i4", "MET_ULONG": "u4", "MET_LONG_LONG": "i8",
               "MET_ULONG_LONG": "u8", "MET_FLOAT": "f4", "MET_DOUBLE": "f8"}
_WRITE = {v: k for k, v in reversed(list(_MET_DTYPES.items()))}


def _floats(path: Path, fields: dict, keys: tuple[str, ...], n: int, default):
    for key in keys:
        if key in fields:
            try:
                values = [float(v) for v in fields[key].split()]
            except ValueError:
                values = []
            if len(values) != n or not all(math.isfinite(v) for v in values):
                raise FormatError(path, f"MetaImage {key} must be {n} finite numbers, got {fields[key]!r}")
            return values
    return default


def read_metaimage(path: str | Path):
    """Read a 3-D ``.mha``/``.mhd``: ``(data[x, y, z] (or [x, y, z, 3] for RGB), Geometry)``."""
    path = Path(path)
    dims = check_claims(path, path.suffix.lower())  # sizes against the file and memory, before anything
    fields, end = metaimage_header(path)
    dtype = np.dtype(_MET_DTYPES[fields["elementtype"].upper()])
    msb = fields.get("binarydatabyteordermsb", fields.get("elementbyteordermsb", "false"))
    if msb.lower() == "true":
        dtype = dtype.newbyteorder(">")
    channels = int(fields.get("elementnumberofchannels", "1"))
    spacing = _floats(path, fields, ("elementspacing", "elementsize"), 3, [1.0, 1.0, 1.0])
    origin = _floats(path, fields, ("offset", "position", "origin"), 3, [0.0, 0.0, 0.0])
    matrix = _floats(path, fields, ("transformmatrix", "rotation", "orientation"), 9, list(IDENTITY.direction))
    try:
        geometry = Geometry(spacing, origin, tuple(np.asarray(matrix).reshape(3, 3).T.reshape(-1)))
    except ValueError as exc:
        raise FormatError(path, f"bad MetaImage geometry: {exc}") from None
    want = math.prod(dims) * dtype.itemsize * channels
    data_file = fields["elementdatafile"]
    source, start = (path, end) if data_file.upper() == "LOCAL" else (path.parent / data_file, 0)
    if data_file.upper() != "LOCAL":
        skip = int(fields.get("headersize", "0") or 0)
        start = max(source.stat().st_size - want, 0) if skip == -1 else skip
    with source.open("rb") as fh:
        fh.seek(start)
        if fields.get("compresseddata", "false").lower() == "true":
            body = b"".join(inflate_capped(path, fh, want))
        else:
            body = fh.read(want)
    if len(body) < want:
        raise FormatError(path, f"its data hold {len(body):,} bytes, the header says {want:,} (the file is truncated)")
    data = np.frombuffer(body, dtype).astype(dtype.newbyteorder("="), copy=True)
    if channels == 1:
        return data.reshape(dims, order="F"), geometry
    vol = data.reshape(*dims[::-1], channels).transpose(2, 1, 0, 3)
    if channels in (3, 4) and dtype == np.uint8:
        return np.asfortranarray(vol[..., :3]) if channels == 4 else vol, geometry
    return np.asfortranarray(vol[..., 0]), geometry  # other vector data: the first component


def write_metaimage(path: str | Path, vol: np.ndarray, geometry: Geometry = IDENTITY) -> None:
    """Write a ``.mha`` (header and raw data in one file) atomically."""
    vol = np.asarray(vol)
    element = _WRITE.get(vol.dtype.str[1:])
    if element is None:
        raise ValueError(f"cannot write {vol.dtype} to .mha")
    rgb = vol.ndim == 4
    matrix = geometry.matrix.T.reshape(-1)  # the axes' vectors one after the other (ITK's order)

    def fmt(values):
        return " ".join(repr(float(v)) for v in values)

    header = (
        "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\nCompressedData = False\n"
        f"TransformMatrix = {fmt(matrix)}\nOffset = {fmt(geometry.origin)}\nCenterOfRotation = 0 0 0\n"
        f"ElementSpacing = {fmt(geometry.spacing)}\n"
        f"DimSize = {vol.shape[0]} {vol.shape[1]} {vol.shape[2]}\n"
        + (f"ElementNumberOfChannels = {vol.shape[3]}\n" if rgb else "")
        + f"ElementType = {element}\nElementDataFile = LOCAL\n"
    )
    data = vol.transpose(2, 1, 0, 3) if rgb else vol.T
    with atomic_open(path, "wb", size=len(header) + vol.nbytes) as fh:
        fh.write(header.encode("ascii"))
        fh.write(np.ascontiguousarray(data).astype(vol.dtype.newbyteorder("<")).tobytes())
