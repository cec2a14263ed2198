"""Input size limits, checked from a file's header *before* anything is allocated.

Every volume reader asks :func:`checked_grid` about the dimensions a header
claims. Sizes are multiplied as Python integers (they never wrap, unlike an
int64 product of ``4294967296 4294967296 1``), each must be a positive whole
number, and the volume must fit both the voxel limit and the memory this
machine has free. ``VOLANIM_MAX_VOXELS`` raises or lowers the limit.
"""

from __future__ import annotations

import math
import numbers
import os
from pathlib import Path

import numpy as np

from volanim_core.errors import FormatError

DEFAULT_MAX_VOXELS = 2**33  # 8 G voxels: far above any scan we know of, far below exabytes
MAX_AXIS = 2**31 - 1  # kernels index with 32-bit ints per axis
MAX_COORD = 2**30  # voxel coordinates and radii (int32 with room to spare); text readers refuse larger
MAX_MEASURE = 1e9  # a coordinate in a file's own units (mm, a mesh's): past it, no measurement of a body


def max_voxels() -> int:
    env = os.environ.get("VOLANIM_MAX_VOXELS", "")
    return int(env) if env.isascii() and env.isdigit() else DEFAULT_MAX_VOXELS


def _proc_bytes(file: str, key: str) -> int | None:
    """A ``KEY: N kB`` line of a Linux ``/proc`` file, in bytes; None where there is none."""
    try:
        with open(file, encoding="ascii") as fh:
            for line in fh:
                if line.startswith(key):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return None


def available_bytes() -> int | None:
    """Memory available to a new allocation (Linux ``MemAvailable``), or None when unknown."""
    return _proc_bytes("/proc/meminfo", "MemAvailable:")


def peak_rss() -> int:
    """This process's peak resident memory in bytes: Linux ``VmHWM``, the peak of its own address space.
    ``getrusage``'s ``ru_maxrss`` survives ``exec``: a spawned worker reported the RSS its parent had when it
    was started (4.5 GB for a 1-2 GB worker whose parent had just made the full-size mannequin)."""
    peak = _proc_bytes("/proc/self/status", "VmHWM:")
    if peak is not None:
        return peak
    import resource
    import sys

    maxrss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return maxrss if sys.platform == "darwin" else maxrss * 1024  # macOS says bytes, Linux kB


def human_bytes(n: float) -> str:
    for unit in ("bytes", "KB", "MB", "GB", "TB", "PB", "EB"):
        if n < 1024 or unit == "EB":
            return f"{n:.0f} {unit}" if unit == "bytes" else f"{n:.1f} {unit}"
        n /= 1024
    return f"{n:.1f} EB"


def whole_number(path, value, what: str, line: int | None = None) -> int:
    """``value`` as an int: Python/NumPy integers or ASCII digit strings (with an optional sign) only."""
    if isinstance(value, bool):
        raise FormatError(path, f"{what} must be a whole number, got {value!r}", line)
    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, str | bytes):
        text = value.decode("latin-1") if isinstance(value, bytes) else value
        digits = text.strip().lstrip("+-")
        if digits.isascii() and digits.isdigit():
            return int(text.strip())
    raise FormatError(path, f"{what} must be a whole number, got {value!r}", line)


def checked_grid(path: str | Path, dims, itemsize: int = 1, *, line: int | None = None,
                 what: str = "dimensions", allocate: bool = True) -> tuple[int, ...]:
    """Dimensions a file claims, refused (FormatError naming the file) unless allocatable.

    Each size must be a whole number >= 1 and <= 2**31 - 1; with ``allocate``
    (the volume will be held in memory) the voxel count must be at most
    :func:`max_voxels` and the bytes at most the memory available now.
    Streaming tools pass ``allocate=False`` and compare with the file size instead.
    """
    try:
        dims = list(dims)
    except TypeError:
        raise FormatError(path, f"{what} must be three whole numbers X Y Z, got {dims!r}", line) from None
    sizes = tuple(whole_number(path, d, what, line) for d in dims)
    if len(sizes) != 3:
        raise FormatError(path, f"{what} must be three whole numbers X Y Z, got {len(sizes)}: {sizes}", line)
    if min(sizes) < 1 or max(sizes) > MAX_AXIS:
        raise FormatError(path, f"{what} {' '.join(map(str, sizes))}: each must be between 1 and {MAX_AXIS}", line)
    voxels = math.prod(sizes)
    if not allocate:
        return sizes
    shown = "x".join(map(str, sizes))
    if voxels > max_voxels():
        raise FormatError(path, f"claims {shown} = {voxels:,} voxels ({human_bytes(voxels * itemsize)}); "
                                f"the limit is {max_voxels():,} voxels (set VOLANIM_MAX_VOXELS to change it)", line)
    free = available_bytes()
    if free is not None and voxels * itemsize > free:
        raise FormatError(path, f"claims {shown} voxels, {human_bytes(voxels * itemsize)}, but only "
                                f"{human_bytes(free)} of memory is available", line)
    return sizes


