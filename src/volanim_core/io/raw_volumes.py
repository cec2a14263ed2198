"""Raw volumes: ``.vol`` (bare uint8 voxels) and ``.VOL`` (100-byte header).

Bytes are x fastest, then y, then z; in memory ``vol[x, y, z]`` is the bytes
viewed with ``order="F"``. A colour volume has 3 bytes per voxel (R, G, B, then
the next voxel) and the same names and header; the file size tells which it is,
and in memory it is ``vol[x, y, z, channel]``. Header add/remove and counting stream in chunks so
they never hold a whole volume (the old AddHeader / rmhdr / Count).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np

from volanim_core.errors import FormatError
from volanim_core.limits import checked_grid

from .atomic import atomic_open

HEADER_BYTES = 100
_NAME_DIMS = re.compile(r"\.(\d+)x(\d+)x(\d+)\.vol$", re.IGNORECASE)
CHUNK = 1 << 24


def dims_from_name(path: str | Path) -> tuple[int, int, int] | None:
    """Dimensions from the ``NAME.XxYxZ.vol`` convention, or None."""
    m = _NAME_DIMS.search(Path(path).name)
    return tuple(int(g) for g in m.groups()) if m else None


def raw_name_for(path: str | Path, shape) -> Path:
    """Where a volume of ``shape`` is written when the user asked for ``path``.

    A headerless ``.vol`` cannot say its size, so one named without it becomes
    ``NAME.XxYxZ.vol`` (the convention every reader here understands); a name whose
    size disagrees with the volume is refused. Other names are kept.
    """
    path = Path(path)
    if path.suffix != ".vol":
        return path
    named = dims_from_name(path)
    shape = tuple(int(n) for n in shape)
    if named is None:
        return path.with_name(f"{path.name[:-4]}.{shape[0]}x{shape[1]}x{shape[2]}.vol")
    if named != shape:
        raise ValueError(f"{path}: the name says {named[0]}x{named[1]}x{named[2]} but the volume is "
                         f"{shape[0]}x{shape[1]}x{shape[2]}; name it NAME.{shape[0]}x{shape[1]}x{shape[2]}.vol")
    return path


def _check_dims(path, dims, line: int | None = None, allocate: bool = True) -> tuple[int, int, int]:
    return checked_grid(path, dims, line=line, allocate=allocate)


def has_header(path: str | Path) -> bool:
    """Whether ``path`` is to be read as a ``.VOL`` (header) file.

    By extension case: ``.VOL`` has a header, ``.vol`` has none. Mixed case
    (``.Vol``) is sniffed: a header starts with three integers.
    """
    suffix = Path(path).suffix
    if suffix == ".VOL":
        return True
    if suffix == ".vol":
        return False
    try:
        with Path(path).open("rb") as fh:
            return _parse_header(path, fh.read(HEADER_BYTES)) is not None
    except (FormatError, OSError):
        return False


def _parse_header(path, head: bytes) -> tuple[int, int, int]:
    """The three dimensions on the header's first line (signs kept, so ``-4`` is refused, not read as 4)."""
    if len(head) < HEADER_BYTES:
        raise FormatError(path, f"file has {len(head)} bytes, expected a {HEADER_BYTES}-byte .VOL header")
    first = head.split(b"\n", 1)[0].replace(b"\0", b" ")
    words = first.split()
    if len(words) < 3 or not all(re.fullmatch(rb"[+-]?[0-9]+", w) for w in words[:3]):
        raise FormatError(path, "the .VOL header's first line does not start with three dimensions 'X Y Z', "
                                f"got {first[:40]!r}", 1)
    return tuple(int(w) for w in words[:3])


def read_header_dims(path: str | Path, allocate: bool = True) -> tuple[int, int, int]:
    """The dimensions recorded in a ``.VOL`` header (checked; see ``limits.checked_grid``)."""
    try:
        with Path(path).open("rb") as fh:
            return _check_dims(path, _parse_header(path, fh.read(HEADER_BYTES)), 1, allocate)
    except OSError as exc:
        raise FormatError(path, f"cannot read file: {exc.strerror or exc}") from exc


