"""Marker data on disk: C3D files (read by ezc3d, checked first by :mod:`.c3d_layout`) and marker maps
(``JOINT MARKER [MARKER ...]`` per line). What the markers mean is :mod:`volanim_core.motion.markers`'s.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from volanim_core.limits import MAX_MEASURE

from .c3d_layout import C3dLayout


def read_c3d(path: str | Path) -> tuple[list[str], np.ndarray, float, str]:
    """A C3D file's marker labels, their ``(F, M, 3)`` positions (NaN where the camera system marked a
    marker invalid), the frame rate and the unit (``"mm"`` usually). Read by ezc3d (pyomeca)."""
    import ezc3d

    from volanim_core.errors import FormatError

    if not Path(path).is_file():  # ezc3d's own message says neither which file nor why
        raise FormatError(path, "no such file" if not Path(path).exists() else "is not a regular file; expected "
                          "a C3D file")
    layout = C3dLayout.read(path)  # checked before ezc3d allocates what the header claims
    try:
        c3d = ezc3d.c3d(str(path))
    except (OSError, RuntimeError, ValueError) as e:
        raise FormatError(path, f"not a C3D file ezc3d can read ({str(e).split(':')[0]})") from None
    point = c3d["parameters"]["POINT"]
    labels = [str(s).strip() for s in point["LABELS"]["value"]]
    xyz = np.asarray(c3d["data"]["points"], float)[:3]  # (4, M, F): x, y, z, 1
    if xyz.shape[1] != len(labels) or xyz.shape[2] == 0:
        raise FormatError(path, f"{xyz.shape[1]} markers and {len(labels)} labels in {xyz.shape[2]} frames")
    claimed = layout.point_frames
    if xyz.shape[2] > layout.held or (claimed is not None and claimed > xyz.shape[2] and not layout.ends_on_a_frame):
        raise FormatError(path, f"{xyz.shape[2]} frames read, where its POINT:FRAMES says {claimed} and its bytes "
                                f"hold {layout.held} and part of another: cut short in the middle of a frame")
    if claimed is not None and claimed > xyz.shape[2]:  # cut at a frame's end, as ezc3d's own Optotrak.c3d is
        import warnings

        warnings.warn(f"{path}: its POINT:FRAMES says {claimed} frames; it holds {xyz.shape[2]}, which are read",
                      stacklevel=2)
    unit = str(point["UNITS"]["value"][0]).strip() if "UNITS" in point and len(point["UNITS"]["value"]) else ""
    xyz = np.transpose(xyz, (2, 1, 0))
    # a coordinate no camera measured (inf, NaN, 1e30) is a missing marker in that frame, as an invalid one is
    xyz[~(np.isfinite(xyz) & (np.abs(xyz) <= MAX_MEASURE)).all(axis=2)] = np.nan
    if np.isnan(xyz).all():
        raise FormatError(path, f"no marker has a position in any of its {len(xyz)} frames")
    return labels, xyz, float(point["RATE"]["value"][0]), unit


def read_marker_map(path: str | Path) -> dict[str, list[str]]:
    """``JOINT MARKER [MARKER ...]`` per line (``#`` comments): each joint the mean of its markers."""
    from volanim_core.errors import FormatError
    from volanim_core.io.files import regular_file_bytes
    from volanim_core.io.text import MAX_TEXT_BYTES

    text = regular_file_bytes(path, MAX_TEXT_BYTES, "marker map").decode("utf-8-sig", errors="replace")
    out: dict[str, list[str]] = {}
    for line_no, line in enumerate(text.splitlines(), start=1):
        fields = line.split("#", 1)[0].split()
        if not fields:
            continue
        if len(fields) < 2:
            raise FormatError(path, f"expected 'JOINT MARKER [MARKER ...]', got {line.strip()!r}", line_no)
        if fields[0] in out:
            raise FormatError(path, f"joint {fields[0]} is mapped twice", line_no)
        out[fields[0]] = fields[1:]
    if not out:
        raise FormatError(path, "no 'JOINT MARKER ...' lines")
    return out
