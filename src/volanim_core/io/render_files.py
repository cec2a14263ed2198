"""``.camera`` and ``.tf`` files: a render's fixed camera and a user transfer function.

The original contract did not cover them (docs/formats.md#camera and #tf now do); they
follow its text conventions (``#`` comments, blank lines, CRLF, tabs, a byte-order mark are
all fine) and errors name the line.

    # volanim camera 1                # volanim tf 1
    position 64.0 -700.0 150.0        # value  red green blue alpha (each 0..1)
    focal_point 64.0 60.0 150.0       0      0    0    0    0
    view_up 0 0 1                     80     0.8  0.6  0.45 0.05
    view_angle 30                     255    1    1    1    0.8
    parallel_scale 120   (optional: a parallel projection)

Colours and opacities are 0..1 as in VTK and ParaView (so a file round-trips
exactly); the value is the voxel value, linear in between.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from volanim_core.camera import Camera
from volanim_core.transfer_function import TransferFunction

from .atomic import atomic_write_text
from .text import fmt_float, parse_float, read_records

_VECTORS = ("position", "focal_point", "view_up")
_SCALARS = ("view_angle", "parallel_scale")


def read_camera(path: str | Path) -> Camera:
    rec = read_records(path)
    seen: dict[str, object] = {}
    for line, tokens in rec.records:
        key = tokens[0].lower()
        if key not in _VECTORS + _SCALARS:
            raise rec.error(line, f"unknown camera key {tokens[0]!r}; expected one of {', '.join(_VECTORS + _SCALARS)}")
        if key in seen:
            raise rec.error(line, f"{key} is given twice")
        want = 3 if key in _VECTORS else 1
        if len(tokens) != want + 1:
            raise rec.error(line, f"{key} takes {want} number{'s' if want > 1 else ''}, got {len(tokens) - 1}")
        nums = [parse_float(rec, line, t, key) for t in tokens[1:]]
        seen[key] = tuple(nums) if want == 3 else nums[0]
        seen[key + "@"] = line
    missing = [k for k in ("position", "focal_point") if k not in seen]
    if missing:
        raise rec.error(None, f"a camera needs {' and '.join(missing)}")
    cam = Camera(seen["position"], seen["focal_point"], seen.get("view_up", (0.0, 0.0, 1.0)),
                 seen.get("view_angle", 30.0), seen.get("parallel_scale"))
    try:
        cam.check("camera")
    except ValueError as exc:
        raise rec.error(None, str(exc).removeprefix("camera: ")) from None
    return cam


def write_camera(path: str | Path, cam: Camera) -> None:
    cam.check(str(path))
    lines = ["# volanim camera 1"]
    for key in _VECTORS:
        lines.append(f"{key} " + " ".join(fmt_float(v) for v in getattr(cam, key)))
    lines.append(f"view_angle {fmt_float(cam.view_angle)}")
    if cam.parallel_scale is not None:
        lines.append(f"parallel_scale {fmt_float(cam.parallel_scale)}")
    atomic_write_text(path, "\n".join(lines) + "\n")


def read_transfer_function(path: str | Path) -> TransferFunction:
    from volanim_core.transfer_function import MAX_POINTS

    rec = read_records(path)
    values, rgba = [], []
    if len(rec.records) > MAX_POINTS:
        raise rec.error(rec.records[MAX_POINTS][0], f"a transfer function has at most {MAX_POINTS} points, "
                                                    f"this one {len(rec.records)}")
    for line, tokens in rec.records:
        if len(tokens) != 5:
            raise rec.error(line, f"expected VALUE RED GREEN BLUE ALPHA (5 numbers), got {len(tokens)}")
        v = parse_float(rec, line, tokens[0], "the value")
        c = [parse_float(rec, line, t, name) for t, name in zip(tokens[1:], ("red", "green", "blue", "alpha"))]
        for x, t, name in zip(c, tokens[1:], ("red", "green", "blue", "alpha")):
            if not 0 <= x <= 1:
                raise rec.error(line, f"{name} is between 0 and 1, got {t}")
        if values and v <= values[-1]:
            raise rec.error(line, f"values must ascend: {tokens[0]} follows {fmt_float(values[-1])}")
        values.append(v)
        rgba.append(c)
    return TransferFunction(np.array(values), np.array(rgba))


def write_transfer_function(path: str | Path, tf: TransferFunction) -> None:
    lines = ["# volanim tf 1", "# value  red green blue alpha (each 0..1)"]
    for v, c in zip(tf.values, tf.rgba):
        lines.append(" ".join(fmt_float(x) for x in (v, *c)))
    atomic_write_text(path, "\n".join(lines) + "\n")
