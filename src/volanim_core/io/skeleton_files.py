"""``.skel`` (x y z dt: one resolution) and ``.mskel`` (x y z dt thinness, sorted) files.

:func:`read_skeleton` and :func:`write_skeleton` pick the format by the name, so every
tool that takes a skeleton takes both, as the thesis's tools took ``.skel``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from volanim_core.skeleton.points import Skeleton

from ._columns import format_point_rows, parse_point_rows
from .atomic import atomic_write_text
from .text import parse_geometry, parse_metric, read_records


def _header(kind: str, skel: Skeleton) -> list[str]:
    lines = [f"# volanim {kind} 1", f"# metric: {skel.metric}"]
    if not skel.geometry.is_identity:
        lines.append(f"# geometry: {skel.geometry.header_value()}")
    return lines


def read_skel(path: str | Path) -> Skeleton:
    """Read a ``.skel`` file (``x y z dt`` a line) into a Skeleton (thinness NaN)."""
    rec = read_records(path)
    arr = parse_point_rows(rec, rec.records, (4,), "x y z dt")
    return Skeleton(arr[:, :3].astype(np.int32), arr[:, 3], None, parse_metric(rec), parse_geometry(rec))


def write_skel(path: str | Path, skel: Skeleton) -> None:
    """Write ``x y z dt`` lines atomically."""
    lines = _header("skel", skel) + format_point_rows(skel.points, skel.dt)
    atomic_write_text(path, "\n".join(lines) + "\n")


def read_mskel(path: str | Path) -> Skeleton:
    """Read a ``.mskel`` file; the result is sorted by decreasing thinness.

    Readers do not rely on the file's order (docs/formats.md), so the points are
    stably re-sorted if needed.
    """
    rec = read_records(path)
    arr = parse_point_rows(rec, rec.records, (5,), "x y z dt thinness")
    skel = Skeleton(arr[:, :3].astype(np.int32), arr[:, 3], arr[:, 4], parse_metric(rec), parse_geometry(rec))
    return skel if skel.is_sorted() else skel.sorted()


def write_mskel(path: str | Path, skel: Skeleton) -> None:
    """Write ``x y z dt thinness`` lines, stably sorted by decreasing thinness."""
    if np.isnan(skel.thinness).any():
        raise ValueError("a .mskel needs a thinness for every point")
    skel = skel if skel.is_sorted() else skel.sorted()
    lines = _header("mskel", skel) + format_point_rows(skel.points, skel.dt, skel.thinness)
    atomic_write_text(path, "\n".join(lines) + "\n")


def read_skeleton(path: str | Path) -> Skeleton:
    """A ``.skel`` (thinness NaN: one resolution) or a ``.mskel``, by the file's suffix."""
    return read_skel(path) if Path(path).suffix.lower() == ".skel" else read_mskel(path)


def write_skeleton(path: str | Path, skel: Skeleton) -> None:
    """``.skel`` (the points as they are, no thinness) or ``.mskel``, by the file's suffix."""
    (write_skel if Path(path).suffix.lower() == ".skel" else write_mskel)(path, skel)


def skeleton_at(skel: Skeleton, thinness: float | None, path) -> Skeleton:
    """``skel`` at ``thinness`` (None: as it is); a ``.skel`` has one resolution, so a thinness is refused."""
    if thinness is None:
        return skel
    if skel.single_resolution:
        raise ValueError(f"{path}: a .skel holds one resolution (no thinness column), so there is no "
                         f"thinness {thinness:g} to choose; give a .mskel, or leave out --thinness")
    return skel.at(thinness)