def check_allocation(shape, bytes_per_voxel: int, what: str, advice: str) -> None:
    """Refuse (ValueError) a grid the caller is about to make when it is over the voxel limit or the
    memory free, stating its size; ``what`` names it ("the output grid"), ``advice`` says what to change."""
    voxels = math.prod(int(n) for n in shape)
    nbytes = voxels * bytes_per_voxel
    shown = "x".join(str(int(n)) for n in shape)
    if voxels > max_voxels():
        raise ValueError(f"{what} would be {shown} = {voxels:,} voxels ({human_bytes(nbytes)}); the limit "
                         f"is {max_voxels():,} voxels: {advice}")
    free = available_bytes()
    if free is not None and nbytes > free:
        raise ValueError(f"{what} would be {shown} voxels, {human_bytes(nbytes)}, but only "
                         f"{human_bytes(free)} of memory is available: {advice}")


def shaped(value, shape: tuple, name: str, dtype=np.float64, hint: str = "") -> np.ndarray:
    """``value`` as a C-contiguous array of ``shape`` (-1: any length), or a ValueError that names the argument,
    the shape it needs and the one it has: the library's callers got numpy's "cannot reshape array of size 12
    into shape (4,4)" (#89)."""
    a = np.ascontiguousarray(value, dtype=dtype)
    if a.ndim == 1 and len(shape) == 1 or a.ndim == len(shape):
        if all(want in (-1, have) for want, have in zip(shape, a.shape)):
            return a
    want = " x ".join("N" if v == -1 else str(v) for v in shape)
    raise ValueError(f"{name} must be an array of shape ({want}), got shape {a.shape}" + (f"; {hint}" if hint else ""))


def voxel_points(points) -> np.ndarray:
    """``(N, 3)`` int32 voxel coordinates; NaN, fractions and magnitudes over ``MAX_COORD`` are a
    ValueError naming the point (a plain int32 cast wraps 3e9 to -2147483648)."""
    raw = np.asarray(points)
    # (N, 3), or flat x y z x y z as some callers give them
    if raw.size and (raw.ndim > 2 or raw.shape[-1] != 3 and raw.ndim == 2 or raw.size % 3):
        raise ValueError(f"points must be an array of shape (N x 3): x, y, z of each voxel, got shape {raw.shape}")
    if raw.size and raw.dtype.kind not in "biuf":
        raise ValueError(f"point coordinates must be numbers, got {raw.dtype}")
    if raw.size and raw.dtype.kind == "f":
        bad = ~np.isfinite(raw) | (np.abs(raw) > MAX_COORD) | (raw != np.round(raw))
    elif raw.size and (raw.max() > MAX_COORD or raw.min() < -MAX_COORD):
        # integers: two reductions, then the voxels found only when one is out of range (an int64 copy and its
        # abs for every call cost 14 ms of each live picture of the frog's 1.3 M points)
        bad = (raw > MAX_COORD) | (raw < -MAX_COORD)  # no cast: a uint64 over 2^63 would wrap negative
    else:
        bad = None
    if bad is not None and bad.any():
        i = int(np.argwhere(bad.reshape(-1, 3) if bad.size % 3 == 0 else bad)[0][0])
        shown = raw.reshape(-1, 3)[i].tolist() if raw.size % 3 == 0 else raw.tolist()
        raise ValueError(f"point {i} {shown} is not a voxel: coordinates must be finite whole numbers "
                         f"within {MAX_COORD:,}")
    return np.ascontiguousarray(raw, dtype=np.int32).reshape(-1, 3)


def expect_bytes(path: str | Path, have: int, want: int, what: str) -> None:
    """Refuse a file whose data is shorter (truncated) or longer than its header says."""
    if have != want:
        raise FormatError(path, f"{what} has {have:,} bytes, its header says {want:,}"
                                + (" (the file is truncated)" if have < want else ""))