def raw_layout(path: str | Path, dims=None, *, allocate: bool = True) -> tuple[tuple[int, int, int], int, int]:
    """``(dims, byte offset of the voxels, bytes per voxel)`` of a raw volume, checked against the
    file size (and, with ``allocate``, against the input limits). Bytes per voxel is 1 (grey) or 3
    (RGB): the file size decides, since the name and the header only give the dimensions."""
    path = Path(path)
    if not path.is_file():
        raise FormatError(path, "no such file")
    size = path.stat().st_size
    if has_header(path):
        dims = _check_dims(path, dims, None, allocate) if dims is not None else read_header_dims(path, allocate)
        n = math.prod(dims)
        channels = channels_for(size - HEADER_BYTES, n)
        if channels:
            return _checked_channels(path, dims, channels, allocate), HEADER_BYTES, channels
        raise FormatError(path, f"file has {size} bytes, expected {n + HEADER_BYTES} "
                          f"({HEADER_BYTES}-byte header + {dims[0]}x{dims[1]}x{dims[2]} voxels) "
                          f"or {3 * n + HEADER_BYTES} (the same in RGB, 3 bytes a voxel)")
    dims = dims if dims is not None else dims_from_name(path)
    if dims is None:
        raise FormatError(path, "unknown dimensions: give them (e.g. --dims X Y Z) or name the file NAME.XxYxZ.vol")
    dims = _check_dims(path, dims, None, allocate)
    n = math.prod(dims)
    channels = channels_for(size, n)
    if channels:
        return _checked_channels(path, dims, channels, allocate), 0, channels
    if size in (n + HEADER_BYTES, 3 * n + HEADER_BYTES):
        raise FormatError(path, f"file has {size} bytes = {dims[0]}x{dims[1]}x{dims[2]}"
                          f"{' x 3' if size > 3 * n else ''} + {HEADER_BYTES}: "
                          "it looks like a .VOL with a 100-byte header; rename it to .VOL or strip "
                          "the header with 'volanim rmheader'")
    raise FormatError(path, f"file has {size} bytes, expected {n} for {dims[0]}x{dims[1]}x{dims[2]} voxels "
                      f"(or {3 * n} in RGB, 3 bytes a voxel)")


def channels_for(data_bytes: int, voxels: int) -> int | None:
    """Bytes per voxel of raw data of this size: 1 (grey), 3 (RGB), or None (neither fits)."""
    return next((c for c in (1, 3) if data_bytes == c * voxels), None)


def _checked_channels(path, dims, channels: int, allocate: bool):
    """An RGB file holds three times the bytes: check those against memory too."""
    if channels == 3 and allocate:
        checked_grid(path, dims, 3)
    return dims


def read_raw(path: str | Path, dims=None, *, mmap: bool = False) -> np.ndarray:
    """Read a ``.vol`` or ``.VOL`` file as a ``(X, Y, Z)`` uint8 array indexed ``[x, y, z]``
    (``(X, Y, Z, 3)`` for an RGB file).

    ``mmap=True`` maps the file read-only instead of loading it (streaming tools).
    """
    dims, offset, channels = raw_layout(path, dims, allocate=not mmap)
    if channels == 3:  # bytes R G B per voxel, x fastest: C order is [z, y, x, c]
        if mmap:
            data = np.memmap(path, np.uint8, "r", offset=offset, shape=(*dims[::-1], 3))
        else:
            with Path(path).open("rb") as fh:
                fh.seek(offset)
                data = np.fromfile(fh, np.uint8, count=3 * math.prod(dims)).reshape(*dims[::-1], 3)
        return data.transpose(2, 1, 0, 3)
    if mmap:
        return np.memmap(path, np.uint8, "r", offset=offset, shape=dims, order="F")
    with Path(path).open("rb") as fh:
        fh.seek(offset)
        data = np.fromfile(fh, np.uint8, count=math.prod(dims))
    return data.reshape(dims, order="F")


def header_bytes(dims) -> bytes:
    """A ``.VOL`` header: ``X Y Z`` padded with spaces to 99 bytes, then ``\\n``."""
    line = f"{dims[0]} {dims[1]} {dims[2]}".encode()
    return line.ljust(HEADER_BYTES - 1, b" ") + b"\n"


