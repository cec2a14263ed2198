"""Joint positions per frame as a CSV (``frame,joint,x,y,z``), read and written. Solving bone matrices
from them is :mod:`volanim_core.motion.positions`'s.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from volanim_core.limits import MAX_MEASURE

MAX_FRAME_NUMBER = 10_000_000  # frame numbers name files (NAME.0012.trans); 10^23 is no frame


def read_positions(path: str | Path, names: list[str], scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """A CSV of ``frame,joint,x,y,z`` rows (a header line; frames whole numbers, any order) as the frame
    numbers and an ``(F, J, 3)`` array for ``names`` (NaN where a frame lacks a joint), times ``scale``.
    Joints not in ``names`` are ignored; a row that is not five fields names its line."""
    from volanim_core.errors import FormatError

    rows = {}
    from volanim_core.io.files import regular_file_bytes
    from volanim_core.io.text import MAX_TEXT_BYTES

    # as every text reader: a missing file, a folder or /dev/zero is a one-line error, not a hang
    text = regular_file_bytes(path, MAX_TEXT_BYTES, "CSV file").decode("utf-8-sig", errors="replace")
    index = {n: j for j, n in enumerate(names)}
    for line_no, line in enumerate(text.splitlines(), start=1):
        fields = [f.strip() for f in line.split(",")]
        if not line.strip() or line.lstrip().startswith("#") or (line_no == 1 and fields[:2] == ["frame", "joint"]):
            continue
        if len(fields) != 5:
            raise FormatError(path, f"expected 'frame,joint,x,y,z', got {len(fields)} fields", line_no)
        try:
            frame, xyz = int(fields[0]), [float(v) for v in fields[2:]]
        except ValueError:
            raise FormatError(path, f"expected a whole frame number and three numbers, got {line.strip()!r}",
                              line_no) from None
        if not 0 <= frame <= MAX_FRAME_NUMBER:
            raise FormatError(path, f"frame {fields[0]}: frame numbers are 0 to {MAX_FRAME_NUMBER:,}", line_no)
        if not all(np.isfinite(v) and abs(v) <= MAX_MEASURE for v in xyz):
            raise FormatError(path, f"a position must be finite and within {MAX_MEASURE:g} of the origin, got "
                              f"{', '.join(fields[2:])}", line_no)
        if fields[1] in index:
            rows.setdefault(frame, {})[index[fields[1]]] = xyz
    if not rows:
        raise FormatError(path, f"no rows for any of the bones' joints ({', '.join(names)})")
    frames = np.array(sorted(rows))
    out = np.full((len(frames), len(names), 3), np.nan)
    for f, frame in enumerate(frames):
        for j, xyz in rows[frame].items():
            out[f, j] = xyz
        present = out[f][~np.isnan(out[f]).any(axis=1)]
        if len(present) >= 2 and np.ptp(present, axis=0).max() == 0:
            raise FormatError(path, f"frame {frame}: every joint is at one place {present[0].tolist()}; no pose "
                              "can be read from it")
    return frames, out * scale


def write_positions(path: str | Path, numbers, names: list[str], positions: np.ndarray) -> None:
    """The CSV :func:`read_positions` reads, atomically."""
    from volanim_core.io.atomic import atomic_write_text

    rows = ["frame,joint,x,y,z"]
    for f, frame in enumerate(numbers):
        rows += [f"{int(frame)},{n},{x:.6f},{y:.6f},{z:.6f}" for n, (x, y, z) in zip(names, positions[f])
                 if np.all(np.isfinite((x, y, z)))]
    atomic_write_text(path, "\n".join(rows) + "\n")
