"""What a C3D file says of itself, read once before ezc3d is let at it (#64).

    block 1 (header)      --words--> points, analog samples a frame, data start block, int or float data
    parameter section     --records--> POINT:FRAMES as written (ezc3d rewrites it to what it could read)
    the file's size       --> frames its bytes hold, and whether the data ends on a whole frame

ezc3d allocates what a header claims (32767 points of a few-kilobyte file) and reads a truncated file
as the frames it still holds; both are checked here instead. The header's own frame range is not
trusted: real files (ezc3d's Optotrak.c3d) get it wrong, and readers go by POINT:FRAMES.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from volanim_core.errors import FormatError

BLOCK = 512
MIPS = 86  # processor type of big-endian files (84 Intel, 85 DEC: little-endian)


@dataclass(frozen=True)
class C3dLayout:
    points: int
    analog: int
    frame_bytes: int  # one frame of points and analog samples
    held: int  # whole frames the bytes after the data start hold
    ends_on_a_frame: bool  # past the last whole frame: nothing, or zeros padding to a block
    point_frames: int | None  # POINT:FRAMES as written; None where the parameter section does not say

    @classmethod
    def read(cls, path) -> C3dLayout:
        """The layout of the C3D at ``path``, from its header, its parameter section and its size (the
        data are not read); FormatError when it is no C3D or cannot hold one frame."""
        path = Path(path)
        total = path.stat().st_size
        with open(path, "rb") as fh:
            head = fh.read(BLOCK)
            if len(head) < BLOCK or head[1] != 0x50:
                raise FormatError(path, "not a C3D file (its first block is not a C3D header)")
            fh.seek(max(head[0] - 1, 0) * BLOCK)
            section = fh.read(4)
            section += fh.read(max(section[2] if len(section) > 2 else 1, 1) * BLOCK - 4)
            order = ">" if len(section) >= 4 and section[3] == MIPS else "<"
            words = np.frombuffer(head[:24], order + "u2")
            points, analog, start = int(words[1]), int(words[2]), max(int(words[8]) - 1, 0) * BLOCK
            size = 4 if float(np.frombuffer(head[12:16], order + "f4")[0]) < 0 else 2  # a negative scale: floats
            frame_bytes = (points * 4 + analog) * size
            held, tail = divmod(max(total - start, 0), max(frame_bytes, 1))
            if held < 1:
                raise FormatError(path, f"its header claims {points} points and {analog} analog samples a frame "
                                        f"({frame_bytes:,} bytes from block {start // BLOCK + 1}); the file holds "
                                        "no whole frame of them")
            fh.seek(total - tail)
            padding = tail < BLOCK and not fh.read(tail).strip(b"\0")
        return cls(points, analog, frame_bytes, int(held), padding, _point_frames(section, order))


def _s8(byte: int) -> int:
    return byte - 256 if byte > 127 else byte


def _point_frames(section: bytes, order: str) -> int | None:
    """POINT:FRAMES from the parameter section: records of a signed name length, a group (< 0) or
    parameter id, the name, an offset to the next record, then a parameter's type, dimensions and data."""
    if len(section) < 4:
        return None
    data = section[4:]
    groups, params, at = {}, {}, 0
    while at + 4 <= len(data):
        size, ident = abs(_s8(data[at])), _s8(data[at + 1])
        if size == 0 or at + 4 + size > len(data):
            break
        name = data[at + 2:at + 2 + size].decode("latin-1").upper()
        step = int(np.frombuffer(data[at + 2 + size:at + 4 + size], order + "i2")[0])
        if ident < 0:
            groups[-ident] = name
        elif at + 6 + size <= len(data):
            body = at + 4 + size
            kind, first = _s8(data[body]), body + 2 + data[body + 1]
            if kind in (2, 4) and first + kind <= len(data):
                params[(ident, name)] = float(np.frombuffer(data[first:first + 4], order + "f4")[0]) if kind == 4 \
                    else int(np.frombuffer(data[first:first + 2], order + "u2")[0])
        if step <= 0:
            break
        at += 2 + size + step
    point = next((g for g, n in groups.items() if n == "POINT"), None)
    value = params.get((point, "FRAMES"))
    return int(value) if value is not None and np.isfinite(value) else None
