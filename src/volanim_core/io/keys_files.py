"""``.keys``: a keyframed animation as text (``volanim keys``, the studio's Export keys).

    fps 24                      # optional settings; command-line options win
    length 48
    ease on
    0   L_UPPERARM  0 -45 0     # FRAME BONE RX RY RZ [TX TY TZ]
    24  L_UPPERARM  0  45 0
    24  PELVIS      0 0 0  0 0 3
    36  -                       # a key with every bone at rest

A bone is named as ``volanim pose`` names it: its name, or ``PROXIMAL-DISTAL``.
Angles are degrees about x, y, z (the pose sliders), shifts voxels; a bone a key
does not list is at rest in that key (docs/formats.md, "Keys").
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from volanim_core.io.atomic import atomic_write_text
from volanim_core.io.text import fmt_float, parse_float, parse_int, read_records
from volanim_core.rig.bones import BoneSkeleton
from volanim_core.rig.key_pose import MAX_FRAMES, KeyPose

MAX_FRAME = 10_000_000
SETTINGS = ("fps", "length", "ease")


@dataclass
class Keys:
    """The keys (frame -> :class:`KeyPose`) and the settings the file gave (None: not given)."""

    keys: dict[int, KeyPose] = field(default_factory=dict)
    fps: float | None = None
    length: int | None = None
    ease: bool | None = None


def read_keys(path: str | Path, bones: BoneSkeleton) -> Keys:
    """Read a ``.keys`` file for ``bones`` (FormatError naming the file and line)."""
    rec = read_records(path)
    out = Keys()
    seen: dict[tuple, int] = {}
    for line, toks in rec.records:
        word = toks[0].lower()
        if word in SETTINGS:
            if len(toks) != 2:
                raise rec.error(line, f"expected '{word} VALUE', got {len(toks)} tokens")
            if word == "fps":
                out.fps = parse_float(rec, line, toks[1], "fps", 1000)
                if out.fps < 1:
                    raise rec.error(line, f"fps must be 1 to 1000, got {toks[1]}")
            elif word == "length":
                out.length = parse_int(rec, line, toks[1], "length", MAX_FRAMES)
                if out.length < 1:
                    raise rec.error(line, f"length must be 1 to {MAX_FRAMES} frames, got {toks[1]}")
            else:
                if toks[1].lower() not in ("on", "off"):
                    raise rec.error(line, f"expected 'ease on' or 'ease off', got {toks[1]!r}")
                out.ease = toks[1].lower() == "on"
            continue
        frame = parse_int(rec, line, toks[0], "the key's frame", MAX_FRAME)
        if frame < 0:
            raise rec.error(line, f"a key's frame must be 0 or more, got {frame}")
        key = out.keys.setdefault(frame, KeyPose())
        if len(toks) == 2 and toks[1] == "-":
            continue
        if len(toks) not in (5, 8):
            raise rec.error(line, f"expected 'FRAME BONE RX RY RZ [TX TY TZ]' or 'FRAME -', got {len(toks)} tokens")
        try:
            b = bones.bones[bones.index(toks[1])]
        except KeyError:
            raise rec.error(line, f"no bone named {toks[1]!r}; bones are "
                            + ", ".join(b.label for b in bones.bones)) from None
        name = (b.proximal, b.distal)
        if (frame, name) in seen:
            raise rec.error(line, f"bone {toks[1]} is keyed twice at frame {frame} (also on line "
                            f"{seen[(frame, name)]})")
        seen[(frame, name)] = line
        values = [parse_float(rec, line, t, f"{toks[1]} {what}") for t, what in
                  zip(toks[2:], ("rx", "ry", "rz", "tx", "ty", "tz"))]
        key.angles[name] = np.array(values[:3])
        key.shifts[name] = np.array(values[3:] if len(values) == 6 else [0.0, 0.0, 0.0])
    if not out.keys:
        raise rec.error(None, "no key: expected lines 'FRAME BONE RX RY RZ [TX TY TZ]'")
    return out


def write_keys(path: str | Path, keys: Keys, bones: BoneSkeleton) -> None:
    """Write ``keys`` atomically; bones the skeleton no longer has are left out (as the studio drops them)."""
    labels = {(b.proximal, b.distal): b.label for b in bones.bones}
    lines = ["# volanim keys 1", "# FRAME BONE RX RY RZ [TX TY TZ]: degrees about x, y, z; shift in voxels"]
    lines += [f"fps {fmt_float(keys.fps)}"] if keys.fps is not None else []
    lines += [f"length {keys.length}"] if keys.length is not None else []
    lines += [f"ease {'on' if keys.ease else 'off'}"] if keys.ease is not None else []
    for frame, key in sorted(keys.keys.items()):
        rows = []
        for name in sorted(set(key.angles) | set(key.shifts)):
            if name not in labels:
                continue
            a = key.angles.get(name, np.zeros(3))
            t = key.shifts.get(name, np.zeros(3))
            text = " ".join(fmt_float(v) for v in a) + ("" if not np.any(t) else " " + " ".join(
                fmt_float(v) for v in t))
            rows.append(f"{frame} {labels[name]} {text}")
        lines += rows or [f"{frame} -"]
    atomic_write_text(path, "\n".join(lines) + "\n")