def _as_uint8(vol: np.ndarray) -> np.ndarray:
    vol = np.asarray(vol)
    if vol.ndim != 3 and not (vol.ndim == 4 and vol.shape[3] == 3):
        raise ValueError(f"a volume must be 3-D (or 3-D with 3 colour channels), got shape {vol.shape}")
    if vol.dtype != np.uint8:
        if vol.dtype == bool or (vol.size and vol.min() >= 0 and vol.max() <= 255
                                 and np.issubdtype(vol.dtype, np.integer)):
            return vol.astype(np.uint8)
        raise ValueError(f".vol files hold uint8 voxels, got {vol.dtype}; convert with float_to_uint8 first")
    return vol


def write_raw(path: str | Path, vol: np.ndarray, *, header: bool | None = None) -> None:
    """Write ``vol`` as ``.vol`` (no header) or ``.VOL`` (header), atomically.

    ``header=None`` decides by the extension's case (``.VOL`` -> header).
    """
    vol = _as_uint8(vol)
    if header is None:
        header = Path(path).suffix == ".VOL"
    with atomic_open(path, "wb", size=vol.nbytes + (HEADER_BYTES if header else 0)) as fh:
        if header:
            fh.write(header_bytes(vol.shape))
        # Transposing the F-order view gives C order: bytes x fastest (RGB: channel, then x).
        axes = (2, 1, 0, 3) if vol.ndim == 4 else (2, 1, 0)
        fh.write(np.ascontiguousarray(vol.transpose(axes)).tobytes())


def _copy_stream(src, dst, remaining: int) -> None:
    while remaining > 0:
        chunk = src.read(min(CHUNK, remaining))
        if not chunk:
            raise OSError("file ended early")
        dst.write(chunk)
        remaining -= len(chunk)


def add_header(src: str | Path, dst: str | Path, dims=None) -> tuple[int, int, int]:
    """Stream a ``.vol`` into a ``.VOL`` with a header (AddHeader)."""
    dims, offset, channels = raw_layout(src, dims, allocate=False)
    if offset:
        raise FormatError(src, "already has a .VOL header")
    with Path(src).open("rb") as fin, atomic_open(dst, "wb", size=HEADER_BYTES + math.prod(dims) * channels) as fout:
        fout.write(header_bytes(dims))
        _copy_stream(fin, fout, math.prod(dims) * channels)
    return dims


def remove_header(src: str | Path, dst: str | Path, header_size: int | None = None,
                  dims=None) -> tuple[int, int, int] | None:
    """Stream a file minus its header into a bare ``.vol`` (rmhdr).

    Without ``header_size`` the file is a ``.VOL``: its 100-byte header names the size, which is
    checked and returned. With it (the thesis's rmhdr took one), that many bytes are dropped from
    whatever file it is; the rest must be ``dims`` voxels (grey or RGB) when ``dims`` is given, and
    the dims (or None) are returned.
    """
    size = Path(src).stat().st_size
    if header_size is None:
        dims = read_header_dims(src, allocate=False)
        header_size = HEADER_BYTES
    if header_size < 0 or header_size >= size:
        raise FormatError(src, f"has {size} bytes: a header of {header_size} bytes leaves no voxels")
    body = size - header_size
    if dims is not None:
        n = math.prod(dims)
        if not channels_for(body, n):
            raise FormatError(src, f"file has {size} bytes, expected {n + header_size} for a {header_size}-byte "
                                   f"header + {'x'.join(map(str, dims))} voxels (or {3 * n + header_size} in RGB)")
    with Path(src).open("rb") as fin, atomic_open(dst, "wb") as fout:
        fin.seek(header_size)
        _copy_stream(fin, fout, body)
    return None if dims is None else tuple(int(v) for v in dims)


def histogram_file(path: str | Path, dims=None) -> np.ndarray:
    """Counts of each value 0..255 in a raw volume, streamed in chunks (Count)."""
    dims, offset, channels = raw_layout(path, dims, allocate=False)
    if channels != 1:
        raise FormatError(path, "is an RGB volume (3 bytes a voxel); counting values needs a grey or an "
                                "index volume ('volanim palette apply' makes one)")
    counts = np.zeros(256, np.int64)
    remaining = math.prod(dims)
    with Path(path).open("rb") as fh:
        fh.seek(offset)
        while remaining:
            chunk = np.frombuffer(fh.read(min(CHUNK, remaining)), np.uint8)
            counts += np.bincount(chunk, minlength=256)
            remaining -= len(chunk)
    return counts
