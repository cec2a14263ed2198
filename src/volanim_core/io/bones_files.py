"""``.bones`` (joints and bones in root order) and ``.connections`` files.

``bone A B`` may carry an optional third token, the bone's name (e.g.
``bone L_HIP L_KNEE L_THIGH``): the original contract was silent on bone names in
``.bones`` but ``.connect`` carries them, so they need a home here.
"""

from __future__ import annotations

from pathlib import Path

from volanim_core.rig.bones import Bone, BoneSkeleton, bone_cycle

from .atomic import atomic_write_text
from .text import fmt_float, parse_float, parse_geometry, read_records


def read_bones(path: str | Path) -> BoneSkeleton:
    """Read a ``.bones`` file."""
    rec = read_records(path)
    joints: dict = {}
    bones: list[Bone] = []
    bone_lines: list[int] = []
    for line, toks in rec.records:
        kind = toks[0].lower()
        if kind == "joint":
            if len(toks) != 5:
                raise rec.error(line, f"expected 'joint NAME x y z', got {len(toks)} tokens")
            name = toks[1]
            if name in joints:
                raise rec.error(line, f"joint {name!r} is defined twice; names must be unique")
            joints[name] = [parse_float(rec, line, t, f"joint {name} {a}") for t, a in zip(toks[2:], "xyz")]
        elif kind == "bone":
            if len(toks) not in (3, 4):
                raise rec.error(line, f"expected 'bone A B [NAME]', got {len(toks)} tokens")
            bones.append(Bone(toks[1], toks[2], toks[3] if len(toks) == 4 else ""))
            bone_lines.append(line)
        else:
            raise rec.error(line, f"expected a 'joint' or 'bone' line, got {toks[0]!r}")
    seen = set()
    for b, line in zip(bones, bone_lines):
        for j in (b.proximal, b.distal):
            if j not in joints:
                raise rec.error(line, f"bone {b.label} names joint {j!r}, which no 'joint' line defines")
        if b.proximal == b.distal:
            raise rec.error(line, f"bone joins joint {b.proximal!r} to itself")
        if (b.proximal, b.distal) in seen:
            raise rec.error(line, f"bone {b.proximal} {b.distal} is listed twice")
        seen.add((b.proximal, b.distal))
    cycle = bone_cycle(bones)
    if cycle:
        raise rec.error(bone_lines[max(cycle)], "the bones form a cycle ("
                        + " -> ".join(bones[i].label for i in cycle) + "); a bone skeleton must be a tree")
    return BoneSkeleton(joints, bones, parse_geometry(rec))


def write_bones(path: str | Path, skeleton: BoneSkeleton, geometry=None) -> None:
    """Write a ``.bones`` file atomically; bone lines in root order. ``geometry``: the grid the joints
    are on, when the caller knows it better than the bones do (the studio's skeleton)."""
    geometry = skeleton.geometry if geometry is None else geometry
    lines = ["# volanim bones 1"] + ([] if geometry.is_identity else [f"# geometry: {geometry.header_value()}"])
    for name, xyz in skeleton.joints.items():
        lines.append(f"joint {name} " + " ".join(fmt_float(v) for v in xyz))
    for b in skeleton.bones:
        lines.append(f"bone {b.proximal} {b.distal}" + (f" {b.name}" if b.name else ""))
    atomic_write_text(path, "\n".join(lines) + "\n")


def read_connections(path: str | Path) -> list[tuple[str, str]]:
    """Read a ``.connections`` file: ``A B`` joint-name pairs in root order."""
    rec = read_records(path)
    pairs, lines = [], {}
    for line, toks in rec.records:
        if len(toks) != 2:
            raise rec.error(line, f"expected 'A B' (two joint names), got {len(toks)} tokens")
        a, b = toks
        if a == b:
            raise rec.error(line, f"'{a} {b}' joins joint {a!r} to itself")
        if (a, b) in lines:
            raise rec.error(line, f"'{a} {b}' is listed twice (also on line {lines[(a, b)]})")
        lines[(a, b)] = line
        pairs.append((a, b))
    return pairs


def write_connections(path: str | Path, skeleton: BoneSkeleton) -> None:
    """Write the bones' joint-name pairs in root order."""
    lines = [f"{b.proximal} {b.distal}" for b in skeleton.bones]
    atomic_write_text(path, "\n".join(lines) + "\n")
